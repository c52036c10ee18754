# Every program's command line follows one convention (runtime/cli/, CLI11):
# generated --help with exit 0, exit 2 and one line on usage errors, and
# `--flag=value` read as `--flag value`. One test per program or command.
# FLAG, BAD, EXPECT: a value-taking flag, a bad value and the message it
# gives; empty for a program or command without one.
function(sinew_cli_convention_test name program command flag bad expect)
  add_test(NAME cli.${name}
    COMMAND ${CMAKE_COMMAND} -DPROGRAM=${program} "-DCOMMAND=${command}" -DFLAG=${flag} -DBAD=${bad}
            "-DEXPECT=${expect}" -P ${CMAKE_CURRENT_LIST_DIR}/convention_check.cmake)
  set_tests_properties(cli.${name} PROPERTIES LABELS "integration")
endfunction()

set(editor $<TARGET_FILE:sinew-editor>)
sinew_cli_convention_test(editor "${editor}" "" "" "" "")
sinew_cli_convention_test(editor_render "${editor}" "render m.glb --out x" --size 0x5 "--size = 0x5: expected WxH")
sinew_cli_convention_test(editor_bake "${editor}" "bake m.glb -o x.pack" --threads two "--threads = two: expected an integer from 0")
sinew_cli_convention_test(editor_subdivide "${editor}" "subdivide m.glb -o x.pack" --levels 99 "--levels = 99: expected an integer")
sinew_cli_convention_test(editor_inspect "${editor}" inspect "" "" "")
sinew_cli_convention_test(editor_validate "${editor}" validate "" "" "")
if(TARGET sinew_editor_gui)
  sinew_cli_convention_test(editor_gui "${editor}" gui --frames -1 "--frames = -1: expected an integer")
endif()
sinew_cli_convention_test(demo $<TARGET_FILE:sinew-demo> "" --frames nope "--frames = nope: expected an integer")
sinew_cli_convention_test(image_diff $<TARGET_FILE:sinew-image-diff> "a.png b.png" --max-channel-diff 300
  "--max-channel-diff = 300: expected an integer from 0 to 255")
sinew_cli_convention_test(frame_check $<TARGET_FILE:sinew-frame-check> "a.png" --turn 45 "--turn = 45")
set(bench $<TARGET_FILE:sinew-bench>)
foreach(benchmark animation bake demo embree memory paper queries raytrace report structures tradeoff)
  if(benchmark STREQUAL "report")
    sinew_cli_convention_test(bench_${benchmark} "${bench}" ${benchmark} --sections nope "--sections = nope")
  elseif(benchmark STREQUAL "animation")
    sinew_cli_convention_test(bench_${benchmark} "${bench}" ${benchmark} --frames 0 "--frames = 0: expected an integer")
  elseif(benchmark MATCHES "^(bake|demo|memory|queries|structures|tradeoff)$")
    sinew_cli_convention_test(bench_${benchmark} "${bench}" ${benchmark} --threads -1
      "--threads = -1: expected an integer from 0 to 1024")
  else()
    sinew_cli_convention_test(bench_${benchmark} "${bench}" ${benchmark} --threads 1,x
      "--threads = x: expected an integer from 0 to 1024")
  endif()
endforeach()
sinew_cli_convention_test(bench "${bench}" "" "" "" "")
