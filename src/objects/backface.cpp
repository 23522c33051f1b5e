// Back-face culling of triangles (patchcull/objects/backface.h): the per-triangle test (scalar reference;
// the SIMD version in backface_simd.cpp does the same operations in the same order) and normal
// masks (Zhang & Hoff 1997, as G. Zachmann's lecture "Advanced Visibility Computations"
// describes them).
//
// Per-triangle test, operation order (shared with backface_simd.cpp; every product feeds an
// explicit fma or is a lone multiply used only as an fma operand, so GCC's default
// -ffp-contract=fast cannot fuse anything differently in the two versions, see backpatch_ptp.cpp):
//   e1 = p1 - p0, e2 = p2 - p0, w = eye - p0                           (9 subtractions)
//   n.x = fma(e1.y, e2.z, -(e1.z * e2.y)), n.y, n.z cyclically
//   s = n.x * w.x;  s = fma(n.y, w.y, s);  s = fma(n.z, w.z, s)
//   P = the same with absolute values and + instead of - (the permanent)
//   margin = fma(kTriangleTestErrorBound, P, 32 * denorm_min)
//   culled = two equal vertices || (s <= -margin && margin <= FLT_MAX)
// Error bound (u = 2^-24, P over the rounded differences): the rounded differences change the
// exact determinant by <= ~3u P, the cross product's fma(a, b, -(c d)) errs by <= u(|ab| + 2|cd|)
// per component (<= 2u P through w), the dot product's fma chain by <= 2u P (1 + 2u), so
// |s - n_exact . (eye - p0)| <= ~7u P + O(u^2); P itself is a sum of positive terms computed
// with <= 3u relative error. 10u P (kTriangleTestErrorBound) therefore exceeds the error, and the
// denorm_min term covers underflow (each operation errs by at most half a denorm_min absolutely
// there).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "patchcull/core/error.h"
#include "patchcull/objects/backface.h"

#include "core/scalar_clones.h"

namespace patchcull {

namespace {

constexpr float kTinyMargin = 32 * std::numeric_limits<float>::denorm_min();

inline bool same_point(Vec3 a, Vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

inline __attribute__((always_inline)) bool triangle_backfacing(Vec3 p0, Vec3 p1, Vec3 p2, Vec3 eye) {
    const float e1x = p1.x - p0.x, e1y = p1.y - p0.y, e1z = p1.z - p0.z;
    const float e2x = p2.x - p0.x, e2y = p2.y - p0.y, e2z = p2.z - p0.z;
    const float wx = eye.x - p0.x, wy = eye.y - p0.y, wz = eye.z - p0.z;
    const float qx = e1z * e2y, qy = e1x * e2z, qz = e1y * e2x;
    const float nx = std::fma(e1y, e2z, -qx);
    const float ny = std::fma(e1z, e2x, -qy);
    const float nz = std::fma(e1x, e2y, -qz);
    float s = nx * wx;
    s = std::fma(ny, wy, s);
    s = std::fma(nz, wz, s);
    const float a1x = std::fabs(e1x), a1y = std::fabs(e1y), a1z = std::fabs(e1z);
    const float a2x = std::fabs(e2x), a2y = std::fabs(e2y), a2z = std::fabs(e2z);
    const float rx = a1z * a2y, ry = a1x * a2z, rz = a1y * a2x;
    const float px = std::fma(a1y, a2z, rx);
    const float py = std::fma(a1z, a2x, ry);
    const float pz = std::fma(a1x, a2y, rz);
    float perm = px * std::fabs(wx);
    perm = std::fma(py, std::fabs(wy), perm);
    perm = std::fma(pz, std::fabs(wz), perm);
    const float margin = std::fma(kTriangleTestErrorBound, perm, kTinyMargin);
    const bool degenerate = same_point(p0, p1) || same_point(p0, p2) || same_point(p1, p2);
    return degenerate || (s <= -margin && margin <= std::numeric_limits<float>::max());
}

double det3(double a0, double a1, double a2, double b0, double b1, double b2, double c0, double c1, double c2) {
    return a0 * (b1 * c2 - b2 * c1) - a1 * (b0 * c2 - b2 * c0) + a2 * (b0 * c1 - b1 * c0);
}

}  // namespace

PATCHCULL_SCALAR_CLONES
void cull_backfacing_triangles_scalar(const Vec3* vertices, const std::uint32_t* indices, std::size_t triangle_count,
                                      Vec3 eye, std::uint8_t* culled) {
    for (std::size_t t = 0; t < triangle_count; ++t) {
        const Vec3 p0 = vertices[indices[3 * t]], p1 = vertices[indices[3 * t + 1]], p2 = vertices[indices[3 * t + 2]];
        culled[t] = triangle_backfacing(p0, p1, p2, eye) ? 1 : 0;
    }
}

// ---- normal masks ------------------------------------------------------------------------

NormalMaskGrid::NormalMaskGrid(int divisions) : n_(divisions) {
    if (divisions < 1 || divisions > kMaxDivisions)
        throw Error("normal mask grid: divisions must be in 1.." + std::to_string(kMaxDivisions) + ", got " +
                    std::to_string(divisions));
}

std::uint16_t NormalMaskGrid::classify(Vec3 normal) const {
    const double c[3] = {normal.x, normal.y, normal.z};
    if (!std::isfinite(c[0]) || !std::isfinite(c[1]) || !std::isfinite(c[2])) return unclassified();
    const double a0 = std::fabs(c[0]), a1 = std::fabs(c[1]), a2 = std::fabs(c[2]);
    const int a = (a0 >= a1 && a0 >= a2) ? 0 : (a1 >= a2 ? 1 : 2);
    const double m = std::fabs(c[a]);
    if (!(m > 0)) return unclassified();
    const int b = (a + 1) % 3, cc = (a + 2) % 3;
    const double u = c[b] / m, v = c[cc] / m;
    auto cell = [&](double t) { return std::clamp(static_cast<int>(std::floor((t + 1.0) * 0.5 * n_)), 0, n_ - 1); };
    const int face = 2 * a + (c[a] < 0 ? 1 : 0);
    return static_cast<std::uint16_t>(face * n_ * n_ + cell(v) * n_ + cell(u));
}

void NormalMaskGrid::classify_triangles(const Vec3* vertices, const std::uint32_t* indices, std::size_t triangle_count,
                                        std::uint16_t* classes) const {
    for (std::size_t t = 0; t < triangle_count; ++t) {
        const Vec3 p0 = vertices[indices[3 * t]], p1 = vertices[indices[3 * t + 1]], p2 = vertices[indices[3 * t + 2]];
        const double e1[3] = {double(p1.x) - p0.x, double(p1.y) - p0.y, double(p1.z) - p0.z};
        const double e2[3] = {double(p2.x) - p0.x, double(p2.y) - p0.y, double(p2.z) - p0.z};
        double n[3], err[3];
        for (int k = 0; k < 3; ++k) {
            const int b = (k + 1) % 3, c = (k + 2) % 3;
            n[k] = e1[b] * e2[c] - e1[c] * e2[b];
            // Differences and products each round once in double (<= 2^-53 relative): 1e-15 of
            // the terms' magnitude is a generous bound on the component's error.
            err[k] = 1e-15 * (std::fabs(e1[b] * e2[c]) + std::fabs(e1[c] * e2[b]));
        }
        std::uint16_t cls = unclassified();
        if (std::isfinite(n[0]) && std::isfinite(n[1]) && std::isfinite(n[2]) && std::isfinite(err[0]) &&
            std::isfinite(err[1]) && std::isfinite(err[2])) {
            const double a0 = std::fabs(n[0]), a1 = std::fabs(n[1]), a2 = std::fabs(n[2]);
            const int a = (a0 >= a1 && a0 >= a2) ? 0 : (a1 >= a2 ? 1 : 2);
            const double m = std::fabs(n[a]);
            const double worst = err[a] + std::max(err[(a + 1) % 3], err[(a + 2) % 3]);
            // |delta u| <= (err_b + |u| err_a) / (m - err_a) with |u| <= 1.
            if (m > 2 * err[a] && worst <= 0.25 * kCellGrowth * (m - err[a]))
                cls = classify({static_cast<float>(n[0]), static_cast<float>(n[1]), static_cast<float>(n[2])});
            // Rounding n to float moves (u, v) by ~1e-7, far inside kCellGrowth / 4 as well.
        }
        classes[t] = cls;
    }
}

void NormalMaskGrid::class_corners(std::uint16_t cls, double corners[4][3]) const {
    const int per_face = n_ * n_;
    const int face = cls / per_face, rest = cls % per_face;
    const int j = rest / n_, i = rest % n_;
    const int a = face / 2, b = (a + 1) % 3, c = (a + 2) % 3;
    const double s = (face % 2) ? -1.0 : 1.0;
    const double u0 = -1.0 + 2.0 * i / n_ - kCellGrowth, u1 = -1.0 + 2.0 * (i + 1) / n_ + kCellGrowth;
    const double v0 = -1.0 + 2.0 * j / n_ - kCellGrowth, v1 = -1.0 + 2.0 * (j + 1) / n_ + kCellGrowth;
    const double uv[4][2] = {{u0, v0}, {u1, v0}, {u1, v1}, {u0, v1}};
    for (int k = 0; k < 4; ++k) {
        corners[k][a] = s;
        corners[k][b] = uv[k][0];
        corners[k][c] = uv[k][1];
    }
}

int BackMask::marked() const {
    int total = 0;
    for (std::uint64_t w : bits) total += __builtin_popcountll(w);
    return total;
}

void make_back_mask(const NormalMaskGrid& grid, const Mat4& world_to_clip, ClipDepth depth, int sector_x, int sector_y,
                    int sectors, BackMask& out) {
    if (sectors < 1 || sector_x < 0 || sector_y < 0 || sector_x >= sectors || sector_y >= sectors)
        throw Error("make_back_mask: sector (" + std::to_string(sector_x) + ", " + std::to_string(sector_y) +
                    ") is not in a " + std::to_string(sectors) + " x " + std::to_string(sectors) + " grid");
    const int classes = grid.class_count();
    out.class_count = classes;
    out.bits.assign(static_cast<std::size_t>(classes + 1 + 63) / 64, 0);

    double m[4][4];
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m[r][c] = world_to_clip.at(r, c);
    // The projection centre: the homogeneous point E with rows x, y, w of the matrix zero (the
    // generalized cross product of the three rows), oriented to the viewer's side (clip z < 0,
    // depth grows away from the eye in both conventions).
    const double* rx = m[0];
    const double* ry = m[1];
    const double* rw = m[3];
    double E[4] = {det3(rx[1], rx[2], rx[3], ry[1], ry[2], ry[3], rw[1], rw[2], rw[3]),
                   -det3(rx[0], rx[2], rx[3], ry[0], ry[2], ry[3], rw[0], rw[2], rw[3]),
                   det3(rx[0], rx[1], rx[3], ry[0], ry[1], ry[3], rw[0], rw[1], rw[3]),
                   -det3(rx[0], rx[1], rx[2], ry[0], ry[1], ry[2], rw[0], rw[1], rw[2])};
    const double ez = m[2][0] * E[0] + m[2][1] * E[1] + m[2][2] * E[2] + m[2][3] * E[3];
    if (!std::isfinite(ez) || ez == 0) return;
    if (ez > 0)
        for (double& e : E) e = -e;
    double inv[4][4];
    if (!invert_double(m, inv)) return;
    const double len_e = std::sqrt(E[0] * E[0] + E[1] * E[1] + E[2] * E[2]);
    const bool perspective = std::fabs(E[3]) > 1e-12 * len_e;
    const double eye[3] = {perspective ? E[0] / E[3] : 0, perspective ? E[1] / E[3] : 0, perspective ? E[2] / E[3] : 0};

    // Corner rays of the (grown) sector, at a depth inside the clip volume.
    const double grow = 2e-5;
    const double x0 = -1.0 + 2.0 * sector_x / sectors - grow, x1 = -1.0 + 2.0 * (sector_x + 1) / sectors + grow;
    const double y0 = -1.0 + 2.0 * sector_y / sectors - grow, y1 = -1.0 + 2.0 * (sector_y + 1) / sectors + grow;
    const double zmid = depth == ClipDepth::minus_one_to_one ? 0.0 : 0.5;  // a depth inside the clip volume
    const double ndc[4][2] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
    double rays[4][3];
    for (int k = 0; k < 4; ++k) {
        if (!perspective) {
            for (int a = 0; a < 3; ++a) rays[k][a] = -E[a];
            continue;
        }
        const double c[4] = {ndc[k][0], ndc[k][1], zmid, 1.0};
        double p[4];
        for (int r = 0; r < 4; ++r) p[r] = inv[r][0] * c[0] + inv[r][1] * c[1] + inv[r][2] * c[2] + inv[r][3] * c[3];
        if (!(p[3] > 0)) return;  // the corner is not in front of the centre: mark nothing
        for (int a = 0; a < 3; ++a) rays[k][a] = p[a] / p[3] - eye[a];
    }
    double ray_len[4];
    for (int k = 0; k < 4; ++k) {
        ray_len[k] = std::sqrt(rays[k][0] * rays[k][0] + rays[k][1] * rays[k][1] + rays[k][2] * rays[k][2]);
        if (!std::isfinite(ray_len[k]) || !(ray_len[k] > 0)) return;
    }
    for (int cls = 0; cls < classes; ++cls) {
        double corners[4][3];
        grid.class_corners(static_cast<std::uint16_t>(cls), corners);
        bool back = true;
        for (int i = 0; i < 4 && back; ++i) {
            const double len_n = std::sqrt(corners[i][0] * corners[i][0] + corners[i][1] * corners[i][1] +
                                           corners[i][2] * corners[i][2]);
            for (int j = 0; j < 4 && back; ++j) {
                const double d = corners[i][0] * rays[j][0] + corners[i][1] * rays[j][1] + corners[i][2] * rays[j][2];
                back = d > 1e-12 * len_n * ray_len[j];
            }
        }
        if (back) out.bits[static_cast<std::size_t>(cls) >> 6] |= std::uint64_t{1} << (cls & 63);
    }
}

int sector_of_point(const Mat4& world_to_clip, Vec3 p, int sectors) {
    if (sectors < 1) return -1;
    double c[4];
    for (int r = 0; r < 4; ++r)
        c[r] = double(world_to_clip.at(r, 0)) * p.x + double(world_to_clip.at(r, 1)) * p.y +
               double(world_to_clip.at(r, 2)) * p.z + double(world_to_clip.at(r, 3));
    if (!(c[3] > 0) || !std::isfinite(c[3])) return -1;
    const double x = c[0] / c[3], y = c[1] / c[3];
    if (!(x >= -1 && x <= 1 && y >= -1 && y <= 1)) return -1;
    const int sx = std::min(sectors - 1, static_cast<int>(std::floor((x + 1) * 0.5 * sectors)));
    const int sy = std::min(sectors - 1, static_cast<int>(std::floor((y + 1) * 0.5 * sectors)));
    return sy * sectors + sx;
}

void cull_by_normal_mask_scalar(const std::uint16_t* classes, std::size_t n, const BackMask& mask,
                                std::uint8_t* culled) {
    for (std::size_t i = 0; i < n; ++i) culled[i] = mask.test(classes[i]) ? 1 : 0;
}

}  // namespace patchcull
