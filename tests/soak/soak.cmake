# The soak test (issue 8, point 3): label "soak", left out of `./sinew test`.
# Included from tests/CMakeLists.txt; CMAKE_CURRENT_LIST_DIR is tests/soak.
