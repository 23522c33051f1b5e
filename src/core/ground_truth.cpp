// Dense-sample ground truth for cull tests (patchcull/ground_truth.h; DESIGN.md "Ground truth").
#include "patchcull/ground_truth.h"

namespace patchcull {

void sample_displaced_patch(const BezierPatch& patch, const TangentPatches* tangents, const Vec2 uv[4],
                            const DisplacementMap* displacement, int grid, Vec3* out) {
    const bool displaced = displacement && !displacement->empty();
    for (int j = 0; j < grid; ++j)
        for (int i = 0; i < grid; ++i) {
            const float u = grid > 1 ? float(i) / float(grid - 1) : 0.5f;
            const float v = grid > 1 ? float(j) / float(grid - 1) : 0.5f;
            Vec3 p;
            if (displaced) {
                const SurfacePoint s = evaluate_surface(patch, u, v);
                const Vec3 n = normalize(tangents ? evaluate_tangent_normal(*tangents, u, v) : s.normal);
                p = s.position + n * displacement->sample(patch_texcoord(uv, u, v));
            } else {
                p = evaluate_position(patch, u, v);
            }
            out[j * grid + i] = p;
        }
}

bool any_point_in_clip_volume(const Mat4& m, const Vec3* points, std::size_t count) {
    double r[4][4];
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 4; ++k) r[i][k] = m.at(i, k);
    for (std::size_t n = 0; n < count; ++n) {
        const double p[4] = {points[n].x, points[n].y, points[n].z, 1.0};
        double c[4];
        for (int i = 0; i < 4; ++i) c[i] = r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2] + r[i][3] * p[3];
        const double w = c[3];
        if (w > 0 && c[0] >= -w && c[0] <= w && c[1] >= -w && c[1] <= w && c[2] >= 0 && c[2] <= w) return true;
    }
    return false;
}

}  // namespace patchcull
