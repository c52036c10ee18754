# One program's command-line convention (cmake -P, by tests/cli/cli.cmake):
#   PROGRAM [COMMAND]: `--help` and `-h` print generated help starting with
#   "usage:" and exit 0; an unknown flag exits 2 with one line naming it;
#   FLAG given as `FLAG=BAD` and as `FLAG BAD` is read alike: exit 2 and one
#   line naming the flag and the value (EXPECT), before anything runs.
# Variables: PROGRAM, COMMAND (may be empty), FLAG, BAD, EXPECT (FLAG empty:
# help and the unknown flag only).
separate_arguments(prefix UNIX_COMMAND "${COMMAND}")

function(run_program out_var)
  execute_process(COMMAND ${PROGRAM} ${prefix} ${ARGN}
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  set(${out_var}_rc "${rc}" PARENT_SCOPE)
  set(${out_var}_out "${out}" PARENT_SCOPE)
  set(${out_var}_err "${err}" PARENT_SCOPE)
endfunction()

function(expect_usage_error name expected)
  if(NOT "${${name}_rc}" STREQUAL "2")
    message(FATAL_ERROR "${name}: exit code ${${name}_rc}, expected 2\n${${name}_err}")
  endif()
  string(FIND "${${name}_err}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${name}: expected '${expected}' on stderr, got:\n${${name}_err}")
  endif()
  string(REGEX MATCHALL "\n" lines "${${name}_err}")
  list(LENGTH lines count)
  if(NOT count EQUAL 1)
    message(FATAL_ERROR "${name}: expected one line on stderr, got ${count}:\n${${name}_err}")
  endif()
endfunction()

foreach(help_flag --help -h)
  run_program(help ${help_flag})
  if(NOT help_rc STREQUAL "0" OR NOT help_out MATCHES "^usage: ")
    message(FATAL_ERROR "${help_flag}: exit code ${help_rc}, expected 0 and help on stdout:\n${help_out}${help_err}")
  endif()
endforeach()

run_program(unknown --no-such-flag)
expect_usage_error(unknown "option = --no-such-flag: unknown option")

if(FLAG STREQUAL "")
  message(STATUS "${PROGRAM} ${COMMAND}: help and unknown flag as expected")
  return()
endif()
run_program(joined "${FLAG}=${BAD}")
expect_usage_error(joined "${EXPECT}")
run_program(separate "${FLAG}" "${BAD}")
expect_usage_error(separate "${EXPECT}")
if(NOT joined_err STREQUAL separate_err)
  message(FATAL_ERROR "${FLAG}=${BAD} and ${FLAG} ${BAD} differ:\n${joined_err}${separate_err}")
endif()
message(STATUS "${PROGRAM} ${COMMAND}: help, unknown flag and ${FLAG} forms as expected")
