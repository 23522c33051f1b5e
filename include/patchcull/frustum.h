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
//   Displacement up to max_displacement[i] along a unit normal moves a plane value by at most
//   |D| * |plane row xyz|, which the kernel adds as a margin (scaled by each point's weight).
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
};

/// Planes of the clip volume of object_to_clip (projection * view * model) whose depth
/// convention is depth (to_zero_to_one first, so the planes, and every kernel decision on them,
/// are the same for one camera written in either convention).
FrustumPlanes make_frustum_planes(const Mat4& object_to_clip, ClipDepth depth);

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

}  // namespace patchcull
