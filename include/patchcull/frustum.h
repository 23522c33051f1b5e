// patchcull/frustum.h: view-frustum cull kernels over patch batches (seed 000 §4.1.1, seed 002).
//
// Clip space as in math.h: inside means -w <= x <= w, -w <= y <= w, 0 <= z <= w. Entries that
// take a clip matrix also take its ClipDepth (clip_space.h), with no default: a standard OpenGL
// projection (-w <= z <= w) is converted, never misread. A patch is
// culled (culled[i] = 1) only when no point of the (displaced) patch can be inside; otherwise
// culled[i] = 0. Both kernels are plane tests in homogeneous clip space, so they stay correct
// when control points straddle w <= 0 (behind the eye): no division by w ever happens.
//
// - frustum (seed 000 §4.1.1): the clip-space bounds of the control points. For a polynomial or
//   rational patch with positive weights, the patch lies in the convex hull of its homogeneous
//   control points, so if every control point is outside one clip plane the patch is too. With
//   w > 0 this equals "the NDC bounding box of the control points misses the clip cube".
//   Each control point goes to clip space once, (x, y, z, w) = M * P in hiz.h's step-2 order
//   (c_r = fma(M(r,3), W, fma(M(r,2), Z, fma(M(r,1), Y, M(r,0) * X)))), and the six plane values
//   are w + x, w - x, w + y, w - y, z, w - z of those coordinates (frustum_plane_values below):
//   the same clip coordinates serve the Hi-Z test's screen box (hiz.h, fused_cull.h), which is
//   what lets one fused kernel compute them once. Without displacement, fl(w + x) < 0 exactly
//   when x < -w for the computed floats (rounding keeps signs), so the tests are comparisons of
//   the clip coordinates, each carrying the relative error of the transform discussed below.
//   Displacement up to max_displacement[i] along a unit normal moves a plane value by at most
//   |D| * |plane row xyz| (per unit weight), which the kernel adds as a margin
//   fma(fl(D * |row xyz|), W, value) when margins are given.
// - frustum-disp (seed 002): the object-space AABB of the control points grown by max |D| on
//   every side; its 8 corners are transformed to clip space and tested against the clip planes
//   (the NDC in-out test, done as homogeneous comparisons).
//
// Contracts: culled must hold patches.count bytes; max_displacement is null (no displacement) or
// holds patches.count values >= 0. Kernels never allocate or throw; scalar and SIMD versions give
// identical decisions (tests/core/frustum_test.cpp): both use fused multiply-adds in the same order
// (see src/core/frustum.cpp). Values are computed in float with no extra padding for rounding, so a
// patch within ~1e-6 (relative) of a plane may go either way. That is far below the rasterizer's
// own precision (GL snaps vertices to 1/256 pixel after the same float transform; 1e-6 of the
// clip cube is 0.002 pixel at 4096 pixels), so it cannot change which pixels are covered.
// "Relative" means relative to the terms' magnitude, |control point| and the eye's distance from
// the frame's 0: patches must be in a local frame near them (ControlMesh::origin, mesh.h; a
// world camera comes in through WorldCamera::local, camera.h). World coordinates of 1e5 in float
// made visible BigGuy patches cull (issue 9); in the local frame any translation culls alike.
#pragma once

#include <cmath>
#include <cstdint>

#include "patchcull/clip_space.h"
#include "patchcull/math.h"
#include "patchcull/patch.h"

namespace patchcull {

/// The six clip planes as rows over object-space homogeneous points: plane k's value for a point
/// P is dot(rows[k], P) and P is inside when every value is >= 0. Order: left (w+x), right (w-x),
/// bottom (w+y), top (w-y), near (z), far (w-z).
struct FrustumPlanes {
    Vec4 rows[6];
    float normal_length[6];  ///< |rows[k].xyz|: bound on the change per unit object-space motion
    /// Rows x, y, z, w of the zero_to_one object_to_clip matrix: the kernels' clip transform
    /// (rows[] are their sums and differences, kept for tests on boxes and spheres).
    Vec4 clip_rows[4];
};

/// Planes of the clip volume of object_to_clip (projection * view * model) whose depth
/// convention is depth (to_zero_to_one first, so the planes, and every kernel decision on them,
/// are the same for one camera written in either convention).
FrustumPlanes make_frustum_planes(const Mat4& object_to_clip, ClipDepth depth);

/// The six plane values (frustum.h's order) of one object-space control point P = (X, Y, Z, W),
/// exactly as every frustum kernel, scalar, SIMD and GLSL (shaders/frustum_test.h), computes
/// them: clip coordinates in hiz.h's step-2 order, then (w + x, w - x, w + y, w - y, z, w - z).
/// A patch is culled when, for some q, the maximum of v[q] over its 16 control points is < 0.
inline void frustum_plane_values(const FrustumPlanes& planes, float X, float Y, float Z, float W, float v[6]);
/// With displacement margins (max_displacement given, even where it is 0): every value becomes
/// fma(fl(d * normal_length[q]), W, v[q]). Without margins the kernels skip this step.
inline void add_frustum_margins(const FrustumPlanes& planes, float d, float W, float v[6]);

/// frustum kernel, scalar reference.
void cull_frustum_scalar(const PatchBatchView& patches, const float* max_displacement,
                         const FrustumPlanes& planes, std::uint8_t* culled);
/// frustum kernel, SIMD (Highway, best instruction set chosen once at run time).
void cull_frustum_simd(const PatchBatchView& patches, const float* max_displacement,
                       const FrustumPlanes& planes, std::uint8_t* culled);

/// frustum-disp kernel (seed 002), scalar reference.
void cull_frustum_disp_scalar(const PatchBatchView& patches, const float* max_displacement,
                              const Mat4& object_to_clip, ClipDepth depth, std::uint8_t* culled);
/// frustum-disp kernel, SIMD.
void cull_frustum_disp_simd(const PatchBatchView& patches, const float* max_displacement,
                            const Mat4& object_to_clip, ClipDepth depth, std::uint8_t* culled);

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
    v[4] = c[2];
    v[5] = c[3] - c[2];
}

inline void add_frustum_margins(const FrustumPlanes& planes, float d, float W, float v[6]) {
    for (int q = 0; q < 6; ++q) v[q] = std::fma(d * planes.normal_length[q], W, v[q]);
}

}  // namespace patchcull
