#!/usr/bin/env bash
# ctest Install.examples (docs/cpp.md): `cmake --install` the build into a temporary prefix, build
# the C++ examples (the prefix's own copy, share/doc/hapsim/examples/cpp) against that prefix
# alone (CMAKE_PREFIX_PATH=prefix: not the build tree), run them, and check that their forces are
# `hapsim run`'s for the same scene and duration; then move the prefix elsewhere and check the
# installed `hapsim` runs the knee from it with no source tree (its scenes, config and libraries
# found from its own place: nothing read under the source folder), and that the installed Python
# package imports.
#   install_examples.sh BUILD_DIR SOURCE_DIR CMAKE PYTHON_OR_EMPTY
set -euo pipefail
build=$1
source_dir=$2
cmake=$3
python=${4:-}

work=$(mktemp -d "${TMPDIR:-/tmp}/hapsim-install-test.XXXXXX")
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
cd "$work"
# Nothing from the developer's environment points back at the tree.
unset HAPSIM_DATA CYCLONEDDS_URI PYTHONPATH CMAKE_PREFIX_PATH || true

fail() {
  echo "FAIL: $*" >&2
  exit 1
}
t0=$(date +%s)
"$cmake" --install "$build" --prefix "$prefix" >"$work/install.log" || {
  cat "$work/install.log"
  fail "cmake --install"
}
for f in bin/hapsim lib/cmake/hapsim/hapsimConfig.cmake lib/cmake/hapsim/hapsimConfigVersion.cmake \
  include/hapsim/world/world.h include/hapsim/device_driver.h include/hapsim/version.h \
  share/hapsim/scenes/knee.json share/hapsim/scenes/fem_block.json \
  share/hapsim/config/cyclonedds-loopback.xml share/doc/hapsim/cpp.md; do
  [[ -e $prefix/$f ]] || fail "$f not installed"
done

# The examples, configured and built against the prefix only.
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
"$cmake" -S "$prefix/share/doc/hapsim/examples/cpp" -B "$work/examples" "${generator[@]}" \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DCMAKE_FIND_USE_SYSTEM_PACKAGE_REGISTRY=OFF \
  >"$work/configure.log" 2>&1 || {
  cat "$work/configure.log"
  fail "configuring the examples against $prefix"
}
grep -q "hapsim_DIR:PATH=$prefix/lib/cmake/hapsim" "$work/examples/CMakeCache.txt" ||
  fail "find_package(hapsim) did not find the installed package: $(grep hapsim_DIR "$work/examples/CMakeCache.txt")"
"$cmake" --build "$work/examples" -j 2 >"$work/build.log" 2>&1 || {
  cat "$work/build.log"
  fail "building the examples"
}
t1=$(date +%s)
echo "installed and built the examples in $((t1 - t0)) s"

scenes=$prefix/share/hapsim/scenes
hapsim=$prefix/bin/hapsim
# The same forces as `hapsim run --json` ("tools": name, peak_force_n, mean_force_n, contact_steps).
compare() {  # OUTPUT JSON RELATIVE_TOLERANCE
  "$cmake" -DOUTPUT="$1" -DJSON="$2" -DTOLERANCE="$3" -P "$source_dir/tests/install/compare_forces.cmake"
}
"$work/examples/scene_forces/scene_forces" "$scenes/fem_block.json" 1.5 | tee "$work/forces.txt"
"$hapsim" run "$scenes/fem_block.json" --duration 1.5 --json "$work/run.json" >"$work/run.txt" 2>&1
compare "$work/forces.txt" "$work/run.json" 0

"$work/examples/haptic_loop/haptic_loop" "$scenes/csg_block.json" 1 | tee "$work/loop.txt"
"$hapsim" run "$scenes/csg_block.json" --duration 1 --json "$work/run_csg.json" >"$work/run_csg.txt" 2>&1
# Real time: the same cycles, unless the loop had to ramp a stall down on a loaded machine.
compare "$work/loop.txt" "$work/run_csg.json" 0.05
t2=$(date +%s)
echo "ran the examples in $((t2 - t1)) s"

# The prefix moved elsewhere: the installed hapsim runs the knee from it, reading nothing in the
# source tree (its scenes, config and libraries found relative to itself).
moved=$work/elsewhere/hapsim
mkdir -p "$work/elsewhere"
mv "$prefix" "$moved"
trace=()
if command -v strace >/dev/null && strace -f -qq -e trace=none true 2>/dev/null; then
  trace=(strace -f -qq -e trace=%file -o "$work/files.trace")
fi
"$moved/bin/hapsim" --version | tee "$work/version.txt"
grep -q "^hapsim [0-9]" "$work/version.txt" || fail "hapsim --version: $(cat "$work/version.txt")"
"${trace[@]}" "$moved/bin/hapsim" run "$moved/share/hapsim/scenes/knee.json" --duration 0.3 \
  >"$work/knee.txt" 2>&1 || {
  cat "$work/knee.txt"
  fail "the installed hapsim did not run the knee"
}
tail -n 3 "$work/knee.txt"
if grep -q "$source_dir" "$work/knee.txt"; then
  fail "the installed hapsim's output names the source tree: $(grep "$source_dir" "$work/knee.txt")"
fi
if ((${#trace[@]})); then
  if grep -v ENOENT "$work/files.trace" | grep -F "\"$source_dir/"; then
    fail "the installed hapsim opened files in the source tree (above)"
  fi
  echo "strace: no file under $source_dir opened"
fi
"$moved/bin/hapsim" doctor --json "$work/doctor.json" >/dev/null 2>&1 || true
if [[ -s $work/doctor.json ]] && grep -q "$source_dir/config" "$work/doctor.json"; then
  fail "hapsim doctor of the installed hapsim uses the source tree's DDS config"
fi

# The Python package, from the moved prefix (its module finds libhapsim_headless beside it).
if [[ -n $python && -d $moved/lib/python3/dist-packages/hapsim ]]; then
  PYTHONPATH=$moved/lib/python3/dist-packages "$python" -c \
    "import hapsim, sys; assert hapsim.__file__.startswith('$moved'), hapsim.__file__; print('python:', hapsim.__file__)"
fi
echo "PASS in $(($(date +%s) - t0)) s"
