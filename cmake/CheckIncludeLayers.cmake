# The layer rule of docs/architecture.md, checked mechanically (a ctest runs this script):
# a file under src/hapsim/<folder>/ may include "hapsim/<other>/..." only when <other>'s layer is
# the same or lower, and the headless layers (core … runtime) include no display or network
# library. A folder missing from the table below is an error too: a new folder must be given
# its layer here and in docs/architecture.md.
#
#   cmake -DSOURCE_DIR=<dir holding src/hapsim> -P CheckIncludeLayers.cmake
cmake_minimum_required(VERSION 3.22)
if(NOT SOURCE_DIR)
  message(FATAL_ERROR "give -DSOURCE_DIR=<project root>")
endif()

# folder -> layer (lower may be included by higher, never the other way round), ten times the
# layer of docs/architecture.md: layer 5's folders are ordered among themselves (5.0 script <
# 5.1 device < 5.2 scene < 5.3 runtime < 5.4 training), so an include between them is checked too.
set(_layer_core 0)
set(_layer_geometry 10)
set(_layer_collision 20)
set(_layer_force 30)
set(_layer_deform 30)
set(_layer_kinematics 30)
set(_layer_rig 45)
set(_layer_world 40)
set(_layer_script 50)
set(_layer_device 51)
set(_layer_scene 52)
set(_layer_runtime 53)
set(_layer_training 54)
set(_layer_net 60)
set(_layer_render 70)
set(_layer_ui 70)
set(_headless_max 54)
# Headers a headless layer must not include (display, GUI, network middleware).
set(_not_headless "GL/" "GLFW/" "EGL/" "imgui" "backends/imgui" "dds/")

# 52 -> "5.2", 40 -> "4": the layer as docs/architecture.md writes it.
function(_layer_name value out)
  math(EXPR _major "${value} / 10")
  math(EXPR _minor "${value} % 10")
  if(_minor EQUAL 0)
    set(${out} "${_major}" PARENT_SCOPE)
  else()
    set(${out} "${_major}.${_minor}" PARENT_SCOPE)
  endif()
endfunction()

get_filename_component(SOURCE_DIR "${SOURCE_DIR}" ABSOLUTE)
file(GLOB_RECURSE _files RELATIVE "${SOURCE_DIR}/src/hapsim" "${SOURCE_DIR}/src/hapsim/*.h"
     "${SOURCE_DIR}/src/hapsim/*.cpp")
set(_violations 0)
foreach(_file IN LISTS _files)
  string(REGEX MATCH "^[^/]+" _folder "${_file}")
  if(NOT DEFINED _layer_${_folder})
    message(SEND_ERROR "src/hapsim/${_file}: folder '${_folder}' has no layer "
                       "(add it to cmake/CheckIncludeLayers.cmake and docs/architecture.md)")
    math(EXPR _violations "${_violations} + 1")
    continue()
  endif()
  set(_mine ${_layer_${_folder}})
  _layer_name(${_mine} _mine_name)
  file(STRINGS "${SOURCE_DIR}/src/hapsim/${_file}" _includes REGEX "^[ \t]*#[ \t]*include[ \t]*[\"<]")
  foreach(_line IN LISTS _includes)
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*[\"<]([^\">]+)[\">].*$" "\\1" _header "${_line}")
    if(_header MATCHES "^hapsim/([^/]+)/")
      set(_other "${CMAKE_MATCH_1}")
      if(NOT DEFINED _layer_${_other})
        message(SEND_ERROR "src/hapsim/${_file}: includes ${_header} from unknown folder '${_other}'")
        math(EXPR _violations "${_violations} + 1")
      elseif(${_layer_${_other}} GREATER ${_mine})
        _layer_name(${_layer_${_other}} _other_name)
        message(SEND_ERROR "src/hapsim/${_file}: ${_folder} (layer ${_mine_name}) includes ${_header} "
                           "from ${_other} (layer ${_other_name}): layers include only downward")
        math(EXPR _violations "${_violations} + 1")
      endif()
    elseif(_mine LESS_EQUAL _headless_max)
      foreach(_prefix IN LISTS _not_headless)
        string(FIND "${_header}" "${_prefix}" _at)
        if(_at EQUAL 0)
          message(SEND_ERROR "src/hapsim/${_file}: headless layer '${_folder}' includes <${_header}> "
                             "(display or network code belongs in render/, ui/ or net/)")
          math(EXPR _violations "${_violations} + 1")
        endif()
      endforeach()
    endif()
  endforeach()
endforeach()
list(LENGTH _files _count)
if(_violations GREATER 0)
  message(FATAL_ERROR "${_violations} include(s) break the layer rule (docs/architecture.md)")
endif()
message(STATUS "include layers: ${_count} files, every include goes downward")
