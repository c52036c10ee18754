# The Cal3D-style mixer (scheduling) and the blend-layer evaluation job.
target_sources(sinew_animation PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/mixer.cpp
  ${CMAKE_CURRENT_LIST_DIR}/blend.cpp)
