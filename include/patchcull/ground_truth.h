// patchcull/ground_truth.h: what "conservative" is measured against (DESIGN.md, CPU side).
//
// The (displaced) surface is sampled densely: a grid x grid lattice over the patch domain, each
// sample S(u,v) = B(u,v) + D(s,t) * n(u,v) with n the unit normal (from the ACC tangent patches
// when given, else from the patch's own derivatives; a degenerate normal leaves the sample
// undisplaced). A sample inside the clip volume means the patch is visible to the frustum test:
// culling it is a false cull. Clip tests run in double precision, independently of the kernels.
#pragma once

#include <cstddef>

#include "patchcull/displacement.h"
#include "patchcull/math.h"
#include "patchcull/patch.h"

namespace patchcull {

inline constexpr int kGroundTruthGrid = 17;  ///< samples per side (issue 2: "for example 17x17")

/// Writes grid*grid samples of the displaced patch to out (row v, column u). tangents and
/// displacement may be null; uv are the patch's corner texture coordinates (PatchInfo::uv).
void sample_displaced_patch(const BezierPatch& patch, const TangentPatches* tangents, const Vec2 uv[4],
                            const DisplacementMap* displacement, int grid, Vec3* out);

/// True when some point lies inside the clip volume of object_to_clip (-w<=x<=w, -w<=y<=w,
/// 0<=z<=w, w>0), evaluated in double precision.
bool any_point_in_clip_volume(const Mat4& object_to_clip, const Vec3* points, std::size_t count);

/// A sphere holding a set of points (not the smallest one; any holding sphere is exact for the
/// test below).
struct SampleSphere {
    Vec3 center;
    float radius = 0;
};
SampleSphere bounding_sphere(const Vec3* points, std::size_t count);

/// True when the whole sphere lies strictly outside one clip plane of object_to_clip, so none of
/// the points it holds can be in the clip volume. A fast, exact pre-check for
/// any_point_in_clip_volume (double precision, with a relative safety margin).
bool sphere_outside_clip_volume(const Mat4& object_to_clip, const SampleSphere& sphere);

}  // namespace patchcull
