# The soak test (docs/ROBUSTNESS.md, "The soak test"): label "soak", left out of `./sinew test`.
# Included from tests/CMakeLists.txt; CMAKE_CURRENT_LIST_DIR is tests/soak.

# One GoogleTest case, registered directly (not with sinew_add_test_binary)
# so it carries its own TIMEOUT. Label "soak" only: `./sinew test` excludes
# it (-LE soak) and the asan/tsan presets take label "unit". Run it with
#   ctest --test-dir build/release -L soak --output-on-failure -V
# SINEW_SOAK_FRAMES (default 20000) and SINEW_SOAK_SEED override the run.
add_executable(sinew_soak_tests ${CMAKE_CURRENT_LIST_DIR}/soak_test.cpp)
target_link_libraries(sinew_soak_tests PRIVATE sinew_demo_lib sinew::content GTest::gtest_main)
add_test(NAME soak.demo_world COMMAND sinew_soak_tests)
# It costs about 11 ms of CPU a frame in Release (220 CPU-seconds for 20,000
# frames: under 2 minutes of wall time on two idle cores), but on a shared
# build machine one run took about 27 minutes; the timeout allows an hour.
# RUN_SERIAL: the RSS figures and the timing are the soak's own.
set_tests_properties(soak.demo_world PROPERTIES LABELS soak TIMEOUT 3600 RUN_SERIAL TRUE)
