// patchcull/core/backpatch.h: back-patch cull kernels (Loop, Niessner & Eisenacher): a patch is culled (culled[i] = 1)
// only when no point of it faces the eye, i.e. e . T(u,v) <= 0 for all (u,v) in [0,1]^2, where
// T(u,v) = cross4(B, B_u, B_v) is the parametric tangent plane (Loop, Niessner & Eisenacher §3) and e the
// homogeneous eye point. For a polynomial patch, e . T = n . (e - p) with n = B_u x B_v, so a
// patch faces the eye where its outward normal (du x dv, patch.h) points towards the eye.
//
// Methods (each a `patchcull cull` method name):
// - tcone (Loop, Niessner & Eisenacher §2, Sederberg & Meyers 1988 as Munkberg et al. 2010 use it): a cone of
//   normals built from the cones of the tangent patch B_u and the bitangent patch B_v.
// - ncone (Loop, Niessner & Eisenacher §2, Shirman & Abi-Ezzi 1993): a cone bounding the normal patch
//   N = B_u x B_v in Bezier form (bidegree 5).
//   Both cone tests are made conservative for a perspective eye and a patch of finite extent:
//   with the patch inside a sphere (c, r) and d = e - c, the directions e - p (p on the patch)
//   lie within angle beta = asin(r/|d|) of d, so the patch is back-facing when
//   angle(a, d) >= 90deg + alpha + beta, i.e. |d| > r, alpha + beta <= 90deg and
//   a . d/|d| <= -sin(alpha + beta). (Without the alpha + beta <= 90deg condition the last
//   inequality also holds for facing patches: alpha = beta = 80deg, angle(a, d) = 175deg.)
//   Cones apply to polynomial patches (all w = 1); a rational patch is never culled by them.
// - ptp (Loop, Niessner & Eisenacher §3-6): the 8x8 Bezier control planes of T, from the 516 weighted cross4
//   products of the clip-space control points, evaluated as z components only (cross4Z). With
//   the eye at (0, 0, alpha, 0) in clip space, e . t_i = s * alpha * t_i.z, where s = sign(det M)
//   because cross4 of transformed points is det(M) times the transformed plane (det < 0 for
//   every GL perspective here; the kernels fold sign(alpha) * sign(det M) into the matrix rows
//   once per call, so mirroring model matrices work too). DVis on Ncnt: culled when all 64
//   e . t_i < 0. ptp-pcnt: culled when no e . t_i > 0 (Pcnt = 0), which also culls degenerate
//   patches with collapsed edges (the teapot's top). Rational patches are supported.
//   Float rounding: each computed t_i must be below -thr_i, thr_i a rigorous bound on its
//   rounding error (per patch, from the control points' magnitude and clip-space extent; 0 on
//   collapsed edges, whose planes are exact zeros), so a plane that faces the eye by less than
//   float precision keeps the patch (src/core/ptp_schedule.h derives the bound; without it,
//   distant edge-on patches were falsely culled about once per million culls). A non-finite
//   control point keeps the patch.
//
// Contracts: culled must hold patches.count bytes. Kernels never allocate or throw; each has a
// scalar reference and a SIMD version that give identical decisions. Displacement is not
// handled by back-patch culling (Loop, Niessner & Eisenacher §8): callers must not use these on displaced patches.
#pragma once

#include <cstdint>

#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"

namespace patchcull {

/// z of the eye in clip space for a projection that maps the eye (view-space origin) to
/// (0, 0, alpha, 0): alpha = projection(2,3). Negative for perspective() in math.h.
inline float clip_space_eye_alpha(const Mat4& projection) { return projection.at(2, 3); }

void cull_tcone_scalar(const PatchBatchView& patches, Vec3 eye, std::uint8_t* culled);
void cull_tcone_simd(const PatchBatchView& patches, Vec3 eye, std::uint8_t* culled);

void cull_ncone_scalar(const PatchBatchView& patches, Vec3 eye, std::uint8_t* culled);
void cull_ncone_simd(const PatchBatchView& patches, Vec3 eye, std::uint8_t* culled);

enum class PtpRule { ncnt, pcnt };

/// The orientation sign s = sign(alpha) * sign(det object_to_clip) that the ptp kernels fold into
/// the rows of object_to_clip (see ptp above; det in double), or 0 when nothing may be culled
/// (alpha or det zero or not finite). For GPU twins of the ptp kernels.
int ptp_orientation_sign(const Mat4& object_to_clip, float alpha);
/// object_to_clip = projection * view (* model); alpha = clip_space_eye_alpha(projection).
void cull_ptp_scalar(const PatchBatchView& patches, const Mat4& object_to_clip, float alpha, PtpRule rule,
                     std::uint8_t* culled);
void cull_ptp_simd(const PatchBatchView& patches, const Mat4& object_to_clip, float alpha, PtpRule rule,
                   std::uint8_t* culled);

}  // namespace patchcull
