// patchcull/mesh.h: polygonal control meshes (positions, optional texture coordinates).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "patchcull/math.h"

namespace patchcull {

/// A semi-sharp or sharp crease on the edge (v0, v1), or a corner on vertex v0 (v1 unused).
/// Sharpness follows OpenSubdiv: 0 smooth, >= 10 infinitely sharp.
struct Crease {
    std::uint32_t v0 = 0, v1 = 0;
    float sharpness = 0;
};

/// A polygon mesh in face-vertex form. Face f has corners [face_offsets[f], face_offsets[f+1]);
/// corner c uses position face_vertices[c] and, when the mesh has texture coordinates,
/// texcoord face_texcoords[c] (face_texcoords is then the same size as face_vertices, else empty).
/// Faces are counter-clockwise seen from outside (OBJ convention).
struct ControlMesh {
    std::string name;  ///< source file or built-in name, used in messages
    std::vector<Vec3> positions;
    std::vector<Vec2> texcoords;
    std::vector<std::uint32_t> face_offsets{0};
    std::vector<std::uint32_t> face_vertices;
    std::vector<std::uint32_t> face_texcoords;
    std::vector<Crease> creases;  ///< edge creases (OBJ "t crease 2/1/0 v0 v1 s", 0-based here)
    std::vector<Crease> corners;  ///< vertex corners (OBJ "t corner 1/1/0 v s")
    std::vector<std::string> warnings;  ///< non-fatal loader notes, for the caller to show

    std::size_t face_count() const { return face_offsets.size() - 1; }
    std::uint32_t face_size(std::size_t f) const { return face_offsets[f + 1] - face_offsets[f]; }
    bool has_texcoords() const { return !face_texcoords.empty(); }
    bool all_quads() const;
    /// True when every edge is shared by exactly two faces, used once in each direction (a closed,
    /// consistently oriented surface, and at least one face). Only on such a surface are
    /// back-facing patches always hidden by front-facing ones when both sides are drawn: through
    /// the boundary of an open one (the teapot's lid gap) the inside of a patch facing away can
    /// show, so back-patch culling (seed 001) is not conservative there.
    bool is_closed() const;
};

/// Axis-aligned bounds of a point set.
struct Bounds {
    Vec3 min{}, max{};
    Vec3 center() const { return (min + max) * 0.5f; }
    /// Radius of the sphere around center() that holds the box.
    float radius() const { return 0.5f * length(max - min); }
};
Bounds compute_bounds(const std::vector<Vec3>& points);

}  // namespace patchcull
