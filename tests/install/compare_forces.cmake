# The example programs' "tool NAME: peak P N, mean M N, S steps in contact" lines against the
# "tools" of `hapsim run --json`: the same tools, the same forces within TOLERANCE (relative; 0:
# the same to 1e-12) and, when TOLERANCE is 0, the same number of steps in contact.
file(READ "${JSON}" json)
file(STRINGS "${OUTPUT}" lines REGEX "^tool [^ ]+: peak ")
string(JSON count LENGTH "${json}" tools)
list(LENGTH lines printed)
if(NOT printed EQUAL count)
  message(FATAL_ERROR "${OUTPUT}: ${printed} tools printed, hapsim run has ${count}")
endif()
if(TOLERANCE EQUAL 0)
  set(TOLERANCE 1e-12)
endif()
math(EXPR last "${count} - 1")
foreach(i RANGE ${last})
  list(GET lines ${i} line)
  if(NOT line MATCHES "^tool (.*): peak ([^ ]+) N, mean ([^ ]+) N, ([0-9]+) steps in contact")
    message(FATAL_ERROR "${OUTPUT}: cannot read '${line}'")
  endif()
  set(name "${CMAKE_MATCH_1}")
  set(peak "${CMAKE_MATCH_2}")
  set(mean "${CMAKE_MATCH_3}")
  set(steps "${CMAKE_MATCH_4}")
  string(JSON run_name GET "${json}" tools ${i} name)
  string(JSON run_peak GET "${json}" tools ${i} peak_force_n)
  string(JSON run_mean GET "${json}" tools ${i} mean_force_n)
  string(JSON run_steps GET "${json}" tools ${i} contact_steps)
  if(NOT name STREQUAL run_name)
    message(FATAL_ERROR "tool ${i}: '${name}', hapsim run has '${run_name}'")
  endif()
  # CMake has no floating point: compare in the shell's awk.
  execute_process(
    COMMAND awk -v a=${peak} -v b=${run_peak} -v c=${mean} -v d=${run_mean} -v tol=${TOLERANCE}
            "BEGIN { e = (a > b ? a - b : b - a) / (b > 1e-9 ? b : 1); f = (c > d ? c - d : d - c) / (d > 1e-9 ? d : 1); exit (e <= tol && f <= tol) ? 0 : 1 }"
    RESULT_VARIABLE differs)
  if(differs)
    message(FATAL_ERROR "tool ${name}: peak ${peak} N, mean ${mean} N; hapsim run: "
                        "peak ${run_peak} N, mean ${run_mean} N (tolerance ${TOLERANCE})")
  endif()
  if(TOLERANCE LESS_EQUAL 1e-12 AND NOT steps EQUAL run_steps)
    message(FATAL_ERROR "tool ${name}: ${steps} steps in contact; hapsim run: ${run_steps}")
  endif()
  message(STATUS "tool ${name}: peak ${peak} N, mean ${mean} N = hapsim run's ${run_peak} N, ${run_mean} N")
endforeach()
