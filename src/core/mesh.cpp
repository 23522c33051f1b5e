// Control-mesh helpers (patchcull/mesh.h).
#include "patchcull/mesh.h"

#include <algorithm>

namespace patchcull {

bool ControlMesh::all_quads() const {
    for (std::size_t f = 0; f < face_count(); ++f)
        if (face_size(f) != 4) return false;
    return true;  // vacuously true for a mesh without faces
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
