# cmake --install: what an engine needs to use patchcull from its own CMake project.
#
#   include/patchcull/*.h                 public headers (+ the generated version.h)
#   include/patchcull/glsl/*.h            GLSL headers an engine's shaders include (with GL)
#   lib/libpatchcull.a, libpatchcull_gl.a (patchcull_gl with GL)
#   lib/cmake/patchcull/                  patchcullConfig.cmake, patchcullConfigVersion.cmake, targets
#   share/patchcull/{models,scenes}/      the shipped models and scenes (patchcull_DATA_DIR)
#   share/doc/patchcull/                  LICENSE, NOTICE
#   bin/patchcull                         the CLI (with GL and PATCHCULL_BUILD_TOOLS)
#
# find_package(patchcull CONFIG) gives patchcull::core (the CPU library: no GL, EGL, GLFW or
# glslang needed to configure or link) and, when the package was built with GL, patchcull::gl.
include(CMakePackageConfigHelpers)
set(PATCHCULL_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/patchcull)

install(TARGETS patchcull EXPORT patchcullCoreTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(EXPORT patchcullCoreTargets NAMESPACE patchcull:: DESTINATION ${PATCHCULL_INSTALL_CMAKEDIR})

# Headers: the GL ones (gl_*.h) only with GL, so a CPU-only install holds no header it cannot link.
if(PATCHCULL_WITH_GL)
  set(patchcull_header_excludes)
else()
  set(patchcull_header_excludes PATTERN "gl_*.h" EXCLUDE)
endif()
install(DIRECTORY include/patchcull DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.h" ${patchcull_header_excludes})
install(FILES ${PROJECT_BINARY_DIR}/include/patchcull/version.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/patchcull)

if(PATCHCULL_WITH_GL)
  install(TARGETS patchcull_gl EXPORT patchcullGLTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(EXPORT patchcullGLTargets NAMESPACE patchcull:: DESTINATION ${PATCHCULL_INSTALL_CMAKEDIR})
  # The GLSL headers of gl_passes.h's shipped_glsl (shared.h: the constants of C++ and GLSL,
  # patchcull_tcs.h: the TCS include) and the bindings of the back-patch and displaced passes
  # (gl_backpatch.h, gl_displaced.h). They include nothing but each other's constants (shared.h
  # first); patchcull::gl puts this folder on the include path, as the build puts shaders/.
  install(FILES shaders/shared.h shaders/patchcull_tcs.h shaders/backpatch_shared.h shaders/displaced_shared.h
    DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/patchcull/glsl)
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
# 0.x: a minor release may change the API, so 0.1 accepts 0.1.z only.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/patchcullConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/patchcullConfig.cmake ${PROJECT_BINARY_DIR}/patchcullConfigVersion.cmake
  cmake/PatchcullImportedDeps.cmake
  DESTINATION ${PATCHCULL_INSTALL_CMAKEDIR})
