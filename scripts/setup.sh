#!/usr/bin/env bash
# Installs the Debian packages hapsim needs (only the missing ones), then configures and builds.
# Works on a bare Debian 12 (no compiler, no cmake yet); uses sudo only when not root.
# Sourced by run-main.sh and run-tests.sh; can also be run on its own.
set -euo pipefail

HAPSIM_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
HAPSIM_PRESET="${HAPSIM_PRESET:-release}"
HAPSIM_BUILD_DIR="${HAPSIM_ROOT}/build/${HAPSIM_PRESET}"

HAPSIM_PACKAGES=(
  # toolchain
  build-essential cmake ninja-build pkg-config
  # product libraries
  libeigen3-dev libassimp-dev liburdfdom-dev nlohmann-json3-dev libcli11-dev libspdlog-dev
  # viewer and headless rendering: GLFW + OpenGL + Dear ImGui, EGL surfaceless on Mesa's software
  # rasterizer, stb for PNG, libspnav for a 3D mouse; Xvfb + xauth for the viewer's smoke test
  libglfw3-dev libgl-dev libegl-dev libgl1-mesa-dri libimgui-dev libstb-dev libspnav-dev xvfb xauth
  # the viewer smoke test moves the real X pointer with xdotool
  xdotool
  # tests and benchmarks; CGAL, FCL, Embree and orocos-kdl are reference oracles only
  libgtest-dev libgmock-dev libbenchmark-dev libcgal-dev libfcl-dev libembree-dev liborocos-kdl-dev
)

hapsim_install_packages() {
  local missing=() p
  for p in "${HAPSIM_PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$p")
    fi
  done
  if ((${#missing[@]} == 0)); then
    return 0
  fi
  local sudo=()
  if [ "$(id -u)" -ne 0 ]; then
    sudo=(sudo)
  fi
  echo "hapsim: installing ${#missing[@]} Debian package(s): ${missing[*]}"
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
}

hapsim_build() {
  cd "$HAPSIM_ROOT"
  if [ ! -f "${HAPSIM_BUILD_DIR}/build.ninja" ]; then
    cmake --preset "$HAPSIM_PRESET"
  fi
  cmake --build --preset "$HAPSIM_PRESET"
}

if [ "${BASH_SOURCE[0]}" = "$0" ]; then
  hapsim_install_packages
  hapsim_build
fi
