# Finds the Debian 12 packages listed in scripts/install-deps.sh. With PATCHCULL_WITH_GL=OFF
# nothing of OpenGL, EGL, libepoxy, glslang, GLFW or Dear ImGui is searched for.
find_package(TBB REQUIRED)
find_package(hwy REQUIRED)
find_package(nlohmann_json REQUIRED)

# OpenSubdiv (osdCPU) and stb: imported by hand, by the same file the installed package uses.
include(${CMAKE_CURRENT_LIST_DIR}/PatchcullImportedDeps.cmake)
patchcull_import_model_deps(patchcull_missing)
if(patchcull_missing)
  list(JOIN patchcull_missing ", " patchcull_missing)
  message(FATAL_ERROR "patchcull: not found: ${patchcull_missing} (scripts/install-deps.sh installs them)")
endif()

if(PATCHCULL_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(PATCHCULL_BUILD_BENCHMARKS AND PATCHCULL_WITH_GL)
  find_package(benchmark REQUIRED)
endif()

if(PATCHCULL_WITH_GL)
  # The CLI (it needs the GL renderer): CLI11.
  if(PATCHCULL_BUILD_TOOLS)
    find_package(CLI11 REQUIRED)
  endif()
  # OpenGL renderer (src/gl): EGL + GL through libepoxy (which loads libEGL/libOpenGL at run time;
  # find_package(OpenGL) checks that the GL/EGL development packages are installed), shaders
  # validated at build time with glslangValidator.
  find_package(OpenGL REQUIRED COMPONENTS OpenGL EGL)
  patchcull_import_gl_deps(patchcull_missing)
  if(patchcull_missing)
    message(FATAL_ERROR "patchcull: not found: ${patchcull_missing} (or configure with -DPATCHCULL_WITH_GL=OFF)")
  endif()
  find_program(GLSLANG_VALIDATOR glslangValidator REQUIRED)
  # The window context (GlContext::create_window): GLFW 3 (libglfw3-dev), CMake target `glfw`.
  find_package(glfw3 3.3 REQUIRED)
  # The viewer's panel (patchcull view): Dear ImGui 1.86 (libimgui-dev), a static library with the
  # GLFW and OpenGL 3 backends, found through pkg-config; backends included as <backends/imgui_impl_glfw.h>.
  find_package(PkgConfig REQUIRED)
  pkg_check_modules(IMGUI REQUIRED IMPORTED_TARGET imgui)
  add_library(PatchcullDeps::imgui ALIAS PkgConfig::IMGUI)
endif()
