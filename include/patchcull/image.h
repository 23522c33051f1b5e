// patchcull/image.h: loading displacement maps from PNG files (8- or 16-bit, any channel count;
// the first channel is the height).
#pragma once

#include <string>

#include "patchcull/displacement.h"

namespace patchcull {

/// Loads path as a height map with D = scale * (h - midlevel), h in [0,1]. Rows are flipped so
/// that row 0 is t = 0 (OBJ texture origin bottom-left, image origin top-left).
/// Throws patchcull::Error("path: cannot read image: <reason>").
DisplacementMap load_displacement_png(const std::string& path, float scale, float midlevel = 0.5f);

}  // namespace patchcull
