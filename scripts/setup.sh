#!/usr/bin/env bash
# Installs the Debian packages hapsim needs (only the missing ones), then configures and builds.
# Works on a bare Debian 12 (no compiler, no cmake yet); uses sudo only when not root.
# Sourced by run-main.sh and run-tests.sh; can also be run on its own.
set -euo pipefail

HAPSIM_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
HAPSIM_PRESET="${HAPSIM_PRESET:-release}"
HAPSIM_BUILD_DIR="${HAPSIM_ROOT}/build/${HAPSIM_PRESET}"

HAPSIM_PACKAGES=(
  # Each line names what CMake (or a test, or the main job) looks for; checked on a bare Debian 12
  # with ../shared/tools/check-fresh-debian.sh, so nothing is assumed from the machine.
  # toolchain: gcc/g++/make, cmake, ninja, pkg-config (stb, imgui and spnav are found through it)
  build-essential cmake ninja-build pkg-config
  # product libraries: find_package(Eigen3, assimp, urdfdom, nlohmann_json, CLI11, spdlog)
  libeigen3-dev libassimp-dev liburdfdom-dev nlohmann-json3-dev libcli11-dev libspdlog-dev
  # find_package(meshoptimizer): mesh simplification (hapsim simplify, display levels of detail)
  libmeshoptimizer-dev
  # find_package(OpenGL COMPONENTS OpenGL EGL GLX): GL/gl.h and KHR/ (libgl-dev), libOpenGL.so
  # (libopengl-dev, GLVND's OpenGL library: the renderer links it, not libGL), EGL/egl.h and
  # libEGL.so (libegl-dev); GL/glx.h and libGLX.so (libglx-dev, a dependency of libgl-dev: the
  # viewer presents part of its window with GLX_MESA_copy_sub_buffer)
  libgl-dev libopengl-dev libegl-dev
  # at run time GLVND dispatches to Mesa: EGL surfaceless for headless pictures (libegl-mesa0),
  # GLX under Xvfb for the viewer (libglx-mesa0), llvmpipe, the software rasteriser (libgl1-mesa-dri)
  libegl-mesa0 libglx-mesa0 libgl1-mesa-dri
  # the viewer: find_package(glfw3), pkg-config imgui (Dear ImGui with its GLFW/OpenGL3 backends),
  # stb (PNG), spnav (a 3D mouse; optional in CMake, installed so the viewer offers it)
  libglfw3-dev libimgui-dev libstb-dev libspnav-dev
  # the viewer's smoke test: xvfb-run (xvfb, which needs xauth) and xdotool for the real X pointer
  xvfb xauth xdotool
  # the network layer (net/): find_package(CycloneDDS) for libddsc and its headers, and idlc
  # (cyclonedds-tools) that idlc_generate runs at build time on the topics' IDL
  cyclonedds-dev cyclonedds-tools
  # secure sessions (net/security_keys): find_package(OpenSSL) for keys, X.509 and S/MIME
  # signatures; Cyclone's own security plugins (libddsc0debian) already depend on libssl3
  libssl-dev
  # the Debian packages (cpack's DEB generator, and its test): `file` tells cpack which files are
  # binaries for dpkg-shlibdeps (itself in dpkg-dev, which build-essential brings)
  file
  # tests and benchmarks: find_package(GTest) with GMock, find_package(benchmark), and
  # find_package(ZLIB) for the golden run traces (tests/golden/*.trace.gz)
  libgtest-dev libgmock-dev libbenchmark-dev zlib1g-dev
  # the papers' figures (scripts/make-figures.sh, and its test): the Gaussian profile plot is drawn
  # by Debian's python3 with matplotlib
  python3-matplotlib
  # reference oracles for tests and benchmarks only (HAPSIM_REQUIRE_ORACLES: configure fails
  # without them rather than skipping their tests): CGAL, FCL, Embree 3, orocos-kdl
  libcgal-dev libfcl-dev libembree-dev liborocos-kdl-dev
  # CalculiX (find_program(ccx)): the FEM body's oracle, a separate GPL program the deform oracle
  # tests run on the same tet mesh (never linked)
  calculix-ccx
  # TetGen (a separate GPL program, never linked): scripts/derive-knee-fem.sh meshes the FEM knee
  # with it, and a test re-runs that script to check the committed mesh is what it derives
  tetgen
  # the Python module (python/): Python's headers and find_package(pybind11) build it; NumPy for
  # its arrays; pytest runs its tests under ctest; the examples' plots use the matplotlib above
  python3-dev python3-numpy pybind11-dev python3-pytest
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
  local started=$SECONDS
  if [ ! -f "${HAPSIM_BUILD_DIR}/build.ninja" ]; then
    cmake --preset "$HAPSIM_PRESET"
  fi
  cmake --build --preset "$HAPSIM_PRESET"
  echo "hapsim: build up to date in $((SECONDS - started)) s (${HAPSIM_BUILD_DIR})"
}

if [ "${BASH_SOURCE[0]}" = "$0" ]; then
  hapsim_install_packages
  hapsim_build
fi
