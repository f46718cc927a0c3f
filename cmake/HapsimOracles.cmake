# Reference libraries used ONLY by tests and benchmarks (never by the product's contact code):
# CGAL (AABB_tree closest point), FCL (BVHModel<OBBRSS> distance), Embree (rtcPointQuery).
# HAPSIM_REQUIRE_ORACLES (default ON; scripts/setup.sh installs them all) makes a missing one a
# configure error naming its Debian package, so a missing install step cannot pass as skipped
# tests. With it OFF each is optional: its oracle tests skip and its benchmark rows are left out.
# They are wrapped behind one small interface (oracles/closest_point_oracle.h) so their heavy
# headers compile in one translation unit each.
find_package(CGAL QUIET)
find_package(fcl QUIET)
find_package(embree 3 QUIET)
# orocos-kdl (kinematics oracle): plain find_path/find_library, as its CMake config and
# kdl_parser's pull in ROS; the tests read the URDF with urdfdom themselves.
find_path(KDL_INCLUDE_DIR kdl/chain.hpp)
find_library(KDL_LIBRARY orocos-kdl)
if(KDL_INCLUDE_DIR AND KDL_LIBRARY)
  set(KDL_FOUND TRUE)
else()
  set(KDL_FOUND FALSE)
endif()
message(STATUS "hapsim oracles: CGAL=${CGAL_FOUND} FCL=${fcl_FOUND} Embree=${embree_FOUND} KDL=${KDL_FOUND}")
if(HAPSIM_REQUIRE_ORACLES)
  set(_missing "")
  foreach(_pair "CGAL_FOUND:libcgal-dev" "fcl_FOUND:libfcl-dev" "embree_FOUND:libembree-dev"
                "KDL_FOUND:liborocos-kdl-dev")
    string(REPLACE ":" ";" _pair "${_pair}")
    list(GET _pair 0 _var)
    list(GET _pair 1 _package)
    if(NOT ${_var})
      list(APPEND _missing "${_package}")
    endif()
  endforeach()
  if(_missing)
    message(FATAL_ERROR "reference oracles missing: install ${_missing} (scripts/setup.sh does), "
                        "or configure with -DHAPSIM_REQUIRE_ORACLES=OFF to skip their tests")
  endif()
endif()

set(_oracle_sources "${CMAKE_SOURCE_DIR}/oracles/closest_point_oracle.cpp")
# Each adapter is added only once its file exists, so a partial checkout still configures.
add_library(hapsim_oracles STATIC)
target_include_directories(hapsim_oracles PUBLIC "${CMAKE_SOURCE_DIR}")
target_link_libraries(hapsim_oracles PUBLIC hapsim::headless)
hapsim_set_warnings(hapsim_oracles)
if(CGAL_FOUND AND EXISTS "${CMAKE_SOURCE_DIR}/oracles/cgal_oracle.cpp")
  list(APPEND _oracle_sources "${CMAKE_SOURCE_DIR}/oracles/cgal_oracle.cpp")
  target_link_libraries(hapsim_oracles PRIVATE CGAL::CGAL)
  target_compile_definitions(hapsim_oracles PUBLIC HAPSIM_HAVE_CGAL=1)
endif()
if(fcl_FOUND AND EXISTS "${CMAKE_SOURCE_DIR}/oracles/fcl_oracle.cpp")
  list(APPEND _oracle_sources "${CMAKE_SOURCE_DIR}/oracles/fcl_oracle.cpp")
  target_link_libraries(hapsim_oracles PRIVATE fcl)
  target_compile_definitions(hapsim_oracles PUBLIC HAPSIM_HAVE_FCL=1)
endif()
if(embree_FOUND AND EXISTS "${CMAKE_SOURCE_DIR}/oracles/embree_oracle.cpp")
  list(APPEND _oracle_sources "${CMAKE_SOURCE_DIR}/oracles/embree_oracle.cpp")
  target_link_libraries(hapsim_oracles PRIVATE embree)
  target_compile_definitions(hapsim_oracles PUBLIC HAPSIM_HAVE_EMBREE=1)
endif()
if(KDL_FOUND)
  target_include_directories(hapsim_oracles PUBLIC "${KDL_INCLUDE_DIR}")
  target_link_libraries(hapsim_oracles PUBLIC "${KDL_LIBRARY}" urdfdom::urdfdom_model)
  target_compile_definitions(hapsim_oracles PUBLIC HAPSIM_HAVE_KDL=1)
endif()
target_sources(hapsim_oracles PRIVATE ${_oracle_sources})
