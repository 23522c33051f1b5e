// Internal (src/import only): how the scene file reader and the scene motion checks write a
// number in their one-line messages.
#pragma once

#include <cstdio>
#include <string>

namespace patchcull::detail {

/// v with 6 significant digits ("%.6g": 0.5, 1e+06, 5.36871e+08).
inline std::string number_text(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.6g", v);
    return text;
}

}  // namespace patchcull::detail
