// Control-mesh helpers (patchcull/mesh.h).
#include "patchcull/mesh.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace patchcull {

bool ControlMesh::all_quads() const {
    for (std::size_t f = 0; f < face_count(); ++f)
        if (face_size(f) != 4) return false;
    return true;  // vacuously true for a mesh without faces
}

bool ControlMesh::is_closed() const {
    if (face_count() == 0) return false;
    // Directed edges (from, to): closed and consistently oriented iff each occurs exactly once
    // and its reverse occurs too.
    std::vector<std::uint64_t> directed;
    directed.reserve(face_vertices.size());
    for (std::size_t f = 0; f < face_count(); ++f) {
        const std::uint32_t first = face_offsets[f], n = face_size(f);
        for (std::uint32_t i = 0; i < n; ++i) {
            const std::uint64_t from = face_vertices[first + i], to = face_vertices[first + (i + 1) % n];
            directed.push_back(from << 32 | to);
        }
    }
    std::sort(directed.begin(), directed.end());
    if (std::adjacent_find(directed.begin(), directed.end()) != directed.end()) return false;
    for (const std::uint64_t e : directed) {
        const std::uint64_t reverse = (e & 0xFFFFFFFFu) << 32 | e >> 32;
        if (!std::binary_search(directed.begin(), directed.end(), reverse)) return false;
    }
    return true;
}

double ControlMesh::signed_volume() const {
    if (positions.empty()) return 0;
    // Sum over fan triangles (a, b, c) of det[a-o, b-o, c-o] / 6, o = positions[0]: translation
    // invariant for a closed mesh, and relative coordinates keep far-away meshes exact enough.
    const Vec3 o = positions[0];
    auto rel = [&](std::uint32_t v) {
        const Vec3 p = positions[v];
        return std::array<double, 3>{double(p.x) - o.x, double(p.y) - o.y, double(p.z) - o.z};
    };
    double six_volume = 0;
    for (std::size_t f = 0; f < face_count(); ++f) {
        const std::uint32_t first = face_offsets[f], n = face_size(f);
        const auto a = rel(face_vertices[first]);
        for (std::uint32_t i = 1; i + 1 < n; ++i) {
            const auto b = rel(face_vertices[first + i]), c = rel(face_vertices[first + i + 1]);
            six_volume += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                          a[2] * (b[0] * c[1] - b[1] * c[0]);
        }
    }
    return six_volume / 6.0;
}

void ControlMesh::reverse_faces() {
    for (std::size_t f = 0; f < face_count(); ++f) {
        const auto begin = static_cast<std::ptrdiff_t>(face_offsets[f]), end = static_cast<std::ptrdiff_t>(face_offsets[f + 1]);
        std::reverse(face_vertices.begin() + begin, face_vertices.begin() + end);
        if (has_texcoords()) std::reverse(face_texcoords.begin() + begin, face_texcoords.begin() + end);
    }
}

namespace {

// Total area of the faces' triangle fans, in double.
double surface_area(const ControlMesh& mesh) {
    double area = 0;
    for (std::size_t f = 0; f < mesh.face_count(); ++f) {
        const std::uint32_t first = mesh.face_offsets[f], n = mesh.face_size(f);
        const Vec3 a = mesh.positions[mesh.face_vertices[first]];
        for (std::uint32_t i = 1; i + 1 < n; ++i) {
            const Vec3 b = mesh.positions[mesh.face_vertices[first + i]];
            const Vec3 c = mesh.positions[mesh.face_vertices[first + i + 1]];
            const double ux = double(b.x) - a.x, uy = double(b.y) - a.y, uz = double(b.z) - a.z;
            const double vx = double(c.x) - a.x, vy = double(c.y) - a.y, vz = double(c.z) - a.z;
            const double cx = uy * vz - uz * vy, cy = uz * vx - ux * vz, cz = ux * vy - uy * vx;
            area += 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
        }
    }
    return area;
}

}  // namespace

SurfaceOrientation classify_orientation(const ControlMesh& mesh) {
    if (!mesh.is_closed()) return SurfaceOrientation::open;
    // Flat against the mesh's own surface (|V| <= 1e-9 A^1.5; a sphere has V = 0.094 A^1.5), not
    // against its bounding box, so that a thin but real solid (a squashed character, a plate of
    // 1e-5 relative thickness) keeps its orientation while a zero-volume sheet (two coincident
    // layers, a flattened mesh, whose volume is rounding noise ~1e-16 A^1.5) does not.
    const double area = surface_area(mesh);
    const double volume = mesh.signed_volume();
    if (!(std::abs(volume) > 1e-9 * area * std::sqrt(area))) return SurfaceOrientation::flat;
    return volume > 0 ? SurfaceOrientation::outward : SurfaceOrientation::inward;
}

SurfaceOrientation orient_outward(ControlMesh& mesh) {
    SurfaceOrientation o = classify_orientation(mesh);
    if (o == SurfaceOrientation::inward) {
        mesh.reverse_faces();
        mesh.warnings.push_back(mesh.name + ": closed surface oriented inward (negative signed volume): "
                                "faces reversed, so that its outside faces out");
        o = SurfaceOrientation::outward;
    } else if (o == SurfaceOrientation::flat) {
        mesh.warnings.push_back(mesh.name + ": closed surface encloses no volume: drawn two-sided, "
                                "no back-patch culling");
    }
    return o;
}

Bounds compute_bounds(const std::vector<Vec3>& points) {
    // An empty point set has the empty-at-origin box {0, 0}: callers get a finite box (radius 0)
    // instead of +-infinity.
    if (points.empty()) return Bounds{};
    Bounds b{points[0], points[0]};
    for (const Vec3& p : points) {
        b.min = {std::min(b.min.x, p.x), std::min(b.min.y, p.y), std::min(b.min.z, p.z)};
        b.max = {std::max(b.max.x, p.x), std::max(b.max.y, p.y), std::max(b.max.z, p.z)};
    }
    return b;
}

}  // namespace patchcull
