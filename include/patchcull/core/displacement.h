// patchcull/core/displacement.h: scalar displacement maps and per-patch displacement bounds.
//
// A displaced surface point is S(u,v) = B(u,v) + D(s,t) * n(u,v), n the unit normal and (s,t) the
// texture coordinate interpolated bilinearly from the patch's corner texcoords (Sathe).
// D(s,t) = scale * (h(s,t) - midlevel), h the bilinearly filtered map value in [0,1], with
// wrap-around addressing (GL_REPEAT) and texel centres at ((i + 0.5)/width, (j + 0.5)/height).
// Row 0 of texels is t = 0 (OBJ's vt origin is bottom-left; image loaders flip rows).
//
// Sathe's pre-processing step bounds D over every texel a patch can sample. The texels a patch
// can read form its window: the texel rows and columns touched by bilinear samples inside the
// texture-space bounding box of its corner texcoords, widened by one texel on every side (float
// rounding of the interpolated texcoords, and a GPU's limited sub-texel precision, may move a
// sample's 2x2 texels by one), wrapped around the map, the whole map when wider than it. Because
// a bilinear sample is a convex combination of its 4 texels, every displacement the patch can
// take lies between the window's smallest and largest texel: patch_range_exact() scans them.
// patch_range() returns an interval that contains that one, in constant time, from a min/max
// pyramid of the map (see there). Both include zero, so the undisplaced surface is inside every
// bound built from a range.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "patchcull/core/math.h"

namespace patchcull {

struct DisplacementRange {
    float d_min = 0;  ///< <= 0
    float d_max = 0;  ///< >= 0
    float max_abs() const { return d_max > -d_min ? d_max : -d_min; }
};

namespace detail {
struct RangePyramid;  // src/core/displacement.cpp

/// The lazily built min/max pyramid of one DisplacementMap. A copy (or an assigned or moved-to
/// map) starts without one and builds its own from its own texels on first use.
class RangePyramidCache {
public:
    RangePyramidCache();
    ~RangePyramidCache();
    RangePyramidCache(const RangePyramidCache&);
    RangePyramidCache& operator=(const RangePyramidCache&);
    /// The pyramid of these texels, built on first use and whenever width, height or the texel
    /// buffer (address, size) differ from the last build. Thread-safe; the pointer stays valid
    /// until the next non-const operation on the cache.
    const RangePyramid& get(const float* texels, std::size_t count, int width, int height) const;
    void reset();

private:
    mutable std::mutex mutex_;
    mutable std::unique_ptr<RangePyramid> pyramid_;
};
}  // namespace detail

struct DisplacementMap {
    int width = 0;
    int height = 0;
    std::vector<float> texels;  ///< heights in [0,1], texels[y * width + x], row 0 at t = 0
    float scale = 0.0f;         ///< displacement of a height of 1 relative to midlevel, in object units
    float midlevel = 0.5f;      ///< height that means no displacement

    bool empty() const { return width == 0 || height == 0 || scale == 0.0f; }
    /// D(s,t), bilinear with wrap-around.
    float sample(Vec2 st) const;

    /// Conservative [D_min, D_max] of the patch whose corner texcoords are uv[4] (patch.h order):
    /// it contains patch_range_exact(uv), so every D(s,t) the patch samples.
    /// Cost: constant per call (at most 36 texel or block look-ups), after the first call, which
    /// builds a min/max pyramid of the texels in O(width * height) time (25 ms CPU for 4096^2)
    /// and 8 bytes per 16 texels x 4/3 of memory (levels with 4x4, 8x8, ... texel blocks, up to
    /// 1x1 block; non-power-of-two sizes have clipped last blocks). A query takes the finest level
    /// (the texels themselves first, then the blocks) on which the window touches at most 36
    /// texels or blocks, counted after wrap-around, and returns their min and max: exactly
    /// patch_range_exact() when the window is at most 36 texels (e.g. 6x6: any footprint within
    /// one texel cell gives 4x4 or 5x5), otherwise the range over the blocks the window touches
    /// (for a square window of w texels a side, a square of under 3w; a long thin window is also
    /// widened across to the chosen level's block size).
    /// A non-finite texcoord gives the whole map's range, a huge one (|s * width| > 2^40) the
    /// whole map along its axis.
    /// Contract: after the first call, changing texels' values in place (same buffer, same size,
    /// same width and height) must be followed by texels_changed(), or the next ranges come from
    /// the old values; anything that reallocates texels or changes width or height is detected.
    /// Thread-safe for concurrent calls on one map; never throws except std::bad_alloc (build).
    DisplacementRange patch_range(const Vec2 uv[4]) const;
    /// The reference: the same window scanned texel by texel, O(window texels) (the whole map for
    /// a patch whose texcoords span it). For tests and benchmarks.
    DisplacementRange patch_range_exact(const Vec2 uv[4]) const;
    /// Drops the pyramid (see patch_range's contract); the next patch_range() rebuilds it.
    void texels_changed() { range_pyramid_.reset(); }

private:
    detail::RangePyramidCache range_pyramid_;
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
