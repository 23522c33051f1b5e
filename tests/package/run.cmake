# Packaging checks (tests/package/CMakeLists.txt runs them under ctest, label package):
#
#   cmake -DMODE=install -DBUILD_DIR=... -DWORK=... -DSOURCE_DIR=... -DCXX=... -DNEXT_MINOR=... -P run.cmake
#     installs the build BUILD_DIR into WORK/prefix (cmake --install), checks the layout, that no
#     PATCHCULL_* definition of the build reaches a consumer, moves the prefix to WORK/moved/prefix
#     (the installed CLI resolves `cull bigguy` there), then configures, builds and runs
#     tests/package/consumer with find_package(patchcull 0.2 CONFIG): with patchcull::import,
#     patchcull::gl and patchcull::gl_osd (core_consumer, import_consumer, gl_consumer,
#     gl_osd_consumer), and with COMPONENTS core alone
#     (the kernels), which must search for no GL, OpenSubdiv or stb package;
#     find_package(patchcull NEXT_MINOR) must refuse the package (version file).
#   cmake -DMODE=cpu -DCPU_BUILD_DIR=... -DWORK=... -DSOURCE_DIR=... -DCXX=... -P run.cmake
#     configures SOURCE_DIR in CPU_BUILD_DIR (a new tree, or one configured before: its build type
#     and sanitizers kept) with PATCHCULL_WITH_GL=OFF, PATCHCULL_WITH_VULKAN=OFF and
#     find_package(OpenGL/glfw3) disabled
#     (a REQUIRED search for them is then an error), checks that nothing of GL was searched for
#     and no GL target exists while the core tests do, builds and installs the CPU layers alone
#     (CPU_BUILD_DIR is kept between runs: incremental), runs core_consumer and import_consumer
#     against that install,
#     and checks that asking the CPU-only package for COMPONENTS gl fails.
#   cmake -DMODE=version -DCLI=... -DVERSION=... -P run.cmake
#     `patchcull --version` prints exactly "patchcull VERSION" and exits 0.
# Any failure: FATAL_ERROR naming the step (the test fails).
cmake_minimum_required(VERSION 3.25)

function(run step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message(STATUS "[${step}] ${out}${err}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${step} failed (exit status ${rc}): ${ARGN}")
  endif()
endfunction()

function(expect_files step)
  foreach(file IN LISTS ARGN)
    if(NOT EXISTS "${file}")
      message(FATAL_ERROR "${step}: ${file} is missing")
    endif()
  endforeach()
endfunction()

function(expect_no_files step)
  foreach(file IN LISTS ARGN)
    if(EXISTS "${file}")
      message(FATAL_ERROR "${step}: ${file} should not be there")
    endif()
  endforeach()
endfunction()

# Cache entries that betray a search for a GL package (or its pkg-config modules, or glslang).
function(expect_no_gl_search step cache)
  file(STRINGS "${cache}" hits REGEX "^(OpenGL_|OPENGL_|glfw3_DIR|PATCHCULL_EPOXY|IMGUI_|GLSLANG_VALIDATOR|EGL_)")
  if(hits)
    message(FATAL_ERROR "${step}: GL packages were searched for (${cache}): ${hits}")
  endif()
endfunction()

# Cache entries that betray a search for the import layer's packages (OpenSubdiv, stb).
function(expect_no_model_search step cache)
  file(STRINGS "${cache}" hits REGEX "^(PATCHCULL_OPENSUBDIV|PATCHCULL_STB)")
  if(hits)
    message(FATAL_ERROR "${step}: the import layer's packages were searched for (${cache}): ${hits}")
  endif()
endfunction()

# Configures, builds and runs the consumer (EXTRA: more -D options) in WORK/<name>: with
# patchcull::gl when consumer_gl, with patchcull::import when consumer_import.
function(build_consumer name prefix consumer_gl consumer_import)
  set(dir "${WORK}/${name}")
  file(REMOVE_RECURSE "${dir}")
  run("${name}: configure" ${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/package/consumer" -B "${dir}"
      -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX} "-DCMAKE_PREFIX_PATH=${prefix}"
      -DCONSUMER_GL=${consumer_gl} -DCONSUMER_IMPORT=${consumer_import} ${ARGN})
  run("${name}: build" ${CMAKE_COMMAND} --build "${dir}" -j2)
  run("${name}: core_consumer" "${dir}/core_consumer")
  if(consumer_import)
    # A shipped model by name: from the package the consumer was built against (wherever its
    # prefix is; not from the source tree, which still exists), then from the folder the
    # environment names instead.
    run("${name}: import_consumer (package data)" ${CMAKE_COMMAND} -E env --unset=PATCHCULL_DATA_DIR
        "${dir}/import_consumer")
    file(COPY "${prefix}/share/patchcull/models/bigguy.obj" DESTINATION "${dir}/env_data/models")
    run("${name}: import_consumer (PATCHCULL_DATA_DIR)" ${CMAKE_COMMAND} -E env "PATCHCULL_DATA_DIR=${dir}/env_data"
        "${dir}/import_consumer")
  elseif(NOT consumer_gl)
    expect_no_model_search("${name}" "${dir}/CMakeCache.txt")
  endif()
  if(EXISTS "${dir}/vk_consumer")
    run("${name}: vk_consumer" "${dir}/vk_consumer")
  endif()
  if(EXISTS "${dir}/gl_osd_consumer")
    run("${name}: gl_osd_consumer" "${dir}/gl_osd_consumer")
  endif()
  if(consumer_gl)
    run("${name}: gl_consumer" "${dir}/gl_consumer")
  else()
    expect_no_gl_search("${name}" "${dir}/CMakeCache.txt")
  endif()
endfunction()

if(MODE STREQUAL "install")
  file(REMOVE_RECURSE "${WORK}")
  set(prefix "${WORK}/prefix")
  run("install" ${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${prefix}")
  set(cmakedir "${prefix}/lib/cmake/patchcull")
  expect_files("install" "${cmakedir}/patchcullConfig.cmake" "${cmakedir}/patchcullConfigVersion.cmake"
    "${cmakedir}/patchcullCoreTargets.cmake" "${cmakedir}/patchcullObjectsTargets.cmake"
    "${cmakedir}/patchcullImportTargets.cmake" "${cmakedir}/patchcullEvalTargets.cmake"
    "${cmakedir}/patchcullGLTargets.cmake" "${cmakedir}/patchcullGlOsdTargets.cmake"
    "${cmakedir}/PatchcullImportedDeps.cmake" "${prefix}/lib/libpatchcull_gl_osd.a"
    "${prefix}/include/patchcull/gl_osd/osd_gl_draw.h"
    "${prefix}/lib/libpatchcull_core.a" "${prefix}/lib/libpatchcull_objects.a" "${prefix}/lib/libpatchcull_import.a"
    "${prefix}/lib/libpatchcull_eval.a" "${prefix}/lib/libpatchcull_gl.a"
    "${prefix}/include/patchcull/core/frustum.h" "${prefix}/include/patchcull/gl/gl_passes.h"
    "${prefix}/include/patchcull/version.h" "${prefix}/include/patchcull/glsl/shared.h"
    "${prefix}/include/patchcull/glsl/patchcull_tcs.h" "${prefix}/share/patchcull/models/bigguy.obj"
    "${prefix}/share/patchcull/models/README.md" "${prefix}/share/doc/patchcull/LICENSE"
    "${prefix}/share/doc/patchcull/NOTICE" "${prefix}/bin/patchcull")
  # Nothing of the build's own configuration in a consumer's flags.
  file(GLOB targets_files "${cmakedir}/patchcull*Targets*.cmake")
  foreach(file IN LISTS targets_files)
    file(STRINGS "${file}" leaks REGEX "PATCHCULL_|${SOURCE_DIR}|${BUILD_DIR}")
    if(leaks)
      message(FATAL_ERROR "install: ${file} passes the build's settings to consumers: ${leaks}")
    endif()
  endforeach()
  # A relocatable package: moved after installing, it still serves its consumers (and its CLI)
  # the data beside it.
  set(moved "${WORK}/moved/prefix")
  file(MAKE_DIRECTORY "${WORK}/moved")
  file(RENAME "${prefix}" "${moved}")
  set(prefix "${moved}")
  run("moved CLI: cull bigguy" ${CMAKE_COMMAND} -E env --unset=PATCHCULL_DATA_DIR "${prefix}/bin/patchcull" cull bigguy
      --views 2)
  # The Vulkan passes when the build has them (PATCHCULL_WITH_VULKAN, on where Vulkan is found).
  set(consumer_vk OFF)
  if(EXISTS "${prefix}/lib/cmake/patchcull/patchcullVkTargets.cmake")
    set(consumer_vk ON)
  endif()
  build_consumer(consumer "${prefix}" ON ON -DCONSUMER_GL_OSD=ON -DCONSUMER_VK=${consumer_vk})
  expect_files("consumer" "${WORK}/consumer/gl_osd_consumer")
  # The kernels alone: no GL, OpenSubdiv or stb package searched for.
  build_consumer(consumer_kernels_only "${prefix}" OFF OFF)
  # The version file: 0.x releases are compatible within a minor version only.
  execute_process(COMMAND ${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/package/consumer" -B "${WORK}/consumer_next_minor"
                  -DCMAKE_CXX_COMPILER=${CXX} "-DCMAKE_PREFIX_PATH=${prefix}" -DCONSUMER_GL=OFF
                  -DCONSUMER_IMPORT=OFF -DCONSUMER_VERSION=${NEXT_MINOR}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(rc EQUAL 0 OR NOT err MATCHES "considered but not accepted")
    message(FATAL_ERROR "install: find_package(patchcull ${NEXT_MINOR}) accepted the package: exit ${rc}: ${err}")
  endif()
  message(STATUS "[find_package(patchcull ${NEXT_MINOR}) refused] ${err}")
elseif(MODE STREQUAL "cpu")
  file(REMOVE_RECURSE "${WORK}")
  # A tree configured before (scripts/test.sh's sanitizer tree) keeps its build type and flags;
  # a new one is of build type None (no -O, no -g): the check is about packaging, and unoptimised
  # the core library compiles in about half the time (its first run compiles it all; later ones
  # only what changed).
  set(cpu_build_type -DCMAKE_BUILD_TYPE=None)
  set(consumer_link_flags)
  if(EXISTS "${CPU_BUILD_DIR}/CMakeCache.txt")
    set(cpu_build_type)
    # Libraries built with the sanitizers need them on the consumers' link line too.
    file(STRINGS "${CPU_BUILD_DIR}/CMakeCache.txt" sanitized REGEX "^PATCHCULL_SANITIZE:BOOL=ON$")
    if(sanitized)
      set(consumer_link_flags "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined")
    endif()
  endif()
  run("cpu-only: configure" ${CMAKE_COMMAND} -S "${SOURCE_DIR}" -B "${CPU_BUILD_DIR}"
      ${cpu_build_type} -DCMAKE_CXX_COMPILER=${CXX} -DPATCHCULL_WITH_GL=OFF -DPATCHCULL_WITH_VULKAN=OFF
      -DPATCHCULL_BUILD_TESTS=ON -DPATCHCULL_BUILD_BENCHMARKS=ON -DPATCHCULL_BUILD_TOOLS=ON
      -DPATCHCULL_BUILD_EXAMPLES=ON -DPATCHCULL_BUILD_FUZZERS=OFF
      -DCMAKE_DISABLE_FIND_PACKAGE_OpenGL=ON -DCMAKE_DISABLE_FIND_PACKAGE_glfw3=ON)
  expect_no_gl_search("cpu-only" "${CPU_BUILD_DIR}/CMakeCache.txt")
  # The help target lists one target a line: "... NAME" (Makefiles) or "NAME: phony" (Ninja).
  execute_process(COMMAND ${CMAKE_COMMAND} --build "${CPU_BUILD_DIR}" --target help OUTPUT_VARIABLE targets)
  foreach(target patchcull_core patchcull_objects patchcull_import patchcull_eval patchcull_core_tests
                 patchcull_import_tests)
    if(NOT targets MATCHES "(\\.\\.\\. |\n)${target}(: phony)?\n")
      message(FATAL_ERROR "cpu-only: no target ${target}")
    endif()
  endforeach()
  foreach(target patchcull_gl patchcull_cli patchcull_shaders patchcull_gl_tests patchcull_bench patchcull_vk)
    if(targets MATCHES "(\\.\\.\\. |\n)${target}(: phony)?\n")
      message(FATAL_ERROR "cpu-only: target ${target} exists without GL")
    endif()
  endforeach()
  run("cpu-only: build" ${CMAKE_COMMAND} --build "${CPU_BUILD_DIR}" -j2 --target patchcull_eval)
  set(prefix "${WORK}/prefix")
  run("cpu-only: install" ${CMAKE_COMMAND} --install "${CPU_BUILD_DIR}" --prefix "${prefix}")
  expect_files("cpu-only: install" "${prefix}/lib/libpatchcull_core.a" "${prefix}/lib/libpatchcull_import.a"
    "${prefix}/include/patchcull/core/frustum.h"
    "${prefix}/lib/cmake/patchcull/patchcullConfig.cmake")
  expect_no_files("cpu-only: install" "${prefix}/lib/libpatchcull_gl.a" "${prefix}/include/patchcull/gl"
    "${prefix}/lib/libpatchcull_gl_osd.a" "${prefix}/include/patchcull/gl_osd" "${prefix}/lib/libpatchcull_vk.a"
    "${prefix}/include/patchcull/vk"
    "${prefix}/include/patchcull/glsl" "${prefix}/lib/cmake/patchcull/patchcullGLTargets.cmake")
  build_consumer(consumer_cpu "${prefix}" OFF ON
    -DCMAKE_DISABLE_FIND_PACKAGE_OpenGL=ON -DCMAKE_DISABLE_FIND_PACKAGE_glfw3=ON ${consumer_link_flags})
  # A package without GL refuses COMPONENTS gl, and says why.
  execute_process(COMMAND ${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/package/consumer" -B "${WORK}/consumer_cpu_gl"
                  -DCMAKE_CXX_COMPILER=${CXX} "-DCMAKE_PREFIX_PATH=${prefix}" -DCONSUMER_GL=ON
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(rc EQUAL 0 OR NOT err MATCHES "PATCHCULL_WITH_GL=OFF")
    message(FATAL_ERROR "cpu-only: find_package(patchcull COMPONENTS gl) on a CPU-only install: exit ${rc}: ${err}")
  endif()
  message(STATUS "[cpu-only: COMPONENTS gl refused] ${err}")
elseif(MODE STREQUAL "version")
  execute_process(COMMAND "${CLI}" --version RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT out STREQUAL "patchcull ${VERSION}\n" OR NOT err STREQUAL "")
    message(FATAL_ERROR "patchcull --version: exit ${rc}, stdout '${out}', stderr '${err}' (expected 'patchcull ${VERSION}')")
  endif()
else()
  message(FATAL_ERROR "run.cmake: MODE must be install, cpu or version")
endif()
