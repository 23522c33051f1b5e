// patchcull/core/ground_truth.h: what "conservative" is measured against on the CPU (the GPU side is
// the unculled render's patch-id buffer; README, "What contributes a pixel").
//
// The (displaced) surface is sampled densely: a grid x grid lattice over the patch domain, each
// sample S(u,v) = B(u,v) + D(s,t) * n(u,v) with n the unit normal (from the ACC tangent patches
// when given, else from the patch's own derivatives; a degenerate normal leaves the sample
// undisplaced). A sample inside the clip volume means the patch is visible to the frustum test:
// culling it is a false cull. Clip tests run in double precision, independently of the kernels.
//
// Memory: the samples are large (grid^2 * 12 bytes of surface points and grid^2 * 32
// bytes of tangent planes per patch: 12.7 KB at grid 17), so a judge of many patches keeps them
// for a small window of patches at a time (PatchTruthWindow below) and computes them again when
// the window comes back to a patch; the answers are those of the functions above, whatever the
// window's size.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "patchcull/core/displacement.h"
#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"

namespace patchcull {

inline constexpr int kGroundTruthGrid = 17;  ///< samples per side (17x17)

/// Writes grid*grid samples of the displaced patch to out (row v, column u). tangents and
/// displacement may be null; uv are the patch's corner texture coordinates (PatchInfo::uv).
void sample_displaced_patch(const BezierPatch& patch, const TangentPatches* tangents, const Vec2 uv[4],
                            const DisplacementMap* displacement, int grid, Vec3* out);

/// True when some point lies inside the clip volume of object_to_clip (-w<=x<=w, -w<=y<=w,
/// 0<=z<=w, w>0), evaluated in double precision.
bool any_point_in_clip_volume(const Mat4& object_to_clip, const Vec3* points, std::size_t count);

// ---- back-facing ground truth (Loop, Niessner & Eisenacher) -------------------------------

/// A homogeneous plane in double precision.
struct PlaneD {
    double x = 0, y = 0, z = 0, w = 0;
};

/// Parametric tangent planes T(u,v) = cross4(B, B_u, B_v) (object space; Loop, Niessner & Eisenacher eq. 1) of the
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

// ---- streamed ground truth ----------------------------------------------------------------

/// One patch's inputs to the dense samples: what sample_displaced_patch and sample_tangent_planes
/// take. tangents may be null; uv (4 corner texcoords, patch.h order) is read only when the
/// window displaces.
struct PatchTruthInput {
    const BezierPatch* patch = nullptr;
    const TangentPatches* tangents = nullptr;
    const Vec2* uv = nullptr;
};

/// The ground truth of up to `capacity` patches at a time (slots 0..capacity-1), each patch's
/// samples computed on the first question about it after clear() and kept until the next clear():
/// memory is capacity * grid^2 * (12 + 32) bytes (only the kinds asked for at construction),
/// allocated once, whatever the number of patches judged through the window. The answers equal
/// the eager functions' on the same inputs: in_clip_volume is
/// !sphere_outside_clip_volume(m, bounding_sphere(S)) && any_point_in_clip_volume(m, S) with S the
/// sample_displaced_patch samples, and faces_eye is any_plane_faces_eye on the
/// sample_tangent_planes planes (the shortcut is exact, so both are "some sample inside").
/// Not thread-safe: one window per thread. No allocation after construction.
class PatchTruthWindow {
public:
    /// clip: in_clip_volume may be asked; facing: faces_eye may be asked. displacement (may be
    /// null or empty) must outlive the window. Throws patchcull::Error for capacity 0 or a grid
    /// outside 1..1024.
    PatchTruthWindow(std::size_t capacity, int grid, const DisplacementMap* displacement, bool clip, bool facing);

    std::size_t capacity() const { return capacity_; }
    int grid() const { return grid_; }
    /// Forgets every slot's samples (capacity flags; nothing is freed). Call it before a slot
    /// holds another patch: a slot's samples are those of the input given when they were made.
    void clear();
    /// Whether a sample of the (displaced) patch in slot lies inside the clip volume of
    /// object_to_clip. Throws patchcull::Error for slot >= capacity or a window built without clip.
    bool in_clip_volume(std::size_t slot, const PatchTruthInput& input, const Mat4& object_to_clip);
    /// Whether a sampled tangent plane of the patch in slot faces eye (any_plane_faces_eye).
    /// Throws patchcull::Error for slot >= capacity or a window built without facing.
    bool faces_eye(std::size_t slot, const PatchTruthInput& input, Vec3 eye);
    /// Sample computations since construction, one per patch and kind (points with their sphere,
    /// or planes): how often the window sampled, for tests and measurements.
    std::uint64_t samplings() const { return samplings_; }

private:
    std::size_t capacity_;
    int grid_;
    std::size_t per_patch_;
    const DisplacementMap* displacement_;
    std::vector<Vec3> points_;           ///< clip: capacity * per_patch_
    std::vector<SampleSphere> spheres_;  ///< clip: capacity
    std::vector<PlaneD> planes_;         ///< facing: capacity * per_patch_
    std::vector<std::uint8_t> ready_;    ///< per slot: bit 0 points, bit 1 planes
    std::uint64_t samplings_ = 0;
};

}  // namespace patchcull
