// patchcull/import/image.h: loading displacement maps from PNG files (8- or 16-bit, grey or colour).
#pragma once

#include <cstdint>

#include <cstddef>
#include <string>

#include "patchcull/core/displacement.h"

namespace patchcull {

/// Largest PNG file load_displacement_png reads: 1 GiB (a regular file; devices and FIFOs are
/// refused before any read).
inline constexpr std::uintmax_t kMaxPngFileBytes = std::uintmax_t{1} << 30;

/// Loads path as a height map with D = scale * (h - midlevel), h in [0,1]. Rows are flipped so
/// that row 0 is t = 0 (OBJ texture origin bottom-left, image origin top-left).
/// h is the grey value of a grey image; of a colour image, stb_image's luminance
/// (77 R + 150 G + 29 B) / 256 (alpha is ignored). 16-bit files keep their 16 bits.
/// Only PNG is read. Throws patchcull::Error("path: cannot read image: <reason>"), one short
/// line for every malformed, truncated or non-PNG file; never crashes on one.
DisplacementMap load_displacement_png(const std::string& path, float scale, float midlevel = 0.5f);

/// The same from the size bytes of a PNG file in memory; name is used in error messages (the
/// fuzz target and tests call it without a file).
DisplacementMap decode_displacement_png(const unsigned char* data, std::size_t size, const std::string& name,
                                        float scale, float midlevel = 0.5f);

}  // namespace patchcull
