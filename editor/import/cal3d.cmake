# Cal3D importer: reads Cal3D files through the Cal3D library itself
# (Debian libcal3d12-dev). Without the library the importer is left out and
# so are its tests (tests/editor/cal3d.cmake checks for Cal3D::cal3d).
if(NOT TARGET Cal3D::cal3d)
  find_path(SINEW_CAL3D_INCLUDE_DIR cal3d/cal3d.h)
  find_library(SINEW_CAL3D_LIBRARY cal3d)
  if(SINEW_CAL3D_INCLUDE_DIR AND SINEW_CAL3D_LIBRARY)
    # GLOBAL: the test fragment, in another directory, links it too.
    add_library(Cal3D::cal3d UNKNOWN IMPORTED GLOBAL)
    # SYSTEM (imported include dirs are) keeps Cal3D's own warnings out of -Werror.
    set_target_properties(Cal3D::cal3d PROPERTIES
      IMPORTED_LOCATION "${SINEW_CAL3D_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${SINEW_CAL3D_INCLUDE_DIR}")
  endif()
endif()

if(TARGET Cal3D::cal3d)
  # cal3d_importer.cpp runs the import and calls the parts; cal3d_*.h say what each does.
  target_sources(sinew_editor PRIVATE ${CMAKE_CURRENT_LIST_DIR}/cal3d_importer.cpp
                                      ${CMAKE_CURRENT_LIST_DIR}/cal3d_files.cpp
                                      ${CMAKE_CURRENT_LIST_DIR}/cal3d_validate.cpp
                                      ${CMAKE_CURRENT_LIST_DIR}/cal3d_xml_tree.cpp
                                      ${CMAKE_CURRENT_LIST_DIR}/cal3d_xml_check.cpp
                                      ${CMAKE_CURRENT_LIST_DIR}/cal3d_convert.cpp)
  target_link_libraries(sinew_editor PRIVATE Cal3D::cal3d)
  target_compile_definitions(sinew_editor PRIVATE SINEW_HAVE_CAL3D=1)
  # UBSan's vptr check (asan preset) references the typeinfo of Cal3D's
  # polymorphic classes, which the shared libcal3d does not export: the link
  # fails. The check is off for the two files that touch Cal3D objects
  # (cal3d_files.cpp, cal3d_validate.cpp and the cal3d_xml_* files never include Cal3D).
  set_source_files_properties(${CMAKE_CURRENT_LIST_DIR}/cal3d_importer.cpp
                              ${CMAKE_CURRENT_LIST_DIR}/cal3d_convert.cpp
    PROPERTIES COMPILE_OPTIONS -fno-sanitize=vptr)
else()
  message(WARNING "Cal3D (libcal3d12-dev) not found: the Cal3D importer is not built")
endif()
