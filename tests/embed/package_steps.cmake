# Steps the package tests share (consumer_test.cmake, readme_example_test.cmake):
# running a command, checking its output, installing Sinew to a fresh prefix
# and reading sinew.pc's flags.

# Runs the command and fails the test on a non-zero exit; leaves its
# standard output in run_output, for expect_output.
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message("$ ${ARGN}\n${out}${err}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}")
  endif()
  set(run_output "${out}" PARENT_SCOPE)
endfunction()

function(expect_output text)
  string(FIND "${run_output}" "${text}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "the output lacks '${text}'")
  endif()
endfunction()

# Empties WORK_DIR and installs the package (headers, libsinew, the CMake
# package and sinew.pc) to `prefix` under it.
function(install_package build_dir work_dir prefix)
  file(REMOVE_RECURSE ${work_dir})
  file(MAKE_DIRECTORY ${work_dir})
  run(${CMAKE_COMMAND} --install ${build_dir} --prefix ${prefix} --component sinew)
endfunction()

# The compile and link flags `pkg-config --cflags --libs sinew` gives for the
# package at `prefix`, as a list, into `out_var`.
function(pkg_config_flags prefix out_var)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env PKG_CONFIG_PATH=${prefix}/lib/pkgconfig
                          pkg-config --cflags --libs sinew
                  OUTPUT_VARIABLE flags RESULT_VARIABLE rc OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "pkg-config does not find sinew.pc under ${prefix}")
  endif()
  separate_arguments(flags UNIX_COMMAND "${flags}")
  set(${out_var} ${flags} PARENT_SCOPE)
endfunction()
