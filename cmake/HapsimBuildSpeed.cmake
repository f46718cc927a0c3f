# What keeps a cold build (CI builds everything from a fresh clone on two cores, docs/benchmarks.md#build-time)
# short, without touching what the library computes:
#  - precompiled headers: the standard and Eigen headers that nearly every file includes, parsed
#    once per library instead of once per file; the tests share one, with GoogleTest added;
#  - unity builds of the targets with the most files (the headless library, the app, each layer's
#    tests): files compiled in batches of 8, so our own headers, GoogleTest's and their template
#    instances are compiled once per batch;
#  - test code at -O1 (release): tests assert no wall-clock time and the library they call keeps
#    the release flags; -O3 on gtest's macro-expanded bodies only cost compile time.
# nlohmann/json stays out of the precompiled headers on purpose: a fifth of the files include
# it, and the larger header costs the other four fifths more to load than it saves.
option(HAPSIM_CCACHE "Compile through ccache when it is installed (a warm rebuild in seconds)" ON)
option(HAPSIM_PCH "Precompile the standard, Eigen and GoogleTest headers (a faster cold build)" ON)
option(HAPSIM_UNITY_BUILD "Compile the headless library, the app and the tests in batches of files (a faster cold build)" ON)

# ccache, when present (not installed by scripts/setup.sh: a bare machine builds without it), and
# unless a launcher was chosen: a build folder rebuilt from nothing (`rm -rf build`, a second CI
# run of the same clone) takes its objects from the cache. Depend mode: a miss costs one compile,
# not a preprocessor run and a compile, so a cold cache adds next to nothing. base_dir at the
# source folder makes the include paths relative, so a clone elsewhere (CI's) shares the cache for
# the release files whose command and contents are the same there: not the batched files of a
# unity build (they name their sources by absolute path), not the tests (HAPSIM_SOURCE_DIR), and
# nothing built with -g (the folder is then hashed: 5 of 40 sanitizer objects hit from another
# clone, 40 of 40 in the same folder). The precompiled headers need the pch sloppiness (ccache
# manual, "Precompiled headers").
if(HAPSIM_CCACHE AND NOT CMAKE_CXX_COMPILER_LAUNCHER)
  find_program(HAPSIM_CCACHE_PROGRAM ccache)
  if(HAPSIM_CCACHE_PROGRAM)
    set(_ccache ${CMAKE_COMMAND} -E env CCACHE_BASEDIR=${CMAKE_SOURCE_DIR} CCACHE_DEPEND=1
                "CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime"
                ${HAPSIM_CCACHE_PROGRAM})
    set(CMAKE_C_COMPILER_LAUNCHER ${_ccache})
    set(CMAKE_CXX_COMPILER_LAUNCHER ${_ccache})
    message(STATUS "hapsim: compiling through ${HAPSIM_CCACHE_PROGRAM} (HAPSIM_CCACHE=OFF to not)")
  endif()
endif()

set(HAPSIM_PCH_HEADERS
    <algorithm> <array> <atomic> <chrono> <cmath> <cstdint> <filesystem> <fstream> <limits>
    <memory> <optional> <span> <string> <vector> <Eigen/Core> <Eigen/Geometry>)

# GCC 12 reports std::string concatenations inside libstdc++ as out of bounds once enough is
# inlined (GCC bugs 105329, 105651: false positives): at -O1 in the tests, and at -O3 across the
# app's batched files. The library's own files keep these warnings.
set(HAPSIM_GCC12_FALSE_POSITIVES -Wno-array-bounds -Wno-stringop-overflow -Wno-stringop-overread
                                 -Wno-restrict)

# The headers as C++-only generator expressions (some targets also compile C: the drivers' ABI
# header, Cyclone's generated types); $<ANGLE-R> writes a header's closing bracket inside one.
function(_hapsim_pch_expressions out)
  set(_headers ${ARGN})
  list(TRANSFORM _headers REPLACE "^<(.*)>$" "$<$<COMPILE_LANGUAGE:CXX>:<\\1$<ANGLE-R>>")
  set(${out} ${_headers} PARENT_SCOPE)
endfunction()

# A library's own precompiled header.
function(hapsim_precompile_headers target)
  if(HAPSIM_PCH)
    _hapsim_pch_expressions(_headers ${HAPSIM_PCH_HEADERS})
    target_precompile_headers(${target} PRIVATE ${_headers})
  endif()
endfunction()

# A unity build of `target` in batches of 8; SKIP files (their anonymous-namespace types would meet
# another file's) are compiled alone.
function(hapsim_unity_build target)
  cmake_parse_arguments(_unity "" "" "SKIP" ${ARGN})
  if(HAPSIM_UNITY_BUILD)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
    if(_unity_SKIP)
      set_source_files_properties(${_unity_SKIP} TARGET_DIRECTORY ${target}
                                  PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
    endif()
  endif()
endfunction()

# The test executables' code flags; `support` is the library every test links (its include
# folders and definitions are the precompiled header's). The first call makes the shared header.
function(hapsim_test_code target support)
  target_compile_options(${target} PRIVATE "$<$<CONFIG:Release>:-O1;${HAPSIM_GCC12_FALSE_POSITIVES}>")
  if(NOT HAPSIM_PCH)
    return()
  endif()
  if(NOT TARGET hapsim_test_pch)
    set(_anchor "${CMAKE_CURRENT_BINARY_DIR}/hapsim_test_pch.cpp")
    file(WRITE "${_anchor}" "// The tests' shared precompiled header is built with this file.\n")
    add_library(hapsim_test_pch OBJECT "${_anchor}")
    target_link_libraries(hapsim_test_pch PRIVATE ${support})
    hapsim_set_warnings(hapsim_test_pch)
    target_compile_options(hapsim_test_pch
                           PRIVATE "$<$<CONFIG:Release>:-O1;${HAPSIM_GCC12_FALSE_POSITIVES}>")
    _hapsim_pch_expressions(_headers ${HAPSIM_PCH_HEADERS} <gtest/gtest.h>)
    target_precompile_headers(hapsim_test_pch PRIVATE ${_headers})
  endif()
  target_precompile_headers(${target} REUSE_FROM hapsim_test_pch)
endfunction()

# The names a test file declares at namespace scope, where clang-format leaves them at column 0:
# functions, variables, types, and aliases with what they alias (the same alias in two files is no
# clash); a using-declaration names nothing new.
function(_hapsim_namespace_scope_names file out)
  file(STRINGS "${file}" _lines REGEX "^[A-Za-z[]")
  set(_names "")
  foreach(_line IN LISTS _lines)
    string(REGEX REPLACE "^\\[\\[[a-z_]+\\]\\] " "" _line "${_line}")
    if(_line MATCHES "^(TEST|TYPED_TEST|INSTANTIATE_|GTEST|HAPSIM_|namespace |template|extern |static_assert)"
       OR _line MATCHES "^using [A-Za-z0-9_:]+;")
      continue()
    elseif(_line MATCHES "^using ([A-Za-z_][A-Za-z0-9_]*) = (.*);")
      string(REPLACE " " "" _aliased "${CMAKE_MATCH_2}")
      list(APPEND _names "${CMAKE_MATCH_1}=${_aliased}")
    elseif(_line MATCHES "^(struct|class|enum class|enum|union) ([A-Za-z_][A-Za-z0-9_]*)")
      list(APPEND _names "${CMAKE_MATCH_2}")
    elseif(_line MATCHES "^[^=(]*[ *&]([A-Za-z_][A-Za-z0-9_]*) *(=|{|;|\\[)")
      list(APPEND _names "${CMAKE_MATCH_1}")
    elseif(_line MATCHES "([A-Za-z_][A-Za-z0-9_]*)\\(")
      list(APPEND _names "${CMAKE_MATCH_1}")
    endif()
  endforeach()
  set(${out} ${_names} PARENT_SCOPE)
endfunction()

# A unity build of a test executable. Test files keep their helpers in anonymous namespaces, which a
# batch merges: two files' `kScene` would not compile, and two files' `at(...)` of different
# parameters would overload each other and a call could take the other file's. So a file that
# declares a name an earlier file of the target declares (or aliases it to another type) is
# compiled alone; the rest in batches.
function(hapsim_unity_tests target)
  if(NOT HAPSIM_UNITY_BUILD)
    return()
  endif()
  get_target_property(_sources ${target} SOURCES)
  set(_plain "")        # names declared so far, not aliases
  set(_aliases "")      # aliases so far, as name=type
  set(_alias_names "")  # their names
  set(_alone "")
  foreach(_source IN LISTS _sources)
    _hapsim_namespace_scope_names("${_source}" _names)
    set(_clash FALSE)
    foreach(_name IN LISTS _names)
      if(_name MATCHES "^([^=]*)=")
        set(_bare "${CMAKE_MATCH_1}")
        if(_bare IN_LIST _plain OR (_bare IN_LIST _alias_names AND NOT _name IN_LIST _aliases))
          set(_clash TRUE)
        endif()
      elseif(_name IN_LIST _plain OR _name IN_LIST _alias_names)
        set(_clash TRUE)
      endif()
    endforeach()
    if(_clash)
      list(APPEND _alone "${_source}")
      continue()
    endif()
    foreach(_name IN LISTS _names)
      if(_name MATCHES "^([^=]*)=")
        list(APPEND _aliases "${_name}")
        list(APPEND _alias_names "${CMAKE_MATCH_1}")
      else()
        list(APPEND _plain "${_name}")
      endif()
    endforeach()
  endforeach()
  list(LENGTH _sources _count)
  list(LENGTH _alone _alone_count)
  message(VERBOSE "hapsim: ${target}: ${_alone_count} of ${_count} files compiled alone")
  hapsim_unity_build(${target} SKIP ${_alone})
endfunction()
