# The Debian packages (docs/cpp.md, "Install the Debian packages"): `cpack --config
# BUILD/CPackConfig.cmake` after a build turns the install rules' three components into
#   hapsim_<version>_amd64.deb         the `hapsim` command, the shared libraries, the scenes, the docs
#   hapsim-dev_<version>_amd64.deb     the headers, the CMake package, the C++ examples
#   python3-hapsim_<version>_amd64.deb the Python module
# all under /usr. Depends are found by dpkg-shlibdeps from the binaries themselves (libassimp5,
# libddsc0debian, libglfw3, ...), plus what no binary names: the Mesa drivers that GLVND loads at
# run time for pictures and the viewer, NumPy for the Python module, the -dev packages whose
# headers hapsim's headers include. tests/install/package_test.sh builds and checks them in CI;
# scripts/check-package-debian.sh installs them into a bare Debian 12 root.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME hapsim)
set(CPACK_PACKAGE_VENDOR "the hapsim developers")
set(CPACK_PACKAGE_CONTACT "hapsim developers <hapsim@localhost>")
set(CPACK_RESOURCE_FILE_LICENSE "${PROJECT_SOURCE_DIR}/LICENSE")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_PACKAGE_DIRECTORY "${PROJECT_BINARY_DIR}/package")
set(CPACK_COMPONENTS_ALL runtime dev python)
set(CPACK_DEB_COMPONENT_INSTALL ON)
# hapsim-dev and python3-hapsim depend on hapsim of the same version.
set(CPACK_DEBIAN_ENABLE_COMPONENT_DEPENDS ON)
# hapsim_0.1.0_amd64.deb: the package's name, version and architecture, as Debian names files.
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# dpkg-shlibdeps resolves $ORIGIN run paths as installed (/usr/lib), where our own libraries are
# not yet: it finds them in the runtime component's staging folder (each component is staged in a
# sibling folder and dpkg-shlibdeps runs in its own); which package holds them is said by the
# components' Depends below. The shlibs file lets other packages depend on ours the same way.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS_PRIVATE_DIRS "../runtime/usr/${CMAKE_INSTALL_LIBDIR}")
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS ON)
set(CPACK_DEBIAN_COMPRESSION_TYPE gzip)

set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME hapsim)
set(CPACK_DEBIAN_RUNTIME_DESCRIPTION
    "The hapsim command, its shared libraries, scenes and docs
hapsim runs haptic scenes (a device touching rigid and FEM-deformable bodies at 1 kHz):
`hapsim run /usr/share/hapsim/scenes/knee.json` palpates a real knee's FEM tissue.")
# GLVND loads Mesa's EGL (offscreen pictures) and GLX (the viewer) drivers by name at run time.
set(CPACK_DEBIAN_RUNTIME_PACKAGE_DEPENDS "libegl-mesa0, libgl1-mesa-dri, libglx-mesa0")
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SUGGESTS "xvfb, python3-matplotlib")

set(CPACK_DEBIAN_DEV_PACKAGE_NAME hapsim-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_DEV_DESCRIPTION
    "Headers and the CMake package, to build C++ programs on hapsim
find_package(hapsim CONFIG) gives hapsim::headless, hapsim::render, hapsim::net and hapsim::ui;
the C++ examples are in /usr/share/doc/hapsim/examples/cpp.")
set(CPACK_COMPONENT_DEV_DEPENDS runtime)
# What hapsimConfig.cmake finds (find_dependency) and hapsim's public headers include.
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS
    "cmake, libeigen3-dev, libspdlog-dev, nlohmann-json3-dev, libgl-dev, libopengl-dev, libegl-dev, cyclonedds-dev, cyclonedds-tools")

set(CPACK_DEBIAN_PYTHON_PACKAGE_NAME python3-hapsim)
set(CPACK_DEBIAN_PYTHON_PACKAGE_SECTION python)
set(CPACK_DEBIAN_PYTHON_DESCRIPTION
    "The hapsim Python module
`import hapsim`: load scenes, step worlds and read forces as NumPy arrays.")
set(CPACK_COMPONENT_PYTHON_DEPENDS runtime)
if(HAPSIM_PYTHON_MODULE)
  # The extension is built for this Python's ABI (cpython-3XY): 3.11 <= python3 < 3.12.
  string(REPLACE "." ";" _py_parts "${HAPSIM_PYTHON_VERSION}")
  list(GET _py_parts 0 _py_major)
  list(GET _py_parts 1 _py_minor)
  math(EXPR _py_next "${_py_minor} + 1")
  set(CPACK_DEBIAN_PYTHON_PACKAGE_DEPENDS
      "python3 (>= ${HAPSIM_PYTHON_VERSION}), python3 (<< ${_py_major}.${_py_next}), python3-numpy")
else()
  # No module was built: no python3-hapsim package.
  list(REMOVE_ITEM CPACK_COMPONENTS_ALL python)
endif()

include(CPack)
