# The public API (include/sinew/, libsinew) against the internal renderer,
# and the installed package used by a separate project.
# Included from tests/CMakeLists.txt; CMAKE_CURRENT_LIST_DIR is tests/embed.
sinew_add_test_binary(sinew_api_tests
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/api_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/api_errors_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/api_queries_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/api_animation_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/api_framing_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/api_gbuffer_test.cpp
  LIBS Sinew::raytrace sinew::editor sinew::content)
target_include_directories(sinew_api_tests PRIVATE ${PROJECT_SOURCE_DIR})

# A host animating with the Cal3D library hands Sinew its bone matrices.
if(TARGET Cal3D::cal3d)
  sinew_add_test_binary(sinew_host_bones_tests
    SOURCES ${CMAKE_CURRENT_LIST_DIR}/host_bones_cal3d_test.cpp
    LIBS Sinew::raytrace sinew::editor_cli sinew::editor Cal3D::cal3d)
  target_include_directories(sinew_host_bones_tests PRIVATE ${PROJECT_SOURCE_DIR})
  target_compile_options(sinew_host_bones_tests PRIVATE -fno-sanitize=vptr)  # as for the importer
endif()

# The installed package from a separate project (label "package"). Not in
# sanitizer builds: an instrumented libsinew needs an instrumented host.
add_executable(sinew-image-diff ${CMAKE_CURRENT_LIST_DIR}/image_diff.cpp)
target_link_libraries(sinew-image-diff PRIVATE sinew::runtime sinew::cli)
add_executable(sinew-frame-check ${CMAKE_CURRENT_LIST_DIR}/frame_check.cpp)
target_link_libraries(sinew-frame-check PRIVATE sinew::runtime sinew::cli)
set(consumer_model ${PROJECT_SOURCE_DIR}/../shared/content/gltf/CesiumMan/CesiumMan.glb)
if(NOT CMAKE_CXX_FLAGS MATCHES "-fsanitize" AND EXISTS ${consumer_model})
  add_test(NAME package.consumer
    COMMAND ${CMAKE_COMMAND}
      -DBUILD_DIR=${PROJECT_BINARY_DIR} -DSOURCE_DIR=${PROJECT_SOURCE_DIR}
      -DWORK_DIR=${PROJECT_BINARY_DIR}/package-test -DEDITOR=$<TARGET_FILE:sinew-editor>
      -DIMAGE_DIFF=$<TARGET_FILE:sinew-image-diff> -DMODEL=${consumer_model} -DCXX=${CMAKE_CXX_COMPILER}
      -P ${CMAKE_CURRENT_LIST_DIR}/consumer_test.cmake)
  set_tests_properties(package.consumer PROPERTIES LABELS "package" TIMEOUT 600 RUN_SERIAL TRUE)
  # The README's host example, as printed there.
  add_test(NAME package.readme_example
    COMMAND ${CMAKE_COMMAND}
      -DBUILD_DIR=${PROJECT_BINARY_DIR} -DSOURCE_DIR=${PROJECT_SOURCE_DIR}
      -DWORK_DIR=${PROJECT_BINARY_DIR}/readme-example-test -DEDITOR=$<TARGET_FILE:sinew-editor>
      -DMODEL=${consumer_model} -DCXX=${CMAKE_CXX_COMPILER}
      -P ${CMAKE_CURRENT_LIST_DIR}/readme_example_test.cmake)
  set_tests_properties(package.readme_example PROPERTIES LABELS "package" TIMEOUT 600 RUN_SERIAL TRUE)
endif()

# examples/minimal, built against the installed package, on every model of
# ../shared/content: one test per model, after the one that builds it.
# Cal3D models need the Cal3D importer.
set(content ${PROJECT_SOURCE_DIR}/../shared/content)
file(GLOB minimal_models ${content}/gltf/*/*.glb ${content}/gltf/*/*.gltf)
if(TARGET Cal3D::cal3d)
  file(GLOB cal3d_models ${content}/cal3d/*/*.cfg)
  list(APPEND minimal_models ${cal3d_models})
endif()
if(NOT CMAKE_CXX_FLAGS MATCHES "-fsanitize" AND minimal_models)
  set(minimal_args -DBUILD_DIR=${PROJECT_BINARY_DIR} -DSOURCE_DIR=${PROJECT_SOURCE_DIR}
                   -DWORK_DIR=${PROJECT_BINARY_DIR}/minimal-test -DCXX=${CMAKE_CXX_COMPILER})
  add_test(NAME package.minimal_build
    COMMAND ${CMAKE_COMMAND} -DSTEP=build ${minimal_args} -P ${CMAKE_CURRENT_LIST_DIR}/minimal_models_test.cmake)
  set_tests_properties(package.minimal_build PROPERTIES LABELS "package" TIMEOUT 600 RUN_SERIAL TRUE
                                                        FIXTURES_SETUP minimal_example)
  foreach(model ${minimal_models})
    get_filename_component(name ${model} NAME_WE)
    add_test(NAME package.minimal.${name}
      COMMAND ${CMAKE_COMMAND} -DSTEP=model ${minimal_args} -DEDITOR=$<TARGET_FILE:sinew-editor>
              -DFRAME_CHECK=$<TARGET_FILE:sinew-frame-check> -DMODEL=${model} -DNAME=${name}
              -P ${CMAKE_CURRENT_LIST_DIR}/minimal_models_test.cmake)
    set_tests_properties(package.minimal.${name} PROPERTIES LABELS "package" TIMEOUT 600
                                                            FIXTURES_REQUIRED minimal_example)
  endforeach()
endif()
