// Control-mesh helpers (patchcull/mesh.h).
#include "patchcull/mesh.h"

#include <algorithm>

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
