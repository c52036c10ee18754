# Every dependency comes from a Debian 12 package (the ./sinew script installs
# them): CMake config packages where Debian ships one, pkg-config otherwise.
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)
find_package(glm CONFIG REQUIRED)
find_package(TBB CONFIG REQUIRED)
# OpenImageIO via pkg-config: Debian 12's CMake config drags in Imath's
# Python targets whose library is not installed (a packaging bug).
pkg_check_modules(OIIO REQUIRED IMPORTED_TARGET OpenImageIO)
pkg_check_modules(XXHASH REQUIRED IMPORTED_TARGET libxxhash)
find_package(nlohmann_json CONFIG REQUIRED)
# Debian's libcli11-dev (header-only): every program's command line.
find_package(CLI11 CONFIG REQUIRED)
# Debian's libtinygltf-dev ships a compiled library, so no
# TINYGLTF_IMPLEMENTATION unit is needed; its headers sit in /usr/include,
# a system directory, so their warnings stay out of -Werror.
find_package(TinyGLTF CONFIG REQUIRED)

if(SINEW_BUILD_DISPLAY)
  find_package(glfw3 CONFIG REQUIRED)
  find_package(OpenGL REQUIRED)
  # Debian's libimgui-dev: a static library with the GLFW and OpenGL 2
  # backends built in; its headers under /usr/include/imgui.
  pkg_check_modules(IMGUI REQUIRED IMPORTED_TARGET imgui)
endif()

if(SINEW_BUILD_TESTS)
  find_package(GTest CONFIG REQUIRED)
endif()
