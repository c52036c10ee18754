# The README's host example, used as a reader would (cmake -P, run by the
# ctest "package.readme_example"): install Sinew to a fresh prefix, take the
# code between the README's example markers, build it through pkg-config
# and run it on a baked pack.
#
# Variables: BUILD_DIR SOURCE_DIR WORK_DIR EDITOR MODEL CXX
cmake_minimum_required(VERSION 3.25)

include(${CMAKE_CURRENT_LIST_DIR}/package_steps.cmake)

set(prefix ${WORK_DIR}/prefix)
install_package(${BUILD_DIR} ${WORK_DIR} ${prefix})

# The code block between the markers, without its fences.
file(READ ${SOURCE_DIR}/README.md readme)
set(begin_marker "<!-- readme example: built and run by the ctest package.readme_example -->")
set(end_marker "<!-- end of readme example -->")
string(FIND "${readme}" "${begin_marker}" begin)
string(FIND "${readme}" "${end_marker}" end)
if(begin EQUAL -1 OR end EQUAL -1 OR end LESS begin)
  message(FATAL_ERROR "README.md lacks the example markers '${begin_marker}' ... '${end_marker}'")
endif()
string(LENGTH "${begin_marker}" marker_length)
math(EXPR begin "${begin} + ${marker_length}")
math(EXPR length "${end} - ${begin}")
string(SUBSTRING "${readme}" ${begin} ${length} block)
string(REGEX REPLACE "```cpp\n" "" block "${block}")
string(REGEX REPLACE "```\n" "" block "${block}")
file(WRITE ${WORK_DIR}/readme_example.cpp "${block}")

pkg_config_flags(${prefix} pc_flags)
run(${CXX} -std=c++20 -Wall -Wextra -Werror ${WORK_DIR}/readme_example.cpp ${pc_flags}
    -o ${WORK_DIR}/readme_example)
run(${EDITOR} bake ${MODEL} -o ${WORK_DIR}/character.pack --threads 2)
run(${WORK_DIR}/readme_example ${WORK_DIR}/character.pack)
