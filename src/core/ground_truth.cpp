// Dense-sample ground truth for cull tests (patchcull/core/ground_truth.h).
#include "patchcull/core/ground_truth.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "patchcull/core/error.h"

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

namespace {

struct V4 {
    double x, y, z, w;
};

double det3(double a0, double a1, double a2, double b0, double b1, double b2, double c0, double c1, double c2) {
    return a0 * (b1 * c2 - b2 * c1) - a1 * (b0 * c2 - b2 * c0) + a2 * (b0 * c1 - b1 * c0);
}

// cross4 of Loop, Niessner & Eisenacher, Appendix A: the plane through homogeneous points a, b, c (rows are the
// components, columns the points).
PlaneD cross4(const V4& a, const V4& b, const V4& c) {
    return {det3(a.y, b.y, c.y, a.z, b.z, c.z, a.w, b.w, c.w), -det3(a.x, b.x, c.x, a.z, b.z, c.z, a.w, b.w, c.w),
            det3(a.x, b.x, c.x, a.y, b.y, c.y, a.w, b.w, c.w), -det3(a.x, b.x, c.x, a.y, b.y, c.y, a.z, b.z, c.z)};
}

void bernstein3d(double t, double b[4], double d[4]) {
    const double s = 1 - t;
    b[0] = s * s * s;
    b[1] = 3 * t * s * s;
    b[2] = 3 * t * t * s;
    b[3] = t * t * t;
    d[0] = -3 * s * s;
    d[1] = 3 * s * s - 6 * t * s;
    d[2] = 6 * t * s - 3 * t * t;
    d[3] = 3 * t * t;
}

double facing_tolerance(double nx, double ny, double nz, double nw, Vec3 eye) {
    const double n = std::sqrt(nx * nx + ny * ny + nz * nz);
    const double e = std::sqrt(double(eye.x) * eye.x + double(eye.y) * eye.y + double(eye.z) * eye.z);
    return 1e-5 * (n * e + std::abs(nw));
}

}  // namespace

void sample_tangent_planes(const BezierPatch& patch, int grid, PlaneD* out) {
    for (int j = 0; j < grid; ++j)
        for (int i = 0; i < grid; ++i) {
            const double u = grid > 1 ? double(i) / (grid - 1) : 0.5, v = grid > 1 ? double(j) / (grid - 1) : 0.5;
            double bu[4], du[4], bv[4], dv[4];
            bernstein3d(u, bu, du);
            bernstein3d(v, bv, dv);
            V4 p{0, 0, 0, 0}, pu{0, 0, 0, 0}, pv{0, 0, 0, 0};
            for (int b = 0; b < 4; ++b)
                for (int a = 0; a < 4; ++a) {
                    const Vec4 c = patch.cp[4 * b + a];
                    const double w0 = bu[a] * bv[b], w1 = du[a] * bv[b], w2 = bu[a] * dv[b];
                    p = {p.x + w0 * c.x, p.y + w0 * c.y, p.z + w0 * c.z, p.w + w0 * c.w};
                    pu = {pu.x + w1 * c.x, pu.y + w1 * c.y, pu.z + w1 * c.z, pu.w + w1 * c.w};
                    pv = {pv.x + w2 * c.x, pv.y + w2 * c.y, pv.z + w2 * c.z, pv.w + w2 * c.w};
                }
            out[j * grid + i] = cross4(p, pu, pv);
        }
}

bool any_plane_faces_eye(const PlaneD* planes, std::size_t count, Vec3 eye) {
    for (std::size_t k = 0; k < count; ++k) {
        const PlaneD& t = planes[k];
        const double value = t.x * eye.x + t.y * eye.y + t.z * eye.z + t.w;
        if (value > 0 && value > facing_tolerance(t.x, t.y, t.z, t.w, eye)) return true;
    }
    return false;
}

void sample_patch_points(const BezierPatch& patch, int grid, PointD* out) {
    for (int j = 0; j < grid; ++j)
        for (int i = 0; i < grid; ++i) {
            const double u = grid > 1 ? double(i) / (grid - 1) : 0.5, v = grid > 1 ? double(j) / (grid - 1) : 0.5;
            double bu[4], du[4], bv[4], dv[4];
            bernstein3d(u, bu, du);
            bernstein3d(v, bv, dv);
            V4 p{0, 0, 0, 0};
            for (int b = 0; b < 4; ++b)
                for (int a = 0; a < 4; ++a) {
                    const Vec4 c = patch.cp[4 * b + a];
                    const double w = bu[a] * bv[b];
                    p = {p.x + w * c.x, p.y + w * c.y, p.z + w * c.z, p.w + w * c.w};
                }
            out[j * grid + i] = {p.x / p.w, p.y / p.w, p.z / p.w};
        }
}

bool any_tessellation_triangle_faces_eye(const PointD* pts, int grid, Vec3 eye) {
    auto faces = [&](const PointD& a, const PointD& b, const PointD& c) {
        const double e1[3] = {b.x - a.x, b.y - a.y, b.z - a.z};
        const double e2[3] = {c.x - a.x, c.y - a.y, c.z - a.z};
        const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                             e1[0] * e2[1] - e1[1] * e2[0]};
        const double nn = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        const double l1 = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
        const double l2 = std::sqrt(e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]);
        if (nn <= 1e-12 * l1 * l2) return false;  // no area: a collapsed edge
        const double value = n[0] * (eye.x - a.x) + n[1] * (eye.y - a.y) + n[2] * (eye.z - a.z);
        const double nw = n[0] * a.x + n[1] * a.y + n[2] * a.z;
        return value > 0 && value > facing_tolerance(n[0], n[1], n[2], nw, eye);
    };
    for (int j = 0; j + 1 < grid; ++j)
        for (int i = 0; i + 1 < grid; ++i) {
            const PointD& p00 = pts[j * grid + i];
            const PointD& p10 = pts[j * grid + i + 1];
            const PointD& p01 = pts[(j + 1) * grid + i];
            const PointD& p11 = pts[(j + 1) * grid + i + 1];
            // Counter-clockwise in (u,v), so a front face has its normal along du x dv.
            if (faces(p00, p10, p11) || faces(p00, p11, p01) || faces(p00, p10, p01) || faces(p10, p11, p01))
                return true;
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
        if (value + len * sphere.radius <
            -1e-9 * (std::abs(p[3]) + len * (std::abs(c[0]) + std::abs(c[1]) + std::abs(c[2]))))
            return true;
    }
    return false;
}

// ---- PatchTruthWindow ------------------------------------------------------------------------

namespace {
constexpr std::uint8_t kPointsReady = 1, kPlanesReady = 2;
}  // namespace

PatchTruthWindow::PatchTruthWindow(std::size_t capacity, int grid, const DisplacementMap* displacement, bool clip,
                                   bool facing)
    : capacity_(capacity), grid_(grid), per_patch_(0), displacement_(displacement) {
    if (capacity == 0) throw Error("ground truth window: capacity 0 (at least one patch)");
    if (grid < 1 || grid > 1024) throw Error("ground truth grid " + std::to_string(grid) + " is not in 1..1024");
    per_patch_ = static_cast<std::size_t>(grid) * static_cast<std::size_t>(grid);
    if (clip) {
        points_.resize(capacity * per_patch_);
        spheres_.resize(capacity);
    }
    if (facing) planes_.resize(capacity * per_patch_);
    ready_.assign(capacity, 0);
}

void PatchTruthWindow::clear() { std::fill(ready_.begin(), ready_.end(), std::uint8_t{0}); }

bool PatchTruthWindow::in_clip_volume(std::size_t slot, const PatchTruthInput& input, const Mat4& object_to_clip) {
    if (slot >= capacity_ || spheres_.empty())
        throw Error("ground truth window: in_clip_volume on slot " + std::to_string(slot) + " of a window of " +
                    std::to_string(capacity_) + (spheres_.empty() ? " built without clip samples" : ""));
    Vec3* points = &points_[slot * per_patch_];
    if (!(ready_[slot] & kPointsReady)) {
        sample_displaced_patch(*input.patch, input.tangents, input.uv, displacement_, grid_, points);
        spheres_[slot] = bounding_sphere(points, per_patch_);
        ready_[slot] |= kPointsReady;
        ++samplings_;
    }
    // The sphere test is exact (every sample is inside the sphere), and cheap: most culled
    // patches are far outside a plane.
    return !sphere_outside_clip_volume(object_to_clip, spheres_[slot]) &&
           any_point_in_clip_volume(object_to_clip, points, per_patch_);
}

bool PatchTruthWindow::faces_eye(std::size_t slot, const PatchTruthInput& input, Vec3 eye) {
    if (slot >= capacity_ || planes_.empty())
        throw Error("ground truth window: faces_eye on slot " + std::to_string(slot) + " of a window of " +
                    std::to_string(capacity_) + (planes_.empty() ? " built without tangent planes" : ""));
    PlaneD* planes = &planes_[slot * per_patch_];
    if (!(ready_[slot] & kPlanesReady)) {
        sample_tangent_planes(*input.patch, grid_, planes);
        ready_[slot] |= kPlanesReady;
        ++samplings_;
    }
    return any_plane_faces_eye(planes, per_patch_, eye);
}

}  // namespace patchcull
