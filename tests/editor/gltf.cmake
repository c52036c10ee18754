# glTF importer tests. The test parses files with tinygltf itself for its
# independent spec oracle, so it links TinyGLTF directly too.
find_package(TinyGLTF REQUIRED)
sinew_add_test_binary(sinew_gltf_tests
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/gltf_import_test.cpp
  LIBS sinew::editor TinyGLTF::TinyGLTF)
