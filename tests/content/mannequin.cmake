# The procedural mannequin (content/mannequin). Included from
# tests/CMakeLists.txt, so CMAKE_CURRENT_LIST_DIR is tests/content.
if(TARGET sinew::content)
  sinew_add_test_binary(sinew_content_tests
    SOURCES ${CMAKE_CURRENT_LIST_DIR}/mannequin_test.cpp
    LIBS sinew::content)
  # The joint-limit checks need clamp_rotation/is_within, which are linked
  # only once animation/joint_limits.cpp is part of sinew_animation.
  get_target_property(_sinew_animation_sources sinew_animation SOURCES)
  list(FILTER _sinew_animation_sources INCLUDE REGEX "joint_limits\\.cpp$")
  if(_sinew_animation_sources)
    target_compile_definitions(sinew_content_tests PRIVATE SINEW_HAVE_JOINT_LIMITS=1)
  endif()
endif()
