# sinew-editor bake interrupted by SIGINT, for real (label "integration"):
# it must exit 1 saying so, and an existing OUT.pack must keep its bytes.
# The bake (100000 random poses) takes far longer than the 2 s before the
# signal, and is cancelled at its next progress report.
add_test(NAME editor.bake_interrupted
  COMMAND sh -c [=[mkdir -p "$2" && printf previous > "$2/keep.pack" &&
                   "$0" bake "$1" -o "$2/keep.pack" --pose-space arbitrary --samples 100000 --threads 1 2> "$2/err.txt" &
                   pid=$!; sleep 2; kill -INT $pid; wait $pid; rc=$?; cat "$2/err.txt";
                   test $rc -eq 1 && grep -q interrupted "$2/err.txt" && test "$(cat "$2/keep.pack")" = previous]=]
          $<TARGET_FILE:sinew-editor>
          ${PROJECT_SOURCE_DIR}/../shared/content/gltf/CesiumMan/CesiumMan.glb
          ${PROJECT_BINARY_DIR}/editor/cli/interrupt-test)
set_tests_properties(editor.bake_interrupted PROPERTIES LABELS "integration")
