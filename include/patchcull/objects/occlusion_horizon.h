// patchcull/objects/occlusion_horizon.h: object-level occlusion culling with an occlusion horizon (G.
// Zachmann, lecture "Advanced Visibility Computations"; Downs, Möller & Séquin, "Occlusion Horizons
// for Driving through Urban Scenery", I3D 2001), made conservative for any camera (pitched and
// rolled too) and any boxes.
//
// The paper renders a 2.5D city front to back and keeps, per image column, the highest projected
// building top so far (the "horizon"); an object whose screen box lies below the horizon in every
// column it spans is hidden. Here each column keeps ONE covered interval [lo, hi] of window y
// instead of a height, which is the paper's horizon for an upright camera over a city (every
// building's interval reaches down to the street or below the image) and stays right when the
// camera pitches or rolls, or an occluder floats.
//
// Window coordinates: x_w = (x/w + 1) W/2, y_w = (y/w + 1) H/2; y grows upward, row 0 at the
// bottom (GL, as hiz.h). Column c is the pixel strip [c, c+1) x [0, H).
//
// ---- Why it is conservative ------------------------------------------------------------------
// Occluders are world AABBs of solid, closed, opaque geometry: the caller guarantees that every
// pixel centre (sample) strictly inside the box's projection is drawn by the occluder at a depth
// no farther than the box's farthest point (true of box-shaped buildings).
// 1. An occluder is used only if all 8 corners have w > 0 and lie inside the depth range
//    0 <= z <= w (zero_to_one form), with a relative margin: then the whole box is unclipped in
//    depth, and its projection is exactly the convex hull of the projected corners (projective
//    maps keep convexity where w > 0). Otherwise it is skipped (never inserted: conservative).
// 2. The hull is eroded by kHorizonPixelMargin (a disk of that radius must fit inside), done
//    exactly as the intersection of its edges' half-planes moved inward. Its lower boundary lo(x)
//    is a max of affine functions (convex), its upper boundary hi(x) a min (concave), so for a
//    strip [c, c+1] inside its x-range every point (x, y) with
//    max(lo(c), lo(c+1)) <= y <= min(hi(c), hi(c+1)) is in the eroded hull: strictly inside the
//    projection by at least the margin, hence drawn by the occluder even after the rasterizer
//    snaps its vertices.
// 3. Per column the covered interval is merged: union when the intervals overlap or touch (every
//    point of the union is covered), else the one with the larger hi is kept (the horizon).
//    Stored as floats rounded inward, clamped to the viewport's [0, H].
// 4. Depth order: occluders are inserted in order of their farthest view depth (max corner w),
//    objects tested in order of their nearest (min corner w); an occluder is inserted before an
//    object only when far_w * (1 + kHorizonDepthMargin) < near_w. Clip w is linear in world
//    space and zero at the eye, so along every pixel ray it grows with distance: every point of
//    every inserted occluder is strictly nearer than every point of the object, on every ray.
//    (This assumes a perspective world_to_clip, the eye its centre of projection; for an
//    orthographic one w is constant and nothing is ever occluded.) An object never hides itself.
// 5. An object is occluded when all 8 corners have w > 0 (with margin) and its window rectangle,
//    grown by kHorizonPixelMargin and clipped to the viewport, lies inside [lo(c), hi(c)] for
//    every column c it overlaps: every sample it can draw in the viewport is then drawn nearer
//    by an inserted occluder. Objects crossing the eye plane, or wholly outside the viewport, are
//    reported not occluded (the frustum test handles the latter).
//
// Rounding: corners are transformed and projected in double from the float inputs (exact
// products, relative error ~1e-16 of the terms), so the only margins are for the renderer:
// kHorizonPixelMargin = 1/16 pixel on each side (occluders shrunk, objects grown: together 1/8
// pixel) covers GL's sub-pixel snapping (GL_SUBPIXEL_BITS >= 4: a vertex moves <= 1/32 pixel), the
// rasterizer's tie rules (points on an edge may go either way) and float window coordinates
// (<= 16384 * 2^-22 = 0.004 pixel); kHorizonDepthMargin = 2^-16 relative in w covers the float
// vertex transform's depth error. As everywhere in patchcull, world coordinates must be in a frame
// near the camera (mesh.h, camera.h): the renderer's own float transform of coordinates of 1e4
// errs by ~1e-3 units, which no margin here can know about. Depth-buffer quantization ties
// (an object within the depth resolution behind an occluder) are z-fighting anyway.
//
// Boxes: empty boxes (min > max on an axis) draw nothing: empty occluders are skipped, empty
// objects are reported occluded (as classify_aabb reports them outside). A NaN coordinate: the
// occluder is skipped, the object is never occluded. Infinite coordinates likewise.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "patchcull/core/clip_space.h"
#include "patchcull/core/math.h"
#include "patchcull/core/mesh.h"

namespace patchcull {

/// Erosion of occluder projections and growth of object rectangles, in pixels (see above).
inline constexpr double kHorizonPixelMargin = 1.0 / 16;
/// Relative view-depth gap an occluder needs in front of an object (see above).
inline constexpr double kHorizonDepthMargin = 1.0 / 65536;

/// Counters of one or more cull() calls (cull adds to them).
struct HorizonStats {
    std::uint32_t occluders_inserted = 0;  ///< merged into the horizon (nearer than some object)
    std::uint32_t occluders_skipped = 0;   ///< empty, NaN, infinite, behind the eye or depth-clipped
    std::uint32_t objects_tested = 0;      ///< every object given (each gets a verdict)
    std::uint32_t objects_occluded = 0;    ///< objects with occluded[i] = 1 (empty boxes included)
};

class OcclusionHorizon {
public:
    /// occluded[i] = 1 when object i is hidden by the occluders (else 0), for i < object_count.
    /// world_to_clip: projection * view (GL conventions, math.h), perspective; depth: its clip
    /// depth convention (clip_space.h); width x height: the viewport (0, 0, width, height) in
    /// pixels, each 1..16384 (else throws patchcull::Error, before writing anything). Occluders and
    /// objects are world AABBs (see the file comment for what each must hold); either pointer may
    /// be null when its count is 0 (else throws). Empty objects are reported occluded, NaN or
    /// infinite ones never. Adds to stats. Reuses its buffers: allocates only when width or the
    /// counts exceed those of earlier calls. Conservative: see the file comment.
    void cull(const Mat4& world_to_clip, ClipDepth depth, int width, int height, const Bounds* occluders,
              std::size_t occluder_count, const Bounds* objects, std::size_t object_count, std::uint8_t* occluded,
              HorizonStats& stats);

    /// The horizon after the last cull, one value per column (width of that call): the covered
    /// interval [column_low()[c], column_high()[c]] in window y, within [0, height]; low > high
    /// means nothing covered. It holds the occluders inserted during that call (those nearer than
    /// the farthest object tested), not necessarily all of them. For tests and pictures.
    const std::vector<float>& column_low() const { return low_; }
    const std::vector<float>& column_high() const { return high_; }

private:
    struct Keyed {
        double key;           ///< occluder: farthest clip w; object: nearest clip w
        std::uint32_t index;  ///< into the caller's array
    };
    void insert(const Bounds& occluder);
    bool covered(const Bounds& object) const;

    // The current call's camera, in double: rows of world_to_clip (z in zero_to_one form).
    double clip_[4][4] = {};
    int width_ = 0, height_ = 0;
    std::vector<float> low_, high_;
    std::vector<Keyed> occluder_order_, object_order_;
};

}  // namespace patchcull
