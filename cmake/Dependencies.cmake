# Finds the Debian 12 packages listed in scripts/install-deps.sh.
find_package(TBB REQUIRED)
find_package(hwy REQUIRED)
find_package(CLI11 REQUIRED)
find_package(nlohmann_json REQUIRED)
find_package(PkgConfig REQUIRED)

# OpenSubdiv 3.5's package config is broken on Debian 12 (its targets file names static
# libraries that are not shipped) and there is no pkg-config file: import osdCPU by hand.
find_path(OPENSUBDIV_INCLUDE_DIR opensubdiv/version.h REQUIRED)
find_library(OPENSUBDIV_CPU_LIBRARY osdCPU REQUIRED)
add_library(PatchcullDeps::OpenSubdiv UNKNOWN IMPORTED)
set_target_properties(PatchcullDeps::OpenSubdiv PROPERTIES
  IMPORTED_LOCATION "${OPENSUBDIV_CPU_LIBRARY}"
  INTERFACE_INCLUDE_DIRECTORIES "${OPENSUBDIV_INCLUDE_DIR}")

# libstb already contains the implementations: never define STB_*_IMPLEMENTATION.
pkg_check_modules(STB REQUIRED IMPORTED_TARGET stb)
add_library(PatchcullDeps::stb ALIAS PkgConfig::STB)

if(PATCHCULL_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(PATCHCULL_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()

# OpenGL renderer (src/gl): EGL + GL through libepoxy (which loads libEGL/libOpenGL at run time;
# find_package(OpenGL) checks that the GL/EGL development packages are installed), shaders
# validated at build time with glslangValidator.
find_package(OpenGL REQUIRED COMPONENTS OpenGL EGL)
pkg_check_modules(EPOXY REQUIRED IMPORTED_TARGET epoxy)
add_library(PatchcullDeps::epoxy ALIAS PkgConfig::EPOXY)
find_program(GLSLANG_VALIDATOR glslangValidator REQUIRED)
# The window context (GlContext::create_window): GLFW 3 (libglfw3-dev), CMake target `glfw`.
find_package(glfw3 3.3 REQUIRED)
# The viewer's panel (patchcull view): Dear ImGui 1.86 (libimgui-dev), a static library with the
# GLFW and OpenGL 3 backends, found through pkg-config; backends included as <backends/imgui_impl_glfw.h>.
pkg_check_modules(IMGUI REQUIRED IMPORTED_TARGET imgui)
add_library(PatchcullDeps::imgui ALIAS PkgConfig::IMGUI)
