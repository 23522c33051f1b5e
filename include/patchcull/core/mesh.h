// patchcull/core/mesh.h: polygonal control meshes (positions, optional texture coordinates).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "patchcull/core/math.h"

namespace patchcull {

/// A point or offset in double precision, for world positions far from the origin: engines
/// place objects at 1e4 - 1e7 units, where a float's spacing is 1e-3 - 1 unit. Patches and
/// kernels stay in float, in a local frame around such a point (ControlMesh::origin, the "local
/// test coordinates" of Zachmann's lecture "Advanced Visibility Computations"); only the
/// translation between the frames is carried in double, so float data never holds a large
/// coordinate and the kernels' rounding stays relative to the object's own size.
struct DVec3 {
    double x = 0, y = 0, z = 0;
};
inline DVec3 operator+(DVec3 a, DVec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline DVec3 operator-(DVec3 a, DVec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline DVec3 to_double(Vec3 a) { return {a.x, a.y, a.z}; }
/// Rounds each component to the nearest float: for offsets that are small (local coordinates).
inline Vec3 to_float(DVec3 a) { return {static_cast<float>(a.x), static_cast<float>(a.y), static_cast<float>(a.z)}; }

/// A semi-sharp or sharp crease on the edge (v0, v1), or a corner on vertex v0 (v1 unused).
/// Sharpness follows OpenSubdiv: 0 smooth, >= 10 infinitely sharp.
struct Crease {
    std::uint32_t v0 = 0, v1 = 0;
    float sharpness = 0;
    std::uint32_t line = 0;  ///< line of its tag in the source file (0: not from a file)
};

/// How boundaries are interpolated: OpenSubdiv's Sdc::Options::VtxBoundaryInterpolation. The
/// OBJ tag "t interpolateboundary 1/0/0 n" means what OpenSubdiv's shape reader makes of it:
/// 0 none, 1 edge_and_corner, 2 edge_only (RenderMan's numbering, not the enum's).
enum class BoundaryInterpolation : std::uint8_t {
    edge_and_corner,  ///< boundary edges sharp, corners (boundary vertices with one face) sharp
    edge_only,        ///< boundary edges sharp, corners smooth
    none,             ///< no surface over faces at a boundary vertex (unless creases sharpen all
                      ///< of its boundary edges): OpenSubdiv makes those faces holes
};

/// Subdivision options a mesh may carry (OpenSubdiv's shape tags; obj.h). The defaults are
/// patchcull's for every mesh: EDGE_AND_CORNER boundaries, uniform creases, Catmull-Clark
/// weights at triangles.
struct SubdivisionOptions {
    BoundaryInterpolation boundary = BoundaryInterpolation::edge_and_corner;
    bool chaikin_creases = false;     ///< Sdc CREASE_CHAIKIN ("t creasemethod 0/0/1 chaikin")
    bool smooth_triangles = false;    ///< Sdc TRI_SUB_SMOOTH ("t smoothtriangles 0/0/1 smooth")
    std::uint32_t boundary_line = 0;  ///< line of the interpolateboundary tag (0: none, or not from a file)
};

/// A polygon mesh in face-vertex form. Face f has corners [face_offsets[f], face_offsets[f+1]);
/// corner c uses position face_vertices[c] and, when the mesh has texture coordinates,
/// texcoord face_texcoords[c] (face_texcoords is then the same size as face_vertices, else empty).
/// Faces are counter-clockwise seen from outside (OBJ convention).
///
/// Positions are relative to `origin`: the file's point X is origin + positions[i] (exactly up
/// to one float rounding of the difference, done in double). Everything built from a mesh
/// (patches, bounds, views, ground truth, GPU buffers) lives in this local frame; a camera or
/// object_to_clip given in the file's (world) frame must be moved into it in double
/// (WorldCamera::local, camera.h). origin is 0 for meshes near the origin (OBJ files whose
/// bounding-box centre is within the box's diagonal of 0, so their float positions are as
/// precise as centred ones and unchanged), else the bounding-box centre (parse_obj).
struct ControlMesh {
    std::string name;  ///< source file or built-in name, used in messages
    DVec3 origin;      ///< world position of the local frame's 0 (see above)
    std::vector<Vec3> positions;
    std::vector<Vec2> texcoords;
    std::vector<std::uint32_t> face_offsets{0};
    std::vector<std::uint32_t> face_vertices;
    std::vector<std::uint32_t> face_texcoords;
    std::vector<Crease> creases;  ///< edge creases (OBJ "t crease 2/1/0 v0 v1 s", 0-based here)
    std::vector<Crease> corners;  ///< vertex corners (OBJ "t corner 1/1/0 v s")
    /// Faces with no surface of their own (OBJ "t hole n/0/0 f..", 0-based), sorted, no repeats.
    /// A hole still shapes its neighbours (its vertices stay in their one-rings), as in
    /// OpenSubdiv; it only produces no patches. The surface is then open whatever is_closed()
    /// says of the faces: load_model draws it two-sided (LoadedModel::closed false).
    std::vector<std::uint32_t> holes;
    SubdivisionOptions options;
    /// Source lines of the faces, for messages: runs of faces on consecutive lines, run k from
    /// face face_line_runs[k].first at line face_line_runs[k].second. Empty when the mesh does
    /// not come from a file.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> face_line_runs;
    std::vector<std::string> warnings;  ///< non-fatal loader notes, for the caller to show

    std::size_t face_count() const { return face_offsets.size() - 1; }
    std::uint32_t face_size(std::size_t f) const { return face_offsets[f + 1] - face_offsets[f]; }
    bool has_texcoords() const { return !face_texcoords.empty(); }
    /// Line of face f in the source file, or 0 when unknown (face_line_runs).
    std::uint32_t face_line(std::size_t f) const {
        std::uint32_t line = 0;
        for (std::size_t lo = 0, hi = face_line_runs.size(); lo < hi;) {  // last run starting at or before f
            const std::size_t mid = (lo + hi) / 2;
            if (face_line_runs[mid].first <= f) {
                line = face_line_runs[mid].second + static_cast<std::uint32_t>(f - face_line_runs[mid].first);
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        return line;
    }
    bool all_quads() const;
    /// True when every edge is shared by exactly two faces, used once in each direction (a closed,
    /// consistently oriented surface, and at least one face). Only on such a surface are
    /// back-facing patches always hidden by front-facing ones when both sides are drawn: through
    /// the boundary of an open one (the teapot's lid gap) the inside of a patch facing away can
    /// show, so back-patch culling (Loop, Niessner & Eisenacher) is not conservative there.
    bool is_closed() const;
    /// Signed volume enclosed by the faces (divergence theorem over each face's triangle fan,
    /// summed in double relative to the first position, so it does not depend on where the mesh
    /// sits). Positive when the faces are oriented outward (counter-clockwise seen from outside),
    /// negative for an inside-out mesh (every winding reversed, or mirrored). Meaningful for a
    /// closed mesh (is_closed); for self-intersecting ones it is the winding-weighted volume, so
    /// its sign is that of the larger part. For a mesh of several shells it is their sum (an
    /// outward hollow solid: the outer shell's volume less its cavities'); orientation is decided
    /// shell by shell (classify_orientation), not from this sum.
    double signed_volume() const;
    /// Reverses every face's corner order (and its texcoords): flips the surface's orientation.
    void reverse_faces();
};

/// How a control mesh's surface may be drawn and back-patch culled (README: "What contributes
/// a pixel"). Orientation comes from geometry, not from topology alone, and shell by shell: a
/// shell is a connected component of the faces over shared edges. The solid is the region
/// inside an odd number of shells (nesting parity, decided in double by rays from up to 64 of
/// each shell's vertices, or the winding number where a ray grazes an edge), and a mesh is oriented outward when every
/// shell's faces are counter-clockwise seen from outside the solid: a shell inside an even number
/// of others (0: an outer surface, 2: an island in a cavity) has positive signed volume, one
/// inside an odd number (the wall of a cavity) negative, facing into the cavity. Shells that
/// touch or intersect count as not nested (each oriented on its own, as their union), and a
/// self-intersecting shell keeps the orientation of its larger part.
enum class SurfaceOrientation {
    open,       ///< not closed (is_closed false): drawn two-sided, no back-patch culling
    flat,       ///< closed, but a shell encloses no volume (|V| <= 1e-9 A^1.5, V and A the
                ///< shell's signed volume and area): its orientation is noise, drawn two-sided
    outward,    ///< closed, every shell oriented as above: one-sided, back-patch culling conservative
    inward,     ///< closed, some shell inside out for its nesting (orient_outward reverses those)
    undecided,  ///< closed, but so many shells' bounds nest that deciding their nesting would take
                ///< more than ~2e8 ray-triangle tests (about a second): drawn two-sided, no
                ///< back-patch culling
};
SurfaceOrientation classify_orientation(const ControlMesh& mesh);

/// Makes a closed mesh outward by reversing the faces of each shell that is inside out for its
/// nesting (an inward single-shell mesh: all its faces), and returns its orientation after that:
/// outward, open, flat or undecided (never inward). Appends a one-line note to mesh.warnings
/// when it reversed faces or found the mesh flat or undecided.
SurfaceOrientation orient_outward(ControlMesh& mesh);

/// Axis-aligned bounds of a point set.
struct Bounds {
    Vec3 min{}, max{};
    Vec3 center() const { return (min + max) * 0.5f; }
    /// Radius of the sphere around center() that holds the box.
    float radius() const { return 0.5f * length(max - min); }
};
Bounds compute_bounds(const std::vector<Vec3>& points);

}  // namespace patchcull
