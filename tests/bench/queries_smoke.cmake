# A tiny `sinew-bench queries` run (cmake -P, by tests/bench/CMakeLists.txt):
# it must exit 0, and its --json must show every contender's answers
# checked against brute force with no mismatch. Nothing is timed.
# Variables: BENCH (the program), JSON (where its --json goes), EMBREE (ON
# when the Embree rows must be there), ARGS (the run's options, ;-list).
execute_process(COMMAND ${BENCH} queries ${ARGS} --json ${JSON}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc STREQUAL "0")
  message(FATAL_ERROR "sinew-bench queries: exit code ${rc}, expected 0\n${out}${err}")
endif()
file(READ ${JSON} doc)
string(JSON count LENGTH "${doc}" contenders)
set(expected 1)
if(EMBREE)
  set(expected 3)  # Sinew, Embree refit, Embree rebuild
endif()
if(NOT count EQUAL expected)
  message(FATAL_ERROR "expected ${expected} contenders in ${JSON}, found ${count}\n${out}")
endif()
math(EXPR last "${count} - 1")
foreach(i RANGE ${last})
  string(JSON name GET "${doc}" contenders ${i} name)
  string(JSON passed GET "${doc}" contenders ${i} brute_force passed)
  string(JSON checked GET "${doc}" contenders ${i} brute_force checked)
  if(NOT passed OR checked EQUAL 0)
    message(FATAL_ERROR "${name}: brute force passed=${passed}, checked=${checked}\n${out}")
  endif()
  message(STATUS "${name}: ${checked} rays agree with brute force")
endforeach()
