# Cal3D importer tests, including the oracle against the Cal3D library.
# Included from tests/CMakeLists.txt; CMAKE_CURRENT_LIST_DIR is tests/editor.
if(TARGET Cal3D::cal3d)
  sinew_add_test_binary(sinew_cal3d_tests
    SOURCES ${CMAKE_CURRENT_LIST_DIR}/cal3d_import_test.cpp
            ${CMAKE_CURRENT_LIST_DIR}/cal3d_mixer_oracle_test.cpp
            ${CMAKE_CURRENT_LIST_DIR}/cally_limits_test.cpp
            ${CMAKE_CURRENT_LIST_DIR}/cal3d_xml_test.cpp
            ${CMAKE_CURRENT_LIST_DIR}/cal3d_texture_import_test.cpp
    LIBS sinew::editor Cal3D::cal3d)
  # As for the importer (editor/import/cal3d.cmake): libcal3d exports no
  # typeinfo for UBSan's vptr check to reference.
  target_compile_options(sinew_cal3d_tests PRIVATE -fno-sanitize=vptr)
endif()
