# Mixer and blend-layer tests, hand-computed against Cal3D's rules.
target_sources(sinew_animation_tests PRIVATE ${CMAKE_CURRENT_LIST_DIR}/mixer_test.cpp)
