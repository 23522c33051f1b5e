// patchcull/objects/bounding_volumes.h: object-level bounding volumes (sphere, AABB, OBB) and their
// view-frustum tests, meta-BVs, plane masking and plane coherence, and detail culling, after
// G. Zachmann's lecture "Advanced Visibility Computations" ("Bounding Volumes", "Test
// Kugel/Box - Frustum", "N-/P-Vertex", "Meta-BVs", "zeitliche Kohärenz", "Plane Masking",
// "Detail Culling"). The object pre-test that Niessner & Loop ("Patch-Based Occlusion Culling for
// Hardware Tessellation", §3) ask for before patch culling. The hierarchy over these
// volumes is in object_bvh.h.
//
// Frustum planes are patchcull::FrustumPlanes (frustum.h): six rows over homogeneous points, a
// point P inside when dot(rows[k], P) >= 0 for every k. With make_frustum_planes(world_to_clip)
// they are world-space planes (not normalized: normal_length[k] = |rows[k].xyz|).
//
// Classification (every test below): outside = no point of the volume is inside the frustum
// (conservative: a volume with a point inside the frustum is never outside); inside = every
// point of the volume is inside every plane; intersecting otherwise (which includes volumes
// outside the frustum but outside no single plane: the plane tests' "false negatives", which
// meta_rejects catches in part).
//
// Float rounding (how the tests stay conservative). A plane value v = dot(rows[k], (c, 1)) is
// evaluated as fma(z, Z, fma(y, Y, fma(x, X, w))) in float. Its error, plus that of rows[k]
// itself (one rounding per element in make_frustum_planes), plus that of normal_length, is below
// 6 u (u = 2^-24) times (|x X| + |y Y| + |z Z| + |w| + r |rows.xyz|). Every test therefore grows
// the volume by kVolumeRelativeEpsilon (1e-6, > 16 u) times (2 M + r), M the largest coordinate
// magnitude of its centre (AABB: of its corners; OBB: plus the sum of its half extents), and
// moves each plane outwards by kVolumeRelativeEpsilon |rows[k].w| + 1e-30 (the last term covers
// products that underflow). A volume is outside plane k only when the grown value is still
// negative, and inside it only when the shrunk value is still positive, so both answers hold
// for the exact (real-number) volume against the exact plane of the float matrix. At 1e5 units
// from the origin this is a margin of ~0.1-0.3 units (float spacing there is 0.008).
// The enclosing-volume builders (sphere_of_points, ...) are exact: they compute in double and
// round outwards, so each volume holds every input point in real arithmetic.
//
// Empty volumes (n = 0): radius < 0, AABB min > max, OBB half_extents[0] < 0; every frustum test
// reports them outside with no plane test. A NaN anywhere in a (non-empty) volume gives
// intersecting, never outside; so does an infinite AABB coordinate (or a finite sum of the six
// that overflows).
#pragma once

#include <cstddef>
#include <cstdint>

#include "patchcull/core/clip_space.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/math.h"
#include "patchcull/core/mesh.h"

namespace patchcull {

/// Relative growth of every volume in the frustum tests (see the file comment).
inline constexpr float kVolumeRelativeEpsilon = 1e-6f;

enum class Containment : std::uint8_t { outside = 0, intersecting = 1, inside = 2 };

/// "outside", "intersecting", "inside" (or "invalid" for other values).
const char* containment_name(Containment c);

/// A sphere; radius < 0 is the empty volume.
struct Sphere {
    Vec3 center;
    float radius = 0;
};

// The AABB is patchcull::Bounds (mesh.h: min, max); min > max on any axis is the empty volume.

/// An oriented box {center + sum_i t_i half_extents[i] axes[i] : |t_i| <= 1}; axes orthonormal
/// (within float rounding: the tests are exact for the set above with the axes as stored, as long
/// as |axes[i]| <= 1.001). half_extents[0] < 0 is the empty volume.
struct Obb {
    Vec3 center;
    Vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    float half_extents[3] = {0, 0, 0};
};

// ---- enclosing volumes ----------------------------------------------------------------------
// Each returns a volume holding every input point exactly (real arithmetic on the returned
// floats); n = 0 gives the empty volume. points must hold n finite points.

/// Ritter's sphere (two passes, in double), centre rounded to float, radius = the largest
/// distance from that centre, rounded up.
Sphere sphere_of_points(const Vec3* points, std::size_t n);
/// Exact min / max per axis.
Bounds aabb_of_points(const Vec3* points, std::size_t n);
/// PCA box: axes = eigenvectors of the points' covariance (Jacobi, in double), right-handed;
/// extents from the points' coordinates in those float axes (solved in double), rounded up.
/// Falls back to the axis-aligned box when that one has the smaller volume (PCA can be worse).
/// Collinear, coplanar and single points give extents of ~1e-12 of the size on the degenerate
/// axes (the double solve's rounding, covered).
Obb obb_of_points(const Vec3* points, std::size_t n);
/// The sphere around the box centre through its farthest corner (rounded up). Empty -> empty.
Sphere sphere_of_aabb(const Bounds& box);
/// The box as an OBB (identity axes, half extents rounded up). Empty -> empty.
Obb obb_of_aabb(const Bounds& box);
/// AABB of the box transformed by an affine matrix (bottom row 0 0 0 1; the refit of a rigid
/// object's object-space box, Arvo's method): computed in double, rounded outwards, so it holds
/// the exact image of every point of the box. Empty -> empty.
Bounds transformed_aabb(const Bounds& object_space, const Mat4& affine);

/// The box grown by margin (>= 0) on every side, computed in double and rounded outwards, so it
/// holds every point within margin (per axis) of the box exactly (a float `min - margin` rounds to
/// nearest and can land half an ulp inside). Empty -> empty.
Bounds grow_bounds(const Bounds& box, float margin);

// ---- frustum tests ----------------------------------------------------------------------------

/// Plane masking and plane coherence (Zachmann's lecture): state carried per volume (or BVH node).
struct PlaneCullState {
    std::uint8_t plane_mask = 0x3f;  ///< in: planes still to test (bit k = FrustumPlanes row k);
                                     ///< out: planes the volume straddles (children test only
                                     ///< these); unchanged when the result is outside
    std::int8_t last_plane = -1;     ///< plane that rejected the volume last time: tried first;
                                     ///< set to the rejecting plane on outside, else unchanged
};

/// Sphere test: outside when some plane has c . n + d < -r |n| (grown, see above); inside when
/// every tested plane has c . n + d > r |n|. Tests only the planes in state.plane_mask
/// (state.last_plane first when it is in the mask); plane_tests += planes evaluated. A volume
/// whose mask is 0 on entry is inside (every plane was decided by a parent that holds it).
Containment classify_sphere(const FrustumPlanes& planes, const Sphere& sphere, PlaneCullState& state,
                            std::uint32_t& plane_tests);
/// AABB test with the n- and p-vertex (the corner with the largest / smallest plane value, chosen
/// by the signs of the plane normal): outside when the p-vertex is outside a plane, inside when
/// every n-vertex is inside. Masking, coherence and plane_tests as classify_sphere.
Containment classify_aabb(const FrustumPlanes& planes, const Bounds& box, PlaneCullState& state,
                          std::uint32_t& plane_tests);
/// OBB test: centre value +- sum_i h_i |n . a_i| against each plane. Masking, coherence and
/// plane_tests as classify_sphere.
Containment classify_obb(const FrustumPlanes& planes, const Obb& box, PlaneCullState& state,
                         std::uint32_t& plane_tests);
/// The box test the lecture starts from: outside when all 8 corners are outside one plane, inside
/// when all 8 are inside every plane; all six planes, in order, stopping at the first rejecting
/// one; plane_tests += planes evaluated (8 corner values each). Returns exactly what classify_aabb
/// returns with a fresh state (the p-vertex value is the largest of the 8 corner values, also in
/// float: every operation is monotone), at 4x the point evaluations: the n/p-vertex is an
/// optimisation, not a tighter test. Its false "intersecting" answers (boxes near a frustum edge,
/// outside no single plane) are what meta_rejects (Bounds) removes in part.
Containment classify_aabb_corners(const FrustumPlanes& planes, const Bounds& box, std::uint32_t& plane_tests);

// ---- batch kernels ----------------------------------------------------------------------------
// No masking and no coherence: every plane, in order 0..5. out[i] is what the single-volume test
// returns for volumes[i] with a fresh PlaneCullState; scalar and SIMD (Highway, best target
// chosen at run time) give identical results (same operations in the same order). out must hold
// n values; n may be 0. Never allocate or throw.

void classify_spheres_scalar(const FrustumPlanes& planes, const Sphere* spheres, std::size_t n, Containment* out);
void classify_spheres_simd(const FrustumPlanes& planes, const Sphere* spheres, std::size_t n, Containment* out);
void classify_aabbs_scalar(const FrustumPlanes& planes, const Bounds* boxes, std::size_t n, Containment* out);
void classify_aabbs_simd(const FrustumPlanes& planes, const Bounds* boxes, std::size_t n, Containment* out);
void classify_obbs_scalar(const FrustumPlanes& planes, const Obb* boxes, std::size_t n, Containment* out);
void classify_obbs_simd(const FrustumPlanes& planes, const Obb* boxes, std::size_t n, Containment* out);

// ---- meta-BVs ------------------------------------------------------------------------------------

/// The frustum's bounding sphere and AABB (Zachmann's lecture "Meta-BVs"): a quick reject before the planes.
struct FrustumMetaBounds {
    Sphere sphere;
    Bounds box;
};

/// Bounds of the frustum of world_to_clip (depth convention as make_frustum_planes): its 8 corners
/// from the inverse matrix in double, grown by 1e-5 of their magnitude and rounded outwards. When
/// the matrix is singular or a corner lies at or behind infinity (an infinite far plane), the
/// bounds are unbounded (box +-inf, radius +inf) and never reject.
FrustumMetaBounds frustum_meta_bounds(const Mat4& world_to_clip, ClipDepth depth);
/// True when the sphere is disjoint from the frustum's sphere or box (so outside the frustum);
/// true for the empty sphere. Exact comparisons in double.
bool meta_rejects(const FrustumMetaBounds& meta, const Sphere& sphere);
/// True when the box is disjoint from the frustum's box or sphere; true for the empty box. The
/// box-box part is the separating-axis test on the three world axes, which the six plane tests
/// do not make: it rejects some boxes that every plane test calls intersecting.
bool meta_rejects(const FrustumMetaBounds& meta, const Bounds& box);

// ---- detail culling ----------------------------------------------------------------------------

/// Pixel scale n of a perspective projection: viewport_height / (2 tan(fovy / 2)).
float projection_pixel_scale(float fovy_radians, float viewport_height);
/// Projected radius in pixels, r * pixel_scale / d (d = |centre - eye|), the lecture's
/// approximation of the sphere's screen size; +inf when the eye is inside the sphere.
float projected_radius_pixels(const Sphere& sphere, Vec3 eye, float pixel_scale);
/// Detail culling (Zachmann's lecture, end): true when pi * projected_radius^2 < min_pixel_area. NOT
/// conservative (the object may still cover pixels; callers report what it changes). Never true
/// when the eye is inside the sphere or min_pixel_area <= 0; true for the empty sphere when
/// min_pixel_area > 0.
bool detail_culled(const Sphere& sphere, Vec3 eye, float pixel_scale, float min_pixel_area);

}  // namespace patchcull
