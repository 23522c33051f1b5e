// patchcull/core/frustum.h: view-frustum cull kernels over patch batches (Niessner & Loop §4.1.1, Sathe).
//
// Clip space as in math.h: inside means -w <= x <= w, -w <= y <= w, 0 <= z <= w. Entries that
// take a clip matrix also take its ClipDepth (clip_space.h), with no default: a standard OpenGL
// projection (-w <= z <= w) is converted and a reversed one tested in its own form, never misread;
// a reversed matrix declared forward (or the other way) is refused (check_clip_depth). A patch is
// culled (culled[i] = 1) only when no point of the (displaced) patch can be inside; otherwise
// culled[i] = 0. Both kernels are plane tests in homogeneous clip space, so they stay correct
// when control points straddle w <= 0 (behind the eye): no division by w ever happens.
// A patch with a NaN or infinite coordinate is never culled (see "Non-finite input" below).
//
// - frustum (Niessner & Loop §4.1.1): the clip-space bounds of the control points. For a polynomial or
//   rational patch with positive weights, the patch lies in the convex hull of its homogeneous
//   control points, so if every control point is outside one clip plane the patch is too. With
//   w > 0 this equals "the NDC bounding box of the control points misses the clip cube".
//   Each control point goes to clip space once, (x, y, k, w) = K * P in hiz.h's step-2 order
//   (c_r = fma(M(r,3), W, fma(M(r,2), Z, fma(M(r,1), Y, M(r,0) * X)))) with K = to_depth_key(M)
//   (row z replaced by the depth-key row), and the six plane values
//   are w + x, w - x, w + y, w - y, k + near_w w, far_w w - k of those coordinates
//   (frustum_plane_values below; near_w, far_w are 0, 1 for the forward conventions, where k = z,
//   and 1, 0 for the reversed ones, where k = -z: the near plane z <= w and the far plane z >= 0;
//   both products are exact). reversed_infinite has no far plane: its far value is never compared.
//   the same clip coordinates serve the Hi-Z test's screen box (hiz.h, fused_cull.h), which is
//   what lets one fused kernel compute them once. Without displacement, fl(w + x) < 0 exactly
//   when x < -w for the computed floats (rounding keeps signs), so the tests are comparisons of
//   the clip coordinates, each carrying the relative error of the transform discussed below.
//   Displacement up to max_displacement[i] along a unit normal moves a plane value by at most
//   |D| * |plane row xyz| (per unit weight), which the kernel adds as a margin
//   fma(fl(D * |row xyz|), W, value) when margins are given.
// - frustum-disp (Sathe): the object-space AABB of the control points grown by max |D| on
//   every side; its 8 corners are transformed to clip space and tested against the clip planes
//   (the NDC in-out test, done as homogeneous comparisons). Without displacement (null
//   max_displacement) it is the box of the control points, valid for any patch but looser than
//   frustum's hull test; patch_source.h runs both over your own control points.
//
// Non-finite input: every clip coordinate of a control point with a NaN or infinite coordinate is
// itself NaN or infinite (a zero matrix entry times +-Inf is NaN, any sum with a non-finite term
// is non-finite), and the max over points would skip a NaN. So each kernel keeps a probe,
// fma(value, 0, probe), over one plane value of every point (frustum) or the coordinates of every
// point (frustum-disp): it stays 0 while every value is finite and becomes NaN for good at the
// first non-finite one, and a patch is culled only while its probe is 0. A finite point whose clip
// coordinate overflows is treated alike (not culled). Weights must be positive (patch.h).
//
// Contracts: culled must hold patches.count bytes; max_displacement is null (no displacement) or
// holds patches.count values >= 0. Kernels never allocate; those that take a matrix and a
// ClipDepth throw Error before their loop when the matrix contradicts it (check_clip_depth), never
// inside it; scalar and SIMD versions give
// identical decisions (tests/core/frustum_test.cpp): both use fused multiply-adds in the same order
// (see src/core/frustum.cpp). Values are computed in float with no extra padding for rounding, so a
// patch within ~1e-6 (relative) of a plane may go either way. That is far below the rasterizer's
// own precision (GL snaps vertices to 1/256 pixel after the same float transform; 1e-6 of the
// clip cube is 0.002 pixel at 4096 pixels), so it cannot change which pixels are covered.
// "Relative" means relative to the terms' magnitude, |control point| and the eye's distance from
// the frame's 0: patches must be in a local frame near them (ControlMesh::origin, mesh.h; a
// world camera comes in through WorldCamera::local, camera.h). World coordinates of 1e5 in float
// made visible BigGuy patches cull; in the local frame any translation culls alike.
#pragma once

#include <cmath>
#include <cstdint>

#include "patchcull/core/clip_space.h"
#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"

namespace patchcull {

/// The six clip planes as rows over object-space homogeneous points: plane k's value for a point
/// P is dot(rows[k], P) and P is inside when every value is >= 0. Order: left (w+x), right (w-x),
/// bottom (w+y), top (w-y), near (z), far (w-z).
struct FrustumPlanes {
    Vec4 rows[6];
    float normal_length[6];  ///< |rows[k].xyz|: bound on the change per unit object-space motion
    /// Rows x, y, k, w of to_depth_key(object_to_clip): the kernels' clip transform (rows[] are
    /// their sums and differences, kept for tests on boxes and spheres).
    Vec4 clip_rows[4];
    /// Near value k + near_w * w, far value far_w * w - k: (0, 1) forward, (1, 0) reversed.
    float near_w = 0, far_w = 1;
    /// The far plane culls where the far value is < far_limit: 0, or -infinity (never) for a
    /// projection without far plane (reversed_infinite, whose rows[5] is then (0, 0, 0, 1)).
    float far_limit = 0;
    ClipDepth depth = ClipDepth::zero_to_one;  ///< the convention the planes were made from
};

/// Planes of the clip volume of object_to_clip (projection * view * model) whose depth
/// convention is depth: the same planes, up to rounding, for one camera written in any
/// convention. Throws Error when the matrix contradicts depth (check_clip_depth).
FrustumPlanes make_frustum_planes(const Mat4& object_to_clip, ClipDepth depth);

/// The six plane values (frustum.h's order) of one object-space control point P = (X, Y, Z, W),
/// exactly as every frustum kernel, scalar, SIMD and GLSL (shaders/frustum_test.h), computes
/// them: clip coordinates in hiz.h's step-2 order, then (w + x, w - x, w + y, w - y,
/// k + near_w * w, far_w * w - k). A patch is culled when, for some q, the maximum of v[q] over
/// its 16 control points is < 0 (< far_limit for the far plane) and every value was finite
/// (FrustumVerdict).
inline void frustum_plane_values(const FrustumPlanes& planes, float X, float Y, float Z, float W, float v[6]);
/// With displacement margins (max_displacement given, even where it is 0): every value becomes
/// fma(fl(d * normal_length[q]), W, v[q]). Without margins the kernels skip this step.
inline void add_frustum_margins(const FrustumPlanes& planes, float d, float W, float v[6]);

/// A patch's frustum verdict, point by point, as every frustum kernel forms it (the SIMD and GLSL
/// ones do the same operations): the plane maxima and the non-finite probe.
struct FrustumVerdict {
    float max[6] = {-INFINITY, -INFINITY, -INFINITY, -INFINITY, -INFINITY, -INFINITY};
    float probe = 0;  ///< fma(v[4], 0, probe) over the points: 0 while finite, NaN after
    void add(const float v[6]) {
        probe = std::fma(v[4], 0.0f, probe);
        for (int q = 0; q < 6; ++q) max[q] = max[q] > v[q] ? max[q] : v[q];
    }
    bool culled(const FrustumPlanes& planes) const {
        bool out = max[5] < planes.far_limit;
        for (int q = 0; q < 5; ++q) out |= max[q] < 0.0f;
        return out && probe == 0.0f;
    }
};

/// frustum kernel, scalar reference.
struct CullView;  // cull_view.h

void cull_frustum_scalar(const PatchBatchView& patches, const float* max_displacement, const FrustumPlanes& planes,
                         std::uint8_t* culled);
/// frustum kernel, SIMD (Highway, best instruction set chosen once at run time).
void cull_frustum_simd(const PatchBatchView& patches, const float* max_displacement, const FrustumPlanes& planes,
                       std::uint8_t* culled);

/// frustum-disp kernel (Sathe), scalar reference.
void cull_frustum_disp_scalar(const PatchBatchView& patches, const float* max_displacement, const Mat4& object_to_clip,
                              ClipDepth depth, std::uint8_t* culled);
/// frustum-disp kernel, SIMD.
void cull_frustum_disp_simd(const PatchBatchView& patches, const float* max_displacement, const Mat4& object_to_clip,
                            ClipDepth depth, std::uint8_t* culled);

/// Name of the instruction set the SIMD kernels dispatch to on this machine (e.g. "AVX2").
const char* simd_target_name();

inline void frustum_plane_values(const FrustumPlanes& planes, float X, float Y, float Z, float W, float v[6]) {
    float c[4];
    for (int r = 0; r < 4; ++r) {
        const Vec4 m = planes.clip_rows[r];
        c[r] = std::fma(m.w, W, std::fma(m.z, Z, std::fma(m.y, Y, m.x * X)));
    }
    v[0] = c[3] + c[0];
    v[1] = c[3] - c[0];
    v[2] = c[3] + c[1];
    v[3] = c[3] - c[1];
    v[4] = c[2] + planes.near_w * c[3];
    v[5] = planes.far_w * c[3] - c[2];
}

inline void add_frustum_margins(const FrustumPlanes& planes, float d, float W, float v[6]) {
    for (int q = 0; q < 6; ++q) v[q] = std::fma(d * planes.normal_length[q], W, v[q]);
}

/// The SIMD kernels on one view's CullView (view.planes; view.object_to_clip in view.depth).
void cull_frustum(const PatchBatchView& patches, const float* max_displacement, const CullView& view,
                  std::uint8_t* culled);
void cull_frustum_disp(const PatchBatchView& patches, const float* max_displacement, const CullView& view,
                       std::uint8_t* culled);

}  // namespace patchcull
