# Joint-limit clamping/JSON tests and pose-space sampler tests.
target_sources(sinew_animation_tests PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/joint_limits_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/pose_space_test.cpp)
