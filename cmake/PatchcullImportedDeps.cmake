# Imports, under PatchcullDeps::, the libraries patchcull links that have no usable CMake package
# on Debian 12. Shared by the build (cmake/Dependencies.cmake) and the installed package
# (patchcullConfig.cmake includes its installed copy), so that a consumer links the same files the
# build did. Both functions define only what is missing (a second find_package is harmless) and
# never fail: they put what they could not find into <missing-var>, and the caller decides.
#
#   patchcull_import_model_deps(<missing-var>) PatchcullDeps::OpenSubdiv (osdCPU), PatchcullDeps::stb
#                                              (the import layer's)
#   patchcull_import_gl_deps(<missing-var>)    PatchcullDeps::epoxy, PatchcullDeps::stb (the gl layer's)
#   patchcull_import_osd_gpu_deps(<missing-var>) PatchcullDeps::OpenSubdivGPU (osdGPU: the gl_osd
#                                              layer's, besides the model and GL dependencies)

# OpenSubdiv 3.5's package config is broken on Debian 12 (its targets file names static
# libraries that are not shipped) and there is no pkg-config file: osdCPU is imported by hand.
# libstb (pkg-config stb) already contains the implementations: never define STB_*_IMPLEMENTATION.
function(patchcull_import_model_deps missing_var)
  set(missing)
  if(NOT TARGET PatchcullDeps::OpenSubdiv)
    find_path(PATCHCULL_OPENSUBDIV_INCLUDE_DIR opensubdiv/version.h)
    find_library(PATCHCULL_OPENSUBDIV_CPU_LIBRARY osdCPU)
    if(PATCHCULL_OPENSUBDIV_INCLUDE_DIR AND PATCHCULL_OPENSUBDIV_CPU_LIBRARY)
      add_library(PatchcullDeps::OpenSubdiv UNKNOWN IMPORTED)
      set_target_properties(PatchcullDeps::OpenSubdiv PROPERTIES
        IMPORTED_LOCATION "${PATCHCULL_OPENSUBDIV_CPU_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${PATCHCULL_OPENSUBDIV_INCLUDE_DIR}")
    else()
      list(APPEND missing "OpenSubdiv (opensubdiv/version.h and libosdCPU: Debian libosd-dev)")
    endif()
  endif()
  _patchcull_import_stb(missing)
  set(${missing_var} "${missing}" PARENT_SCOPE)
endfunction()

# libepoxy loads libEGL / libOpenGL at run time: linking patchcull_gl needs only epoxy itself.
function(patchcull_import_gl_deps missing_var)
  set(missing)
  if(NOT TARGET PatchcullDeps::epoxy)
    _patchcull_pkg_config_target(epoxy PATCHCULL_EPOXY PatchcullDeps::epoxy)
    if(NOT TARGET PatchcullDeps::epoxy)
      list(APPEND missing "libepoxy (pkg-config module epoxy: Debian libepoxy-dev)")
    endif()
  endif()
  _patchcull_import_stb(missing)  # the PNG output of the renderer
  set(${missing_var} "${missing}" PARENT_SCOPE)
endfunction()

# OpenSubdiv's GL patch tables and GLSL patch shader sources (Osd::GLPatchTable,
# Osd::GLSLPatchShaderSource) are in libosdGPU, which Debian's libosd-dev ships beside osdCPU.
function(patchcull_import_osd_gpu_deps missing_var)
  set(missing)
  if(NOT TARGET PatchcullDeps::OpenSubdivGPU)
    find_library(PATCHCULL_OPENSUBDIV_GPU_LIBRARY osdGPU)
    if(PATCHCULL_OPENSUBDIV_GPU_LIBRARY)
      add_library(PatchcullDeps::OpenSubdivGPU UNKNOWN IMPORTED)
      set_target_properties(PatchcullDeps::OpenSubdivGPU PROPERTIES
        IMPORTED_LOCATION "${PATCHCULL_OPENSUBDIV_GPU_LIBRARY}")
    else()
      list(APPEND missing "OpenSubdiv's libosdGPU (Debian libosd-dev)")
    endif()
  endif()
  set(${missing_var} "${missing}" PARENT_SCOPE)
endfunction()

# PatchcullDeps::stb, or its name appended to the list named by list_var.
macro(_patchcull_import_stb list_var)
  if(NOT TARGET PatchcullDeps::stb)
    _patchcull_pkg_config_target(stb PATCHCULL_STB PatchcullDeps::stb)
    if(NOT TARGET PatchcullDeps::stb)
      list(APPEND ${list_var} "stb (pkg-config module stb: Debian libstb-dev)")
    endif()
  endif()
endmacro()

# PatchcullDeps::<name> as an interface target over pkg-config's PkgConfig::<prefix>: a real
# (not ALIAS) imported name, so that the exported link interfaces name it and the installed config
# can define it again.
function(_patchcull_pkg_config_target module prefix target)
  find_package(PkgConfig QUIET)
  if(NOT PKG_CONFIG_FOUND)
    return()
  endif()
  pkg_check_modules(${prefix} QUIET IMPORTED_TARGET ${module})
  if(TARGET PkgConfig::${prefix})
    add_library(${target} INTERFACE IMPORTED)
    set_target_properties(${target} PROPERTIES INTERFACE_LINK_LIBRARIES PkgConfig::${prefix})
  endif()
endfunction()
