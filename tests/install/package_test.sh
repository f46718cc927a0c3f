#!/usr/bin/env bash
# ctest Package.debs (docs/cpp.md, "Install the Debian packages"): build the Debian packages once
# with cpack, check their names and Depends (dpkg-shlibdeps found the libraries the binaries link,
# the -dev and Python packages depend on hapsim of the same version), unpack them into an empty
# folder and run what they hold from there: `hapsim --version`, a scene from /usr/share/hapsim,
# `import hapsim`. When this machine has apt's package lists, apt also checks (without installing
# anything) that every Depends resolves in the archive. Installing them into a bare Debian 12 root
# is scripts/check-package-debian.sh (root, minutes of downloads: not part of the suite).
#   package_test.sh BUILD_DIR CPACK PYTHON_OR_EMPTY
set -euo pipefail
build=$1
cpack=$2
python=${3:-}

fail() {
  echo "FAIL: $*" >&2
  exit 1
}
t0=$(date +%s)
version=$(sed -n 's/^CMAKE_PROJECT_VERSION:STATIC=//p' "$build/CMakeCache.txt")
[[ -n $version ]] || fail "no CMAKE_PROJECT_VERSION in $build/CMakeCache.txt"
out=$build/package
rm -f "$out"/*.deb
"$cpack" --config "$build/CPackConfig.cmake" >"$build/package.log" 2>&1 || {
  tail -n 40 "$build/package.log"
  fail "cpack (log: $build/package.log)"
}
names=(hapsim hapsim-dev)
[[ -n $python ]] && names+=(python3-hapsim)
debs=()
for name in "${names[@]}"; do
  deb=$out/${name}_${version}_amd64.deb
  [[ -f $deb ]] || fail "cpack made no $deb: $(ls "$out")"
  debs+=("$deb")
  echo "$(basename "$deb"): $(du -h "$deb" | cut -f1), Depends: $(dpkg-deb -f "$deb" Depends)"
done
t1=$(date +%s)
echo "built the packages in $((t1 - t0)) s"

depends() { dpkg-deb -f "$out/${1}_${version}_amd64.deb" Depends; }
# dpkg-shlibdeps ran: the libraries hapsim links are in its Depends, with versions.
for lib in libassimp5 libddsc0debian libglfw3 libspdlog1.10 liburdfdom-model libmeshoptimizer libstdc++6; do
  depends hapsim | grep -q "$lib" || fail "hapsim's Depends lacks $lib (dpkg-shlibdeps): $(depends hapsim)"
done
# ... and no reference oracle (they are for tests and benchmarks only).
if depends hapsim | grep -Ei "cgal|fcl|embree|kdl|benchmark"; then
  fail "hapsim's Depends names an oracle library"
fi
# The Mesa drivers GLVND loads at run time, which no binary names.
depends hapsim | grep -q "libegl-mesa0" || fail "hapsim's Depends lacks libegl-mesa0"
depends hapsim-dev | grep -q "hapsim (= $version)" || fail "hapsim-dev does not depend on hapsim (= $version)"
if [[ -n $python ]]; then
  depends python3-hapsim | grep -q "hapsim (= $version)" || fail "python3-hapsim does not depend on hapsim"
  depends python3-hapsim | grep -q "python3-numpy" || fail "python3-hapsim does not depend on NumPy"
fi
# What lands where (the listings read whole: grep -q closing a pipe early would fail it).
runtime_files=$(dpkg-deb -c "$out/hapsim_${version}_amd64.deb")
dev_files=$(dpkg-deb -c "$out/hapsim-dev_${version}_amd64.deb")
grep -q "./usr/share/hapsim/scenes/knee.json" <<<"$runtime_files" ||
  fail "hapsim has no /usr/share/hapsim/scenes/knee.json"
grep -q "./usr/bin/hapsim$" <<<"$runtime_files" || fail "hapsim has no /usr/bin/hapsim"
grep -q "./usr/lib/cmake/hapsim/hapsimConfig.cmake" <<<"$dev_files" ||
  fail "hapsim-dev has no /usr/lib/cmake/hapsim/hapsimConfig.cmake"
grep -q "./usr/include/hapsim/world/world.h" <<<"$dev_files" || fail "hapsim-dev has no world.h"
if grep -E "/include/|hapsim-bench" <<<"$runtime_files"; then
  fail "the runtime package holds headers or hapsim-bench (above)"
fi

# Unpacked into an empty folder, the packages' /usr is a prefix like any other (the installed
# hapsim finds its share/ and libraries from its own place).
root=$(mktemp -d "${TMPDIR:-/tmp}/hapsim-package-test.XXXXXX")
trap 'rm -rf "$root"' EXIT
for deb in "${debs[@]}"; do dpkg-deb -x "$deb" "$root"; done
unset HAPSIM_DATA CYCLONEDDS_URI PYTHONPATH LD_LIBRARY_PATH || true
if ldd "$root/usr/bin/hapsim" | grep -E "not found|cgal|CGAL|fcl|embree|kdl|benchmark"; then
  fail "ldd of the packaged hapsim (above)"
fi
"$root/usr/bin/hapsim" --version | grep -q "^hapsim $version" || fail "hapsim --version: $("$root/usr/bin/hapsim" --version)"
(cd "$root" && "$root/usr/bin/hapsim" run "$root/usr/share/hapsim/scenes/fem_block.json" --duration 0.5 \
  --json "$root/run.json" >"$root/run.txt" 2>&1) || {
  cat "$root/run.txt"
  fail "the packaged hapsim did not run fem_block.json"
}
grep -q '"pop_throughs": 0' "$root/run.json" || fail "the packaged run's summary: $(head -c 600 "$root/run.json")"
tail -n 2 "$root/run.txt"
if [[ -n $python ]]; then
  PYTHONPATH=$root/usr/lib/python3/dist-packages "$python" -c \
    "import hapsim; assert hapsim.__file__.startswith('$root'), hapsim.__file__; print('python:', hapsim.__file__)"
fi

# apt resolves every Depends against the archive this machine knows (a simulation: nothing is
# installed). Without package lists (apt-get update never ran) there is nothing to resolve against.
if compgen -G "/var/lib/apt/lists/*_Packages*" >/dev/null; then
  apt-get install --simulate --no-install-recommends "${debs[@]}" >"$root/apt.log" 2>&1 || {
    cat "$root/apt.log"
    fail "apt cannot resolve the packages' Depends (above)"
  }
  echo "apt: the Depends resolve ($(grep -c '^Inst ' "$root/apt.log") packages would be installed)"
else
  echo "apt: no package lists on this machine; the Depends were not resolved"
fi
echo "PASS in $(($(date +%s) - t0)) s"
