# Precompiled headers: the standard, Eigen and (in tests) GoogleTest headers that nearly every file
# includes, parsed once per target instead of once per file. Measured on the 2-core machine
# (docs/benchmarks.md#build-time): about 1 s saved per library file and 2-3 s per test file.
# nlohmann/json is left out on purpose: a fifth of the files include it, and the larger
# precompiled header costs the other four fifths more to load than it saves.
option(HAPSIM_PCH "Precompile the standard, Eigen and GoogleTest headers (a faster cold build)" ON)

set(HAPSIM_PCH_HEADERS
    <algorithm> <array> <atomic> <chrono> <cmath> <cstdint> <filesystem> <fstream> <limits>
    <memory> <optional> <span> <string> <vector> <Eigen/Core> <Eigen/Geometry>)

# hapsim_precompile_headers(target [TEST]): TEST adds <gtest/gtest.h> and builds the test code
# itself at -O1 in a release build. Test code does no timed work (tests assert no wall-clock
# time), and the library it calls keeps the release flags; -O3 on gtest's macro-expanded bodies
# only cost compile time.
function(hapsim_precompile_headers target)
  cmake_parse_arguments(_pch "TEST" "" "" ${ARGN})
  if(_pch_TEST)
    # GCC 12 at -O1 reports std::string concatenations inside libstdc++ as out of bounds (GCC bugs
    # 105329, 105651: false positives); the library code keeps these warnings.
    set(_test_flags -O1 -Wno-array-bounds -Wno-stringop-overflow -Wno-stringop-overread
                    -Wno-restrict)
    target_compile_options(${target} PRIVATE "$<$<CONFIG:Release>:${_test_flags}>")
  endif()
  if(NOT HAPSIM_PCH)
    return()
  endif()
  set(_headers ${HAPSIM_PCH_HEADERS})
  if(_pch_TEST)
    list(APPEND _headers <gtest/gtest.h>)
  endif()
  # C++ only: some targets also compile C (the drivers' ABI header, Cyclone's generated types).
  # ($<ANGLE-R> writes the header's closing bracket inside the expression.)
  list(TRANSFORM _headers REPLACE "^<(.*)>$" "$<$<COMPILE_LANGUAGE:CXX>:<\\1$<ANGLE-R>>")
  target_precompile_headers(${target} PRIVATE ${_headers})
endfunction()
