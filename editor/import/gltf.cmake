# glTF 2.0 importer through tinygltf (found in cmake/SinewDependencies.cmake).
target_sources(sinew_editor PRIVATE ${CMAKE_CURRENT_LIST_DIR}/gltf_importer.cpp
                                    ${CMAKE_CURRENT_LIST_DIR}/gltf_container.cpp)
target_link_libraries(sinew_editor PRIVATE TinyGLTF::TinyGLTF)
