# `cmake --install BUILD --prefix P` (docs/cpp.md): the `hapsim` command in P/bin, the libraries in
# P/lib (shared, libhapsim_<name>.so.0.1), their headers in P/include/hapsim/... (the same include
# paths as in the tree), the CMake package P/lib/cmake/hapsim that `find_package(hapsim 0.1 CONFIG)`
# reads (imported targets hapsim::headless, hapsim::render, hapsim::net, hapsim::ui, ...), the
# scenes and the loopback config in P/share/hapsim (which an installed `hapsim` finds from its own
# place, hapsim/core/install_dirs.h), the docs in P/share/doc/hapsim; the Python package is
# installed by python/CMakeLists.txt.
include(CMakePackageConfigHelpers)

set(HAPSIM_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/hapsim" CACHE STRING
    "Where `cmake --install` puts hapsimConfig.cmake (relative to the prefix)")
set(HAPSIM_INSTALL_DATADIR "${CMAKE_INSTALL_DATADIR}/hapsim")

set(_hapsim_libraries hapsim_headless hapsim_render hapsim_net_types hapsim_net hapsim_ui)
set(HAPSIM_WITH_SPNAV OFF)
if(TARGET hapsim_spacenav)
  list(APPEND _hapsim_libraries hapsim_spacenav)
  set(HAPSIM_WITH_SPNAV ON)
endif()

# Installed binaries find the libraries relative to themselves, wherever the prefix is copied.
function(_hapsim_relative_rpath out from_dir)
  if(IS_ABSOLUTE "${from_dir}" OR IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}")
    set(${out} "${CMAKE_INSTALL_FULL_LIBDIR}" PARENT_SCOPE)
  else()
    file(RELATIVE_PATH _rel "/prefix/${from_dir}" "/prefix/${CMAKE_INSTALL_LIBDIR}")
    set(${out} "$ORIGIN/${_rel}" PARENT_SCOPE)
  endif()
endfunction()
_hapsim_relative_rpath(_bin_rpath "${CMAKE_INSTALL_BINDIR}")
set_target_properties(hapsim PROPERTIES INSTALL_RPATH "${_bin_rpath}")
set_target_properties(${_hapsim_libraries} PROPERTIES INSTALL_RPATH "$ORIGIN")
if(TARGET hapsim_python)
  _hapsim_relative_rpath(_python_rpath "${HAPSIM_PYTHON_INSTALL_DIR}/hapsim")
  set_target_properties(hapsim_python PROPERTIES INSTALL_RPATH "${_python_rpath}")
endif()

install(TARGETS hapsim RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}" COMPONENT runtime)
install(TARGETS ${_hapsim_libraries} EXPORT hapsimTargets
        LIBRARY DESTINATION "${CMAKE_INSTALL_LIBDIR}" COMPONENT runtime NAMELINK_COMPONENT dev
        ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}" COMPONENT dev
        RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}" COMPONENT runtime
        INCLUDES DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}")

# Headers: every layer's (a world header includes core, geometry, collision, ...), the drivers' C
# ABI, the generated version and DDS message headers. docs/cpp.md says which are stable in 0.x.
install(DIRECTORY "${PROJECT_SOURCE_DIR}/src/hapsim" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}"
        COMPONENT dev FILES_MATCHING PATTERN "*.h" PATTERN "idl" EXCLUDE)
install(FILES "${PROJECT_SOURCE_DIR}/include/hapsim/device_driver.h"
              "${PROJECT_BINARY_DIR}/include/hapsim/version.h"
        DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/hapsim" COMPONENT dev)
install(FILES "${PROJECT_BINARY_DIR}/src/hapsim_messages.h"
        DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/hapsim/net/generated" COMPONENT dev)

# The package: targets, their dependencies (hapsimConfig.cmake.in), the version (0.1.x matches 0.1).
install(EXPORT hapsimTargets NAMESPACE hapsim:: DESTINATION "${HAPSIM_INSTALL_CMAKEDIR}"
        COMPONENT dev)
configure_package_config_file("${PROJECT_SOURCE_DIR}/cmake/hapsimConfig.cmake.in"
                              "${PROJECT_BINARY_DIR}/hapsimConfig.cmake"
                              INSTALL_DESTINATION "${HAPSIM_INSTALL_CMAKEDIR}")
write_basic_package_version_file("${PROJECT_BINARY_DIR}/hapsimConfigVersion.cmake"
                                 COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/hapsimConfig.cmake"
              "${PROJECT_BINARY_DIR}/hapsimConfigVersion.cmake"
        DESTINATION "${HAPSIM_INSTALL_CMAKEDIR}" COMPONENT dev)

# Shipped data: the scenes with their meshes, the loopback-only DDS config, the report script.
install(DIRECTORY "${PROJECT_SOURCE_DIR}/scenes/" DESTINATION "${HAPSIM_INSTALL_DATADIR}/scenes"
        COMPONENT runtime)
install(FILES "${PROJECT_SOURCE_DIR}/config/cyclonedds-loopback.xml"
        DESTINATION "${HAPSIM_INSTALL_DATADIR}/config" COMPONENT runtime)
install(FILES "${PROJECT_SOURCE_DIR}/python/hapsim/assessment_report.py"
        DESTINATION "${HAPSIM_INSTALL_DATADIR}" COMPONENT runtime)
# The docs, with the C++ examples (docs/cpp.md) beside them.
install(DIRECTORY "${PROJECT_SOURCE_DIR}/docs/" DESTINATION "${CMAKE_INSTALL_DOCDIR}"
        COMPONENT runtime)
install(FILES "${PROJECT_SOURCE_DIR}/README.md" "${PROJECT_SOURCE_DIR}/LICENSE"
        DESTINATION "${CMAKE_INSTALL_DOCDIR}" COMPONENT runtime)
install(DIRECTORY "${PROJECT_SOURCE_DIR}/examples/cpp/" DESTINATION "${CMAKE_INSTALL_DOCDIR}/examples/cpp"
        COMPONENT dev)
