# glTF 2.0 importer through tinygltf (found in cmake/SinewDependencies.cmake).
# gltf_importer.cpp runs the import and calls the parts; gltf_*.h say what each does.
target_sources(sinew_editor PRIVATE ${CMAKE_CURRENT_LIST_DIR}/gltf_importer.cpp
                                    ${CMAKE_CURRENT_LIST_DIR}/gltf_container.cpp
                                    ${CMAKE_CURRENT_LIST_DIR}/gltf_accessors.cpp
                                    ${CMAKE_CURRENT_LIST_DIR}/gltf_transforms.cpp
                                    ${CMAKE_CURRENT_LIST_DIR}/gltf_skeleton.cpp
                                    ${CMAKE_CURRENT_LIST_DIR}/gltf_clips.cpp
                                    ${CMAKE_CURRENT_LIST_DIR}/gltf_mesh.cpp
                                    ${CMAKE_CURRENT_LIST_DIR}/gltf_textures.cpp)
target_link_libraries(sinew_editor PRIVATE TinyGLTF::TinyGLTF)
