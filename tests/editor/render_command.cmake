# sinew-editor render, in-process: the written files, the depth and triangle
# AOVs against brute force, multi-frame stats, instances and error handling.
sinew_add_test_binary(sinew_render_command_tests
  SOURCES editor/render_command_test.cpp
  LIBS sinew::editor_cli sinew::editor sinew::raytrace nlohmann_json::nlohmann_json)
if(TARGET Cal3D::cal3d)
  target_compile_definitions(sinew_render_command_tests PRIVATE SINEW_HAVE_CAL3D=1)
endif()

# The real executable on a real model (label "integration", not part of the
# asan "unit" run): it must exit 0 and write its four files; a usage error
# must exit with code 2 and name the flag and the value.
add_test(NAME editor.render_cesiumman
  COMMAND sh -c [=[rm -rf "$2" && "$0" render "$1" --time 0.5 --size 128x128 --frames 2 --threads 2 --out "$2" &&
                   for f in color.png depth.exr triangle_id.exr stats.json; do
                     test -s "$2/$f" || { echo "missing $2/$f"; exit 1; }; done]=]
          $<TARGET_FILE:sinew-editor>
          ${PROJECT_SOURCE_DIR}/../shared/content/gltf/CesiumMan/CesiumMan.glb
          ${PROJECT_BINARY_DIR}/editor/cli/test-out)
set_tests_properties(editor.render_cesiumman PROPERTIES LABELS "integration")
add_test(NAME editor.render_usage
  COMMAND sh -c [=[out=$("$0" render model.glb --out x --size 0x5 2>&1); rc=$?; echo "$out";
                   test "$rc" -eq 2 && echo "$out" | grep -q -e '--size = 0x5: expected WxH']=]
          $<TARGET_FILE:sinew-editor>)
set_tests_properties(editor.render_usage PROPERTIES LABELS "integration")
