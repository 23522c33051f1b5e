// Dense-sample ground truth for cull tests (patchcull/ground_truth.h; DESIGN.md "Ground truth").
#include "patchcull/ground_truth.h"

#include <algorithm>
#include <cmath>

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

SampleSphere bounding_sphere(const Vec3* points, std::size_t count) {
    SampleSphere s;
    if (count == 0) return s;
    double lo[3] = {points[0].x, points[0].y, points[0].z}, hi[3] = {lo[0], lo[1], lo[2]};
    for (std::size_t n = 1; n < count; ++n) {
        const double p[3] = {points[n].x, points[n].y, points[n].z};
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::min(lo[k], p[k]);
            hi[k] = std::max(hi[k], p[k]);
        }
    }
    const double c[3] = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])};
    double r2 = 0;
    for (std::size_t n = 0; n < count; ++n) {
        const double d[3] = {points[n].x - c[0], points[n].y - c[1], points[n].z - c[2]};
        r2 = std::max(r2, d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    }
    s.center = {float(c[0]), float(c[1]), float(c[2])};
    // Round the radius up past the float rounding of the centre.
    const double shift = std::abs(c[0] - s.center.x) + std::abs(c[1] - s.center.y) + std::abs(c[2] - s.center.z);
    s.radius = float((std::sqrt(r2) + shift) * (1 + 1e-6));
    return s;
}

bool sphere_outside_clip_volume(const Mat4& m, const SampleSphere& sphere) {
    double r[4][4];
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 4; ++k) r[i][k] = m.at(i, k);
    // Clip planes as rows over object-space points: w+x, w-x, w+y, w-y, z, w-z (all >= 0 inside).
    const double planes[6][4] = {
        {r[3][0] + r[0][0], r[3][1] + r[0][1], r[3][2] + r[0][2], r[3][3] + r[0][3]},
        {r[3][0] - r[0][0], r[3][1] - r[0][1], r[3][2] - r[0][2], r[3][3] - r[0][3]},
        {r[3][0] + r[1][0], r[3][1] + r[1][1], r[3][2] + r[1][2], r[3][3] + r[1][3]},
        {r[3][0] - r[1][0], r[3][1] - r[1][1], r[3][2] - r[1][2], r[3][3] - r[1][3]},
        {r[2][0], r[2][1], r[2][2], r[2][3]},
        {r[3][0] - r[2][0], r[3][1] - r[2][1], r[3][2] - r[2][2], r[3][3] - r[2][3]},
    };
    const double c[3] = {sphere.center.x, sphere.center.y, sphere.center.z};
    for (const auto& p : planes) {
        const double len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        const double value = p[0] * c[0] + p[1] * c[1] + p[2] * c[2] + p[3];
        // Outside when even the sphere's nearest point has a negative plane value.
        if (value + len * sphere.radius < -1e-9 * (std::abs(p[3]) + len * (std::abs(c[0]) + std::abs(c[1]) + std::abs(c[2]))))
            return true;
    }
    return false;
}

}  // namespace patchcull
