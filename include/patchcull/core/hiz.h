// patchcull/core/hiz.h: the Hi-Z pyramid and the patch occlusion test (Niessner & Loop §4.1, §4.1.1), CPU side.
//
// Everything below is defined exactly, so that the GLSL compute-shader mirror can reproduce the
// pyramid bit for bit and the decisions operation by operation. Conventions are those of math.h:
// clip space of glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE) in any of clip_space.h's depth
// conventions. The pyramid and the test work on depth keys (clip_space.h): the window depth d for
// the forward conventions and -d for the reversed ones, so that a larger key is farther in every
// convention and "max of keys" keeps the farthest depth of a footprint (the min of d, reversed).
// Below, "depth" means the key.
//
// ---- Depth buffer ----------------------------------------------------------------------------
// W x H values, depth[y * W + x], row 0 = bottom (what glReadPixels returns; a GL texture's row 0
// is the bottom row too, so GPU depth and the pyramid agree without flipping). Pixel (x, y) is the
// window square [x, x+1) x [y, y+1); the viewport is (0, 0, W, H). Either floats (must not be NaN;
// GL writes values in [0,1]; the pyramid is exact for any non-NaN values) in the declared
// convention, or 24-bit unsigned normalized depth (GL_DEPTH24_STENCIL8, GL_DEPTH_COMPONENT24,
// Vulkan's X8_D24) in 32-bit words: value u stands for every depth that the depth test stores as
// u, so its key is the far end of that set, (u + 1/2) / (2^24 - 1) forward or -(u - 1/2) /
// (2^24 - 1) reversed, rounded one ulp outward (farther): a fragment that ties with u under
// GL_LEQUAL or GL_GEQUAL is then never hidden.
//
// ---- Pyramid (Niessner & Loop §4.1) ----------------------------------------------------------
// The full-resolution level is skipped (seed): level 0 has half resolution. With s(l) = 2^(l+1),
//   size:      W_l = ceil(W / s(l)),  H_l = ceil(H / s(l))     (equivalently W_{l+1} = ceil(W_l / 2))
//   footprint: texel (tx, ty) of level l covers exactly the depth pixels (x, y) with
//              x >> (l+1) == tx and y >> (l+1) == ty (those that exist: x < W, y < H);
//   value:     T_l(tx, ty) = max of depth over that footprint.
// Every depth pixel lies in exactly one texel of every level: pixel (x, y) -> (x >> (l+1), y >> (l+1)).
// Levels go down to 1x1: levels() = max(1, ceil(log2(max(W, H)))). Built by max reduction:
// T_0(tx,ty) = max of depth(2tx+i, 2ty+j), T_l(tx,ty) = max of T_{l-1}(2tx+i, 2ty+j), i, j in {0,1},
// children outside the parent level skipped. Max is exact in float, so the values are the same
// whatever the order or the grouping: a GL shader reproduces them bit for bit.
//
// NPOT handling, and why "unused texels = 0" (seed) is right: the seed enlarges the map to the next
// power of two so that a 5x5 level reduces to 3x3, not 2x2 (GL mip sizes round down and would drop
// the last row/column). The sizes above (rounding up) are exactly the used part of that enlarged
// map. The texels (and depth pixels) outside it cover no screen pixel; a max reduction must treat
// them as the identity of max, i.e. a value <= every real depth: 0, the nearest depth, since depths
// are in [0,1]. (A far value 1 there would be conservative too but would make every texel along the
// right/top edge 1, so nothing touching the edge could ever be occluded.) 0 is never read on its
// own: rectangles are clamped to the screen, so every texel the test reads covers at least one
// real pixel. Hence a GL implementation may use a POT texture whose unused texels are 0 with the
// standard 2x2 reduction: the used texels equal T_l above exactly (for depths in [0,1]; tested).
// Storage: level l is a row-major W_l x H_l block (row 0 = bottom) at level(l).offset in data().
//
// ---- Occlusion test (Niessner & Loop §4.1.1), per patch, in this order -----------------------
// 1. Frustum: exactly cull_frustum_scalar without displacement (frustum.h; the kernels call it,
//    or cull_frustum_simd, whose decisions are identical). Culled -> kHiZFrustumCulled.
// 2. Clip-space control points: for each control point P_k (object space, homogeneous) and row r of
//    M = to_depth_key(object_to_clip) (row z gives the depth key), c_r = fma(M(r,3), W, fma(M(r,2), Z, fma(M(r,1), Y,
//    M(r,0) * X))).
// 3. Projectable: every control point has w_k > 2^-20 * s_k, with
//    s_k = fma(|M(3,3)|, |W|, fma(|M(3,2)|, |Z|, fma(|M(3,1)|, |Y|, |M(3,0)| * |X|))).
//    s_k bounds the terms of w_k, and the rounding error of the computed w_k is below 2^-22 s_k, so
//    this proves the exact w_k > 0 (a plain `w > 0` can be wrong for a point within rounding of
//    the eye plane, whose projection would then be mirrored). Otherwise (control points straddle
//    w <= 0, or touch it) the patch cannot be projected: kHiZVisible (such patches are
//    culled by the homogeneous plane tests only, never by a screen rectangle).
//    Why the box is exact: with all weights and all w_k > 0, every point of the patch is a convex
//    combination of the control points in clip space, and x/w, y/w, z/w of such a point are convex
//    combinations of the x_k/w_k, y_k/w_k, z_k/w_k; so the NDC box of the control points bounds the
//    whole patch, and z/w >= min_k z_k/w_k on the whole patch.
// 4. NDC box and front plane: nx_k = x_k / w_k, ny_k = y_k / w_k, nz_k = z_k / w_k (IEEE division,
//    correctly rounded); nxmin/nxmax/nymin/nymax/zmin = min/max over k.
// 5. Window box: xlo = fma(nxmin, W/2, W/2), xhi = fma(nxmax, W/2, W/2), ylo/yhi likewise with H/2
//    (W/2, H/2 exact floats). Rounding is monotone, so these equal the min/max of the per-point
//    window coordinates.
// 6. Pixel rectangle (inclusive): x0 = clamp(floor(xlo), 0, W-1), x1 = clamp(floor(xhi), 0, W-1),
//    y0/y1 likewise with H-1, the clamp done in float before the conversion to int. These are all
//    pixels whose square touches the box: a superset of the pixels whose centre (or any MSAA sample)
//    is inside it, with at least 0.5 pixel to spare on every side for the rasterizer's sub-pixel
//    snapping and the rounding of the tessellated vertices. Clamping (seed: "clamp bounding box
//    corners to screen space") is exact because GL clips everything outside the viewport.
// 7. Level (seed: level = ceil(log2(max(width, height))), but in pixel indices and for this
//    pyramid, whose level l has texels of s(l) = 2^(l+1) pixels): L = the smallest level l >= 0 at
//    which the rectangle meets at most 2 texels per axis:
//       (x1 >> (l+1)) - (x0 >> (l+1)) <= 1  and  (y1 >> (l+1)) - (y0 >> (l+1)) <= 1.
//    Computed in O(1) (hiz_select_level): with span = max(x1 - x0, y1 - y0), a rectangle of
//    span + 1 pixels meets at most 2 texels of size s at any alignment iff span <= s, so
//    Lc = (span <= 2) ? 0 : bit_width(span - 1) - 1   (= ceil(log2(span)) - 1, integer-exact)
//    always qualifies, no level below Lc - 1 can (span > 2 s(Lc - 2) means >= 3 texels), and
//    L = Lc - 1 when Lc > 0 and that level qualifies, else Lc. (A `floor` instead of the ceil
//    would pick a level where the rectangle can meet 3 texels per axis, of which only the outer
//    two are read: false occlusion; tests/core/hiz_test.cpp shows it.) L <= levels() - 1 always.
// 8. Hi-Z value: tx0 = x0 >> (L+1), tx1 = x1 >> (L+1), ty0, ty1 likewise; h = max of
//    T_L(tx0,ty0), T_L(tx1,ty0), T_L(tx0,ty1), T_L(tx1,ty1) (tx0 == tx1 or ty0 == ty1 reads a texel
//    twice; max is unaffected). These texels hold every depth pixel of the rectangle.
// 9. Decision: kHiZOccluded iff h < zmin (strict), else kHiZVisible. Conservative: for a float h
//    and a correctly rounded q = fl(z/w), h < fl(z/w) implies h < z/w exactly (rounding is
//    monotone and h is a float), so every pixel the patch can cover already holds a depth strictly
//    nearer than any point of the patch, which then fails both GL_LESS and GL_LEQUAL.
//
// Precision limits (honest): the exactness of steps 4-9 is relative to the computed clip coordinates;
// the float clip transform (step 2) itself rounds (~1e-7 relative, like the frustum kernels, which
// add no padding either), and so do the rasterizer's depth and the TES's evaluation. A fragment could
// therefore land a few ulps in front of zmin; a patch that close to the occluder's surface is
// z-fighting with it anyway. The matrix must be finite; a control point that is not is never culled. Pyramid texels are
// bit-exact maxima; where -0 and +0 tie, either may be stored (they compare equal, so decisions
// cannot differ).
// GLSL mirror notes: all steps are IEEE add/mul/fma/min/max/floor and integer ops, which GLSL
// evaluates exactly when declared `precise` (fma() then has a single rounding), except the
// divisions of step 4: GLSL allows 2.5 ulp there, so a driver with approximate division can
// differ from this reference for a patch whose box edge lies within a few ulps of a pixel edge or
// whose zmin lies within a few ulps of h. Use an exactly rounded division in the shader (e.g. a
// quotient corrected by its fma residual), or have the equality test tolerate only such ties.
//
// Extension point (displaced patches, Niessner & Loop §4.2): a displaced patch gets its window
// box and front plane from the camera-aligned frustum instead of steps 2-5; steps 6-9 are
// hiz_rect_from_window_box + hiz_rect_max + `h < zmin`, shared by both. The kernels below take no
// displacement yet.
//
// SIMD: cull_occlusion_simd is the fused kernel (fused_cull.h) with the plan {frustum, occlusion}:
// steps 1-6 (clip coordinates once for the frustum planes and the screen box, 16x3 divisions per
// patch: the bulk of the work) over Highway vectors, one patch per lane, a group leaving once all
// its lanes are frustum-culled, and steps 7-9 (data-dependent level and up to 4 texel loads: an
// irregular gather that vectors do not speed up) per patch with the same code as the scalar
// reference. Decisions are identical to cull_occlusion_scalar (tested on every target).
//
// Contracts: decision must hold patches.count bytes; the pyramid must be built in the matrix's
// direction; kernels never allocate, and throw Error only before their loop (a matrix that
// contradicts its convention, a pyramid of the other direction or never built).
// HiZPyramid::build allocates only when the size changes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "patchcull/core/clip_space.h"
#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"

namespace patchcull {

/// One level of a HiZPyramid: width x height texels, row-major from data() + offset.
struct HiZLevel {
    int width = 0;
    int height = 0;
    std::size_t offset = 0;
};

/// Max-reduced depth pyramid of a W x H depth buffer (definitions at the top of this header).
class HiZPyramid {
public:
    static constexpr int kMaxLevels = 32;

    HiZPyramid() = default;
    HiZPyramid(int depth_width, int depth_height) { resize(depth_width, depth_height); }

    /// Sets the depth-buffer size (>= 1 each) and the level layout; allocates when the texel count
    /// changes. Contents are unspecified until build().
    void resize(int depth_width, int depth_height);

    /// Builds every level from depth (depth_width * depth_height floats, row 0 = bottom), written in
    /// convention (clip_space.h: texels hold its depth keys). Calls resize() first, so it
    /// allocates only when the size differs from the last one.
    void build(const float* depth, int depth_width, int depth_height, ClipDepth convention);
    /// build(depth, w, h, ClipDepth::zero_to_one): a forward depth buffer (either forward
    /// convention writes the same window depths).
    void build(const float* depth, int depth_width, int depth_height);
    /// Builds from 24-bit unsigned normalized depth: value (word >> depth_shift) & 0xFFFFFF of each
    /// 32-bit word (depth_shift 8 for GL_UNSIGNED_INT_24_8, i.e. GL_DEPTH24_STENCIL8 read with its
    /// stencil; 0 for depth in the low 24 bits), keys as described at the top of this header.
    void build_unorm24(const std::uint32_t* depth, int depth_width, int depth_height, int depth_shift,
                       ClipDepth convention);
    /// True when built from a reversed depth buffer (texels are minus the depths).
    bool reversed() const { return reversed_; }

    int depth_width() const { return width_; }
    int depth_height() const { return height_; }
    int levels() const { return levels_; }
    const HiZLevel& level(int l) const { return level_[l]; }
    /// T_l(tx, ty); 0 <= tx < level(l).width, 0 <= ty < level(l).height.
    float texel(int l, int tx, int ty) const {
        return data_[level_[l].offset + static_cast<std::size_t>(ty) * level_[l].width + tx];
    }
    const float* data() const { return data_.data(); }
    /// Texels in all levels together.
    std::size_t size() const { return data_.size(); }

    /// Number of levels for a W x H depth buffer: max(1, ceil(log2(max(W, H)))).
    static int level_count(int depth_width, int depth_height);

private:
    void reduce_upper_levels();
    std::vector<float> data_;
    HiZLevel level_[kMaxLevels];
    int width_ = 0, height_ = 0, levels_ = 0;
    bool reversed_ = false;
};

/// Throws Error("<what>: ...") unless hiz was built and in a convention of depth's direction
/// (forward or reversed): the kernels call it before their loops.
void check_hiz_convention(const HiZPyramid& hiz, ClipDepth depth, const char* what);

/// Inclusive rectangle of depth pixels: x0 <= x <= x1, y0 <= y <= y1.
struct PixelRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

/// Step 6: the pixels touched by the window box [xlo, xhi] x [ylo, yhi], clamped to the W x H
/// screen. Requires xlo <= xhi, ylo <= yhi, no NaN (infinities are clamped).
PixelRect hiz_rect_from_window_box(float xlo, float xhi, float ylo, float yhi, int width, int height);

/// Step 7: the finest level of a pyramid at which rect meets at most 2x2 texels, capped at
/// levels - 1 (never reached for a rectangle inside the screen). rect must be inside the screen.
int hiz_select_level(const PixelRect& rect, int levels);

/// Step 8: max of the (at most) 2x2 texels at level hiz_select_level() holding rect; >= the depth
/// of every pixel of rect. rect must lie inside the pyramid's depth buffer.
float hiz_rect_max(const HiZPyramid& hiz, const PixelRect& rect);

/// Steps 2-6 for one patch. Returns false (patch not projectable: step 3) or true with the pixel
/// rectangle and zmin = min_k fl(z_k / w_k) filled in.
struct PatchScreenBounds {
    PixelRect rect;
    float zmin = 0;
};
/// object_to_clip's depth convention is depth (clip_space.h); zmin is the smallest depth key of the
/// control points (the window depth with glDepthRange(0, 1), negated for reversed conventions).
bool patch_screen_bounds(const PatchBatchView& patches, std::size_t index, const Mat4& object_to_clip, ClipDepth depth,
                         int width, int height, PatchScreenBounds& out);

/// Per-patch decision bytes written by the kernels.
enum HiZDecision : std::uint8_t {
    kHiZVisible = 0,        ///< draw it
    kHiZFrustumCulled = 1,  ///< outside one clip plane (same as cull_frustum_scalar, no displacement)
    kHiZOccluded = 2,       ///< behind the Hi-Z pyramid
};

/// Frustum + occlusion test (steps 1-9), scalar reference. The screen is the pyramid's depth buffer
/// (viewport (0, 0, W, H)). decision must hold patches.count bytes. depth: object_to_clip's
/// convention (clip_space.h); the pyramid must be built from a depth buffer of the same direction
/// (forward or reversed). Throws Error before the loop when the matrix contradicts depth or the
/// pyramid does not match (check_clip_depth, check_hiz_convention). A patch with a non-finite
/// coordinate is never culled (step 1 keeps it, step 3 finds it not projectable).
void cull_occlusion_scalar(const PatchBatchView& patches, const Mat4& object_to_clip, ClipDepth depth,
                           const HiZPyramid& hiz, std::uint8_t* decision);
/// Same decisions, steps 1-6 in SIMD (Highway, target chosen once at run time): the fused kernel's
/// {frustum, occlusion} plan (fused_cull.h; defined in src/core/fused_cull_simd.cpp).
void cull_occlusion_simd(const PatchBatchView& patches, const Mat4& object_to_clip, ClipDepth depth,
                         const HiZPyramid& hiz, std::uint8_t* decision);

struct CullView;  // cull_view.h
/// cull_occlusion_simd on one view's CullView (view.object_to_clip in view.depth).
void cull_occlusion(const PatchBatchView& patches, const CullView& view, const HiZPyramid& hiz, std::uint8_t* decision);

}  // namespace patchcull
