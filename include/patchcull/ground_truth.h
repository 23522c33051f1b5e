// patchcull/ground_truth.h: what "conservative" is measured against on the CPU (the GPU side is
// the unculled render's patch-id buffer; README, "What contributes a pixel").
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

// ---- back-facing ground truth (seed 001) --------------------------------------------------

/// A homogeneous plane in double precision.
struct PlaneD {
    double x = 0, y = 0, z = 0, w = 0;
};

/// Parametric tangent planes T(u,v) = cross4(B, B_u, B_v) (object space; seed 001 eq. 1) of the
/// patch at a grid x grid lattice (row v, column u), computed directly in double precision.
/// For a polynomial patch T = (n, -n.p) with n = B_u x B_v, so e . T = n . (e - p).
void sample_tangent_planes(const BezierPatch& patch, int grid, PlaneD* out);

/// True when some sampled tangent plane faces the eye: e . T > tolerance, where the tolerance
/// (1e-5 relative to |T.xyz| (|e| + |T.w|/|T.xyz|)) absorbs the float rounding of the kernels.
/// A culled patch with a facing sample is a false back-patch cull.
bool any_plane_faces_eye(const PlaneD* planes, std::size_t count, Vec3 eye);

/// A point in double precision.
struct PointD {
    double x = 0, y = 0, z = 0;
};

/// Surface points of the patch (undisplaced) at a grid x grid lattice, evaluated in double.
void sample_patch_points(const BezierPatch& patch, int grid, PointD* out);

/// True when some triangle of the uniform level-(grid-1) tessellation of the grid of surface
/// points (row v, column u) faces the eye. Both diagonals of every cell are tried, so the result
/// holds whatever triangulation the tessellator picks. Triangles without area (relative to
/// their edges, 1e-12: collapsed patch edges) face nowhere. Same tolerance rule as above.
bool any_tessellation_triangle_faces_eye(const PointD* grid_points, int grid, Vec3 eye);

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
