// The library's version (include/patchcull/version.h). Outside the layers of src/ (core, import,
// eval): it depends on nothing but the generated header, and any layer may report it.
#include "patchcull/version.h"

namespace patchcull {

Version version() { return {PATCHCULL_VERSION_MAJOR, PATCHCULL_VERSION_MINOR, PATCHCULL_VERSION_PATCH}; }

const char* version_string() { return PATCHCULL_VERSION_STRING; }

}  // namespace patchcull
