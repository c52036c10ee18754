# The installed package, used the way an engine would (cmake -P, run by the
# ctest "package.consumer"): install Sinew to a fresh prefix, configure and
# build the example host engine against it with find_package(Sinew), build
# the minimal example through pkg-config, then render one frame headless and
# compare it with sinew-editor render of the same frame, and pick the
# character in it with a ray query.
#
# Variables: BUILD_DIR SOURCE_DIR WORK_DIR EDITOR IMAGE_DIFF MODEL CXX
cmake_minimum_required(VERSION 3.25)

include(${CMAKE_CURRENT_LIST_DIR}/package_steps.cmake)

# 1. Install: headers, libsinew, the CMake package and sinew.pc.
set(prefix ${WORK_DIR}/prefix)
install_package(${BUILD_DIR} ${WORK_DIR} ${prefix})

# 2. A separate project finds it.
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/host_engine -B ${WORK_DIR}/host-build -G Ninja
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_CXX_COMPILER=${CXX}
    "-DCMAKE_CXX_FLAGS=-Wall -Wextra -Wpedantic -Werror")
run(${CMAKE_COMMAND} --build ${WORK_DIR}/host-build)

# 3. pkg-config alone is enough too (the source before the libraries:
#    Debian's GCC links with --as-needed). Its Libs carry the rpath, so the
#    program finds libsinew without LD_LIBRARY_PATH (step 8 runs it so).
pkg_config_flags(${prefix} pc_flags)
run(${CXX} ${SOURCE_DIR}/examples/minimal/minimal.cpp ${pc_flags} -o ${WORK_DIR}/minimal)

# 4. One frame: the editor's and the host's, same pack, pose, camera, light
#    (a point light: the host's default is a sphere light).
set(camera 0.0108692,1.37059,3.10876,0.0108692,0.754971,0.0306663,0,1,0,40)
run(${EDITOR} bake ${MODEL} -o ${WORK_DIR}/cesium.pack --threads 2)
run(${EDITOR} render ${WORK_DIR}/cesium.pack --clip "#0" --time 0.7 --camera ${camera} --light 2,4,3
    --size 200x150 --instances 1 --ground off --threads 2 --out ${WORK_DIR}/editor)
run(${WORK_DIR}/host-build/host_engine --headless --pack ${WORK_DIR}/cesium.pack --clip "#0" --time 0.7
    --camera ${camera} --light 2,4,3 --light-radius 0 --size 200x150 --threads 2 --out ${WORK_DIR}/host)
run(${IMAGE_DIFF} ${WORK_DIR}/host/sinew_color.ppm ${WORK_DIR}/editor/color.png
    --max-channel-diff 0 --max-differing-pixels 0)
# The host's own pass shows around the character in its composite.
execute_process(COMMAND ${IMAGE_DIFF} ${WORK_DIR}/host/frame.ppm ${WORK_DIR}/host/sinew_color.ppm
                RESULT_VARIABLE rc OUTPUT_VARIABLE out)
message("${out}")
if(rc EQUAL 0)
  message(FATAL_ERROR "the composite equals Sinew's output: the host's pass is missing")
endif()

# 4b. The host's default light is a sphere light: the characters' shadows
#     fall soft on the host's ground (Sinew's G-buffer mode), with a
#     penumbra around them.
run(${WORK_DIR}/host-build/host_engine --headless --pack ${WORK_DIR}/cesium.pack --clip "#0" --time 0.7
    --size 200x150 --threads 2 --out ${WORK_DIR}/host-soft)
string(REGEX MATCH "ground shadow: ([0-9]+) pixels shadowed, ([0-9]+) of them in penumbra" shadow_line
       "${run_output}")
if(NOT shadow_line OR CMAKE_MATCH_1 EQUAL 0 OR CMAKE_MATCH_2 EQUAL 0)
  message(FATAL_ERROR "no soft shadow of the character on the host's ground: '${shadow_line}'")
endif()

# 5. Through the host's own thread pool: the same image.
run(${WORK_DIR}/host-build/host_engine --headless --pack ${WORK_DIR}/cesium.pack --clip "#0" --time 0.7
    --camera ${camera} --light 2,4,3 --light-radius 0 --size 200x150 --scheduler host --threads 3 --out ${WORK_DIR}/host-pool)
run(${IMAGE_DIFF} ${WORK_DIR}/host-pool/frame.ppm ${WORK_DIR}/host/frame.ppm --max-channel-diff 0)

# 6. Ray queries: the camera frames CesiumMan in the image's centre, so
#    picking pixel 100,75 selects him, and the light's line of sight to him is
#    clear. The highlight goes into frame.ppm only: a query before the pass
#    leaves Sinew's own output identical to the editor's.
run(${WORK_DIR}/host-build/host_engine --headless --pack ${WORK_DIR}/cesium.pack --clip "#0" --time 0.7
    --camera ${camera} --light 2,4,3 --light-radius 0 --size 200x150 --threads 2 --pick 100,75 --out ${WORK_DIR}/host-pick)
expect_output("pick 100,75: selected instance 0,")
expect_output("line of sight from the light: instance 0 visible")
run(${IMAGE_DIFF} ${WORK_DIR}/host-pick/sinew_color.ppm ${WORK_DIR}/editor/color.png
    --max-channel-diff 0 --max-differing-pixels 0)
execute_process(COMMAND ${IMAGE_DIFF} ${WORK_DIR}/host-pick/frame.ppm ${WORK_DIR}/host/frame.ppm
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")
if(NOT rc EQUAL 1)  # 1: the images differ; 2 would be a read error
  message(FATAL_ERROR "the picked character is not highlighted in frame.ppm (sinew-image-diff: ${rc})")
endif()
# A pixel outside the image is bad usage.
execute_process(COMMAND ${WORK_DIR}/host-build/host_engine --headless --pack ${WORK_DIR}/cesium.pack
                        --size 200x150 --pick 200,75 --out ${WORK_DIR}/host-pick-outside
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")
if(NOT rc EQUAL 2)
  message(FATAL_ERROR "--pick 200,75 in a 200x150 image exited with ${rc}, not 2 (bad usage)")
endif()

# 7. The windowed engine frame, where a display can be made (Xvfb).
find_program(xvfb_run xvfb-run)
if(xvfb_run)
  run(${xvfb_run} -a -s "-screen 0 640x480x24" ${WORK_DIR}/host-build/host_engine --pack ${WORK_DIR}/cesium.pack
      --size 320x240 --frames 3 --threads 2)
endif()

# 8. The 30-line example runs as a user would start it: no LD_LIBRARY_PATH,
#    libsinew found through the rpath pkg-config gave it.
run(${CMAKE_COMMAND} -E env --unset=LD_LIBRARY_PATH ${WORK_DIR}/minimal ${WORK_DIR}/cesium.pack
    ${WORK_DIR}/minimal.ppm)
if(NOT EXISTS ${WORK_DIR}/minimal.ppm)
  message(FATAL_ERROR "minimal wrote no ${WORK_DIR}/minimal.ppm")
endif()
message("package.consumer: passed")
