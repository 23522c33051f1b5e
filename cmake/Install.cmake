# cmake --install: what an engine needs to use patchcull from its own CMake project.
#
#   include/patchcull/<layer>/*.h         public headers by layer (core, objects, import, eval; gl,
#                                         eval_gl and gl_osd with GL) and the generated include/patchcull/version.h
#   include/patchcull/glsl/*.h            GLSL headers an engine's shaders include (with GL)
#   lib/libpatchcull_<layer>.a            one static library per layer (patchcull_gl, patchcull_eval_gl,
#                                         patchcull_gl_osd with GL; patchcull_vk with Vulkan)
#   lib/cmake/patchcull/                  patchcullConfig.cmake, patchcullConfigVersion.cmake, targets
#   share/patchcull/{models,scenes}/      the shipped models and scenes (patchcull_DATA_DIR)
#   share/doc/patchcull/                  LICENSE, NOTICE
#   bin/patchcull                         the CLI (with GL and PATCHCULL_BUILD_TOOLS)
#
# find_package(patchcull CONFIG COMPONENTS ...) gives one target per layer asked for (and the
# layers it needs): patchcull::core (the kernels: TBB and Highway), patchcull::objects,
# patchcull::import (OpenSubdiv, stb), patchcull::eval and, when the package was built with GL,
# patchcull::gl, patchcull::eval_gl and patchcull::gl_osd (OpenSubdiv's osdGPU), and, when it
# was built with PATCHCULL_WITH_VULKAN, patchcull::vk (patchcullConfig.cmake.in).
include(CMakePackageConfigHelpers)
set(PATCHCULL_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/patchcull)

# One export set per layer, so that the config loads (and finds the dependencies of) only the
# layers a consumer asks for.
foreach(layer core objects import eval)
  string(SUBSTRING ${layer} 0 1 first)
  string(TOUPPER ${first} first)
  string(SUBSTRING ${layer} 1 -1 rest)
  install(TARGETS patchcull_${layer} EXPORT patchcull${first}${rest}Targets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(EXPORT patchcull${first}${rest}Targets NAMESPACE patchcull:: DESTINATION ${PATCHCULL_INSTALL_CMAKEDIR})
endforeach()

# Headers: the GL layers' folders only with GL, so a CPU-only install holds no header it cannot link.
if(PATCHCULL_WITH_GL)
  set(patchcull_header_excludes)
else()
  set(patchcull_header_excludes PATTERN "gl" EXCLUDE PATTERN "eval_gl" EXCLUDE PATTERN "gl_osd" EXCLUDE)
endif()
if(NOT TARGET patchcull_vk)
  list(APPEND patchcull_header_excludes PATTERN "vk" EXCLUDE)
endif()
install(DIRECTORY include/patchcull DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.h" ${patchcull_header_excludes})
install(FILES ${PROJECT_BINARY_DIR}/include/patchcull/version.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/patchcull)

if(PATCHCULL_WITH_GL)
  install(TARGETS patchcull_gl EXPORT patchcullGLTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(EXPORT patchcullGLTargets NAMESPACE patchcull:: DESTINATION ${PATCHCULL_INSTALL_CMAKEDIR})
  install(TARGETS patchcull_eval_gl EXPORT patchcullEvalGLTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(EXPORT patchcullEvalGLTargets NAMESPACE patchcull:: DESTINATION ${PATCHCULL_INSTALL_CMAKEDIR})
  install(TARGETS patchcull_gl_osd EXPORT patchcullGlOsdTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(EXPORT patchcullGlOsdTargets NAMESPACE patchcull:: DESTINATION ${PATCHCULL_INSTALL_CMAKEDIR})
  # The GLSL headers of gl_passes.h's shipped_glsl, as the library embeds them: shared.h (the
  # constants of C++ and GLSL, with core/cull_flags.h's flag word inlined by the shader build, so an
  # engine's shader include system needs no second folder) and patchcull_tcs.h (the TCS include,
  # which uses shared.h's constants) and patchcull_draw_list.h (the vertex side of a compacted
  # draw, gl_compaction.h); patchcull::gl puts this folder on the include path, as the build puts
  # shaders/.
  install(FILES ${PROJECT_BINARY_DIR}/src/gl/shaders/shipped/shared.h shaders/patchcull_tcs.h
    shaders/patchcull_draw_list.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/patchcull/glsl)
endif()
if(TARGET patchcull_vk)
  # The Vulkan passes (PATCHCULL_WITH_VULKAN): their headers and library; the SPIR-V is inside it.
  install(TARGETS patchcull_vk EXPORT patchcullVkTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(EXPORT patchcullVkTargets NAMESPACE patchcull:: DESTINATION ${PATCHCULL_INSTALL_CMAKEDIR})
endif()
if(TARGET patchcull_cli)
  install(TARGETS patchcull_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

# Models keep their own credits (data/models/README.md goes with them).
install(DIRECTORY data/models data/scenes DESTINATION ${CMAKE_INSTALL_DATADIR}/patchcull)
install(FILES LICENSE NOTICE DESTINATION ${CMAKE_INSTALL_DOCDIR})

# The package: config (finds the dependencies, then loads the targets), version file, and the
# dependency importer the build uses too.
configure_package_config_file(cmake/patchcullConfig.cmake.in
  ${PROJECT_BINARY_DIR}/patchcullConfig.cmake
  INSTALL_DESTINATION ${PATCHCULL_INSTALL_CMAKEDIR}
  PATH_VARS CMAKE_INSTALL_DATADIR CMAKE_INSTALL_INCLUDEDIR)
# 0.x: a minor release may change the API, so 0.2 accepts 0.2.z only.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/patchcullConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/patchcullConfig.cmake ${PROJECT_BINARY_DIR}/patchcullConfigVersion.cmake
  cmake/PatchcullImportedDeps.cmake
  DESTINATION ${PATCHCULL_INSTALL_CMAKEDIR})
