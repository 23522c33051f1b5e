// stb_image's implementation, compiled into the fuzz targets only (fuzz/CMakeLists.txt): there it
// is instrumented like the loader around it. Every other build links Debian's libstb instead,
// which already contains it (cmake/Dependencies.cmake).
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
