# The public API (include/sinew/, libsinew) against the internal renderer,
# and the installed package used by a separate project.
# Included from tests/CMakeLists.txt; CMAKE_CURRENT_LIST_DIR is tests/embed.
sinew_add_test_binary(sinew_api_tests
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/api_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/api_errors_test.cpp
  LIBS Sinew::raytrace sinew::editor sinew::content)
target_include_directories(sinew_api_tests PRIVATE ${PROJECT_SOURCE_DIR})
