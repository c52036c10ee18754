# glTF 2.0 importer (tinygltf). Debian's libtinygltf-dev ships a compiled
# library (TinyGLTF::TinyGLTF), so no TINYGLTF_IMPLEMENTATION unit is needed;
# its include directory is /usr/include, which compilers treat as a system
# directory, so the header's warnings do not reach our -Werror build.
find_package(TinyGLTF REQUIRED)
target_sources(sinew_editor PRIVATE ${CMAKE_CURRENT_LIST_DIR}/gltf_importer.cpp)
target_link_libraries(sinew_editor PRIVATE TinyGLTF::TinyGLTF)
