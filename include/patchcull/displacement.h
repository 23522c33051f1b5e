// patchcull/displacement.h: scalar displacement maps and per-patch displacement bounds.
//
// A displaced surface point is S(u,v) = B(u,v) + D(s,t) * n(u,v), n the unit normal and (s,t) the
// texture coordinate interpolated bilinearly from the patch's corner texcoords (seed 002).
// D(s,t) = scale * (h(s,t) - midlevel), h the bilinearly filtered map value in [0,1], with
// wrap-around addressing (GL_REPEAT) and texel centres at ((i + 0.5)/width, (j + 0.5)/height).
// Row 0 of texels is t = 0 (OBJ's vt origin is bottom-left; image loaders flip rows).
//
// Seed 002's pre-processing step bounds D over every texel a patch can sample: patch_range()
// returns D_min <= 0 <= D_max over all texels touched by bilinear samples inside the texture-space
// bounding box of the patch's corner texcoords. Because D is a convex combination of texel values,
// every displacement the patch can take lies in [D_min, D_max]. Zero is always included, so the
// undisplaced surface is inside every bound built from the range.
#pragma once

#include <cstdint>
#include <vector>

#include "patchcull/math.h"

namespace patchcull {

struct DisplacementRange {
    float d_min = 0;  ///< <= 0
    float d_max = 0;  ///< >= 0
    float max_abs() const { return d_max > -d_min ? d_max : -d_min; }
};

struct DisplacementMap {
    int width = 0;
    int height = 0;
    std::vector<float> texels;  ///< heights in [0,1], texels[y * width + x], row 0 at t = 0
    float scale = 0.0f;         ///< displacement of a height of 1 relative to midlevel, in object units
    float midlevel = 0.5f;      ///< height that means no displacement

    bool empty() const { return width == 0 || height == 0 || scale == 0.0f; }
    /// D(s,t), bilinear with wrap-around.
    float sample(Vec2 st) const;
    /// Conservative [D_min, D_max] of the patch whose corner texcoords are uv[4] (patch.h order).
    DisplacementRange patch_range(const Vec2 uv[4]) const;
};

/// Texture coordinate at (u,v) of a patch with corner texcoords uv[4] (bilinear).
inline Vec2 patch_texcoord(const Vec2 uv[4], float u, float v) {
    const Vec2 bottom = uv[0] * (1 - u) + uv[1] * u;
    const Vec2 top = uv[2] * (1 - u) + uv[3] * u;
    return bottom * (1 - v) + top * v;
}

/// A built-in procedural height map (sum of a few seeded sine ridges and bumps), size x size
/// texels, for the "--displace procedural" option. Values span [0,1].
DisplacementMap make_procedural_displacement(int size, float scale, std::uint32_t seed = 7);

}  // namespace patchcull
