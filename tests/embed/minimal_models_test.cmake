# examples/minimal on every model of ../shared/content, used as a reader
# would (cmake -P; ctests "package.minimal_build" and "package.minimal.NAME"):
#
# STEP=build: install Sinew to a fresh prefix, check that docs/EMBEDDING.md
#   quotes examples/minimal/minimal.cpp as it is, and build it through
#   pkg-config.
# STEP=model: bake MODEL quickly (a few samples of its clips: poses between
#   them escape into the fallback and stay exact), run minimal on it with
#   LD_LIBRARY_PATH unset, and check with sinew-frame-check that the image
#   shows the character non-empty, upright and framed; and that the same
#   image turned by 90 and by 180 degrees is refused (the check can fail).
#
# Variables: STEP BUILD_DIR SOURCE_DIR WORK_DIR CXX; for STEP=model also
# EDITOR FRAME_CHECK MODEL NAME.
cmake_minimum_required(VERSION 3.25)

include(${CMAKE_CURRENT_LIST_DIR}/package_steps.cmake)

set(prefix ${WORK_DIR}/prefix)
set(minimal ${WORK_DIR}/minimal)

if(STEP STREQUAL "build")
  install_package(${BUILD_DIR} ${WORK_DIR} ${prefix})
  # The 30-line host docs/EMBEDDING.md prints is the file, as it is.
  file(READ ${SOURCE_DIR}/docs/EMBEDDING.md doc)
  file(READ ${SOURCE_DIR}/examples/minimal/minimal.cpp code)
  string(FIND "${doc}" "```cpp\n${code}```\n" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "docs/EMBEDDING.md does not quote examples/minimal/minimal.cpp as it is: copy the file "
                        "into its code block")
  endif()
  pkg_config_flags(${prefix} pc_flags)
  run(${CXX} -std=c++20 -Wall -Wextra -Werror ${SOURCE_DIR}/examples/minimal/minimal.cpp ${pc_flags} -o ${minimal})
  message("package.minimal_build: passed")
  return()
endif()

if(NOT STEP STREQUAL "model")
  message(FATAL_ERROR "STEP must be build or model, not '${STEP}'")
endif()
if(NOT EXISTS ${minimal})
  message(FATAL_ERROR "${minimal} is missing: package.minimal_build makes it")
endif()
set(dir ${WORK_DIR}/${NAME})
file(REMOVE_RECURSE ${dir})
file(MAKE_DIRECTORY ${dir})
run(${EDITOR} bake ${MODEL} -o ${dir}/${NAME}.pack --samples 6 --threads 2)
run(${CMAKE_COMMAND} -E env --unset=LD_LIBRARY_PATH ${minimal} ${dir}/${NAME}.pack ${dir}/minimal.ppm)
run(${FRAME_CHECK} ${dir}/minimal.ppm)
foreach(turn 90 180)
  execute_process(COMMAND ${FRAME_CHECK} ${dir}/minimal.ppm --turn ${turn}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message("${out}${err}")
  if(NOT rc EQUAL 1)
    message(FATAL_ERROR "the image turned by ${turn} degrees was not refused (sinew-frame-check: ${rc})")
  endif()
endforeach()
message("package.minimal.${NAME}: passed")
