#!/usr/bin/env bash
# Proves the Debian packages on a bare Debian 12 (docs/cpp.md, "Install the Debian packages"):
# builds them with cpack from a finished build, makes a minimal Debian 12 root (debootstrap
# minbase: no compiler, no libraries), and in it
#   apt-get install ./hapsim_*.deb ./python3-hapsim_*.deb      (Depends pulled from the archive)
#   hapsim run /usr/share/hapsim/scenes/knee.json               (the main job's scene, whole)
#   python3 -c "import hapsim"
#   apt-get install ./hapsim-dev_*.deb g++ make, then the C++ examples in
#   /usr/share/doc/hapsim/examples/cpp configured with find_package(hapsim), built and run.
# Usage (root, from the project's root, after scripts/run-tests.sh or a build):
#   bash scripts/check-package-debian.sh [BUILD_DIR]        (default build/release)
# ~5-10 min, most of it downloads (the minbase root is cached in $CHECK_DIR, default
# /tmp/hapsim-package-debian). Prints its verdict last; the log is $CHECK_DIR/run.log.
set -u
proj=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-$proj/build/release}
dir=${CHECK_DIR:-/tmp/hapsim-package-debian}
root=$dir/root
tgz=$dir/bookworm-minbase.tgz
[ "$(id -u)" -eq 0 ] || { echo "needs root (debootstrap, chroot)"; exit 2; }
[ -f "$build/CPackConfig.cmake" ] || { echo "no $build/CPackConfig.cmake: build first (bash scripts/run-tests.sh)"; exit 2; }
mkdir -p "$dir"

echo "building the packages (cpack, $build) ..."
rm -f "$build"/package/*.deb
cpack --config "$build/CPackConfig.cmake" >"$dir/cpack.log" 2>&1 || { echo "cpack failed: see $dir/cpack.log"; exit 2; }
debs=("$build"/package/*.deb)
[ -f "${debs[0]}" ] || { echo "cpack made no package: see $dir/cpack.log"; exit 2; }
ls -sh "${debs[@]}"

# The bare root, made once (the same minbase as ../shared/tools/check-fresh-debian.sh).
if [ ! -f "$tgz" ] && [ -f /tmp/fresh-debian/bookworm-minbase.tgz ]; then
  cp /tmp/fresh-debian/bookworm-minbase.tgz "$tgz"
fi
if [ ! -f "$tgz" ]; then
  echo "making a minimal Debian 12 root (debootstrap, a few minutes) ..."
  command -v debootstrap >/dev/null || { apt-get update -q >/dev/null; apt-get install -y -q debootstrap >/dev/null; }
  mirror=$(awk '/^URIs:/{print $2; exit}' /etc/apt/sources.list.d/*.sources 2>/dev/null)
  [ -n "$mirror" ] || mirror=$(awk '$1=="deb"{print $2; exit}' /etc/apt/sources.list 2>/dev/null)
  [ -n "$mirror" ] || { echo "no Debian mirror in this machine's apt sources"; exit 2; }
  rm -rf "$dir/boot-tmp"
  debootstrap --variant=minbase bookworm "$dir/boot-tmp" "$mirror" >"$dir/debootstrap.log" 2>&1 ||
    { echo "debootstrap failed: see $dir/debootstrap.log"; exit 2; }
  tar -C "$dir/boot-tmp" -czf "$tgz" . && rm -rf "$dir/boot-tmp"
fi
for m in proc sys dev; do mountpoint -q "$root/$m" 2>/dev/null && umount -l "$root/$m"; done
rm -rf "$root"; mkdir -p "$root" && tar -C "$root" -xzf "$tgz"
cp /etc/resolv.conf "$root/etc/resolv.conf"
mkdir -p "$root/tmp/debs" && cp "${debs[@]}" "$root/tmp/debs/"
mount -t proc proc "$root/proc"; mount --rbind /sys "$root/sys"; mount --rbind /dev "$root/dev"

# In the root: nothing of the project but the three .deb files.
cat >"$root/tmp/check.sh" <<'EOF'
set -eux
export DEBIAN_FRONTEND=noninteractive
cd /tmp
apt-get update -q
apt-get install -y -q --no-install-recommends ./debs/hapsim_*.deb ./debs/python3-hapsim_*.deb
hapsim --version
hapsim run /usr/share/hapsim/scenes/knee.json --json /tmp/knee.json
grep -q '"pop_throughs": 0' /tmp/knee.json
python3 -c "import hapsim, numpy; print('import hapsim:', hapsim.__file__)"
# The C++ quick start against the installed package (find_package from /usr).
apt-get install -y -q --no-install-recommends ./debs/hapsim-dev_*.deb g++ make
cmake -S /usr/share/doc/hapsim/examples/cpp -B /tmp/examples -DCMAKE_BUILD_TYPE=Release
cmake --build /tmp/examples -j 2
/tmp/examples/scene_forces/scene_forces /usr/share/hapsim/scenes/fem_block.json 1.0
echo "PACKAGE CHECK PASSED"
EOF
echo "installing and running the packages in the bare root (log: $dir/run.log) ..."
t0=$(date +%s)
chroot "$root" /usr/bin/env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
  bash /tmp/check.sh >"$dir/run.log" 2>&1
rc=$?
umount -l "$root/proc" "$root/sys" "$root/dev" 2>/dev/null
grep -E "^hapsim [0-9]|pop-throughs|import hapsim:|newly installed" "$dir/run.log" | head -8
if [ $rc -eq 0 ] && grep -q "PACKAGE CHECK PASSED" "$dir/run.log"; then
  echo "Debian packages on a bare Debian 12: OK in $(($(date +%s) - t0)) s ($(basename -a "${debs[@]}" | tr '\n' ' '))"
else
  echo "Debian packages on a bare Debian 12: FAILED (exit $rc); last lines of $dir/run.log:"
  tail -n 15 "$dir/run.log"
fi
exit $rc
