# The numerical-extremes suite (docs/ROBUSTNESS.md) and resource limits.
# Included from tests/CMakeLists.txt; CMAKE_CURRENT_LIST_DIR is tests/extremes.
sinew_add_test_binary(sinew_extremes_tests
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/extremes_scene_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/extremes_input_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/resource_limits_test.cpp
  LIBS sinew::editor sinew::editor_cli sinew::content sinew::raytrace)
