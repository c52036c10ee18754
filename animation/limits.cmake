# Joint limits (Euler and swing-twist, JSON files) and the pose-space
# samplers the bake uses (paper section 3.3, Table 1).
find_package(nlohmann_json CONFIG REQUIRED)
target_sources(sinew_animation PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/joint_limits.cpp
  ${CMAKE_CURRENT_LIST_DIR}/joint_limits_json.cpp
  ${CMAKE_CURRENT_LIST_DIR}/pose_space.cpp)
target_link_libraries(sinew_animation PRIVATE nlohmann_json::nlohmann_json)
