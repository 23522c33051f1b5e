// Back-face culling of triangles (patchcull/objects/backface.h): the per-triangle test against exact
// integer arithmetic and double precision (scalar == SIMD bit for bit), and normal masks
// (Zhang & Hoff 1997) against dense samples of the frustum and of the class cones.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "patchcull/core/clip_space.h"
#include "patchcull/core/error.h"
#include "patchcull/core/math.h"
#include "patchcull/objects/backface.h"

using namespace patchcull;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Mesh {
    std::vector<Vec3> vertices;
    std::vector<std::uint32_t> indices;
    std::size_t triangles() const { return indices.size() / 3; }
};

// Calls body() once per SIMD target compiled in and supported here, dispatch forced to it.
void for_each_simd_target(const std::function<void()>& body) {
    for (std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
        hwy::SetSupportedTargetsForTest(target);
        SCOPED_TRACE(std::string("SIMD target ") + hwy::TargetName(target));
        body();
    }
    hwy::SetSupportedTargetsForTest(0);
}

std::vector<std::uint8_t> run(bool simd, const Mesh& m, Vec3 eye) {
    constexpr std::size_t kGuard = 40;
    std::vector<std::uint8_t> out(m.triangles() + kGuard, 0xAB);
    (simd ? cull_backfacing_triangles_simd : cull_backfacing_triangles_scalar)(m.vertices.data(), m.indices.data(),
                                                                               m.triangles(), eye, out.data());
    for (std::size_t k = 0; k < kGuard; ++k) EXPECT_EQ(out[m.triangles() + k], 0xAB) << "wrote past the end";
    out.resize(m.triangles());
    return out;
}

// Exact sign of n . (eye - p0) for points on the grid step * integer (|integer| < 2^24): the
// integers' triple product fits __int128.
int exact_sign(Vec3 p0, Vec3 p1, Vec3 p2, Vec3 e, float step) {
    auto I = [&](float v) { return static_cast<__int128>(std::llround(double(v) / step)); };
    const __int128 a[3] = {I(p1.x) - I(p0.x), I(p1.y) - I(p0.y), I(p1.z) - I(p0.z)};
    const __int128 b[3] = {I(p2.x) - I(p0.x), I(p2.y) - I(p0.y), I(p2.z) - I(p0.z)};
    const __int128 w[3] = {I(e.x) - I(p0.x), I(e.y) - I(p0.y), I(e.z) - I(p0.z)};
    const __int128 n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    const __int128 s = n[0] * w[0] + n[1] * w[1] + n[2] * w[2];
    return s > 0 ? 1 : (s < 0 ? -1 : 0);
}

// A random mesh whose vertices (and the eyes below) lie on the grid step * integer around
// centre (a multiple of step), |integer| < 2^24 so every value is an exact float.
struct GridCase {
    Mesh mesh;
    std::vector<Vec3> eyes;
    float step;
};

GridCase grid_case(std::mt19937& rng, float step, double centre, int extent, std::size_t triangles) {
    GridCase g;
    g.step = step;
    std::uniform_int_distribution<int> coord(-extent, extent), small(-3, 3), pick(0, 9);
    const double c = std::round(centre / step);
    auto point = [&](int x, int y, int z) {
        return Vec3{float((c + x) * step), float((c + y) * step), float((c + z) * step)};
    };
    for (std::size_t t = 0; t < triangles; ++t) {
        const int x = coord(rng), y = coord(rng), z = coord(rng);
        const int kind = pick(rng);
        Vec3 p[3];
        p[0] = point(x, y, z);
        // Mostly small triangles, some large, some degenerate (coincident or collinear).
        const int s = kind < 6 ? 8 : extent / 4;
        std::uniform_int_distribution<int> d(-s, s);
        const int a[3] = {d(rng), d(rng), d(rng)}, b[3] = {d(rng), d(rng), d(rng)};
        p[1] = point(x + a[0], y + a[1], z + a[2]);
        p[2] = point(x + b[0], y + b[1], z + b[2]);
        if (kind == 8) p[2] = p[1];                                             // coincident
        if (kind == 9) p[2] = point(x + 2 * a[0], y + 2 * a[1], z + 2 * a[2]);  // collinear
        for (int k = 0; k < 3; ++k) {
            g.mesh.indices.push_back(static_cast<std::uint32_t>(g.mesh.vertices.size()));
            g.mesh.vertices.push_back(p[k]);
        }
    }
    // Eyes: random grid points, and eyes exactly on / one grid step off a triangle's plane.
    for (int k = 0; k < 40; ++k) g.eyes.push_back(point(coord(rng), coord(rng), coord(rng)));
    std::uniform_int_distribution<std::size_t> tri(0, triangles - 1);
    for (int k = 0; k < 40; ++k) {
        const std::size_t t = tri(rng);
        const Vec3 p0 = g.mesh.vertices[3 * t], p1 = g.mesh.vertices[3 * t + 1], p2 = g.mesh.vertices[3 * t + 2];
        const int i = small(rng), j = small(rng);
        Vec3 e = p0 + (p1 - p0) * float(i) + (p2 - p0) * float(j);  // exact: small grid integers
        if (k % 2) e.z += step * float(small(rng));
        g.eyes.push_back(e);
    }
    return g;
}

}  // namespace

TEST(BackfaceTriangles, HandCases) {
    // Counter-clockwise seen from +z: normal +z.
    Mesh m{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}};
    EXPECT_EQ(run(false, m, {0.2f, 0.2f, 1})[0], 0);   // in front
    EXPECT_EQ(run(false, m, {0.2f, 0.2f, -1})[0], 1);  // behind
    EXPECT_EQ(run(false, m, {5, 5, 0})[0], 0);         // in the plane: the margin keeps it
    // Zero-area triangles are culled; non-finite ones kept.
    Mesh z{{{1, 2, 3}, {1, 2, 3}, {4, 5, 6}}, {0, 1, 2}};
    EXPECT_EQ(run(false, z, {0, 0, 10})[0], 1);
    EXPECT_EQ(run(true, z, {0, 0, 10})[0], 1);
    Mesh n{{{0, 0, 0}, {1, 0, 0}, {0, std::numeric_limits<float>::quiet_NaN(), 0}}, {0, 1, 2}};
    EXPECT_EQ(run(false, n, {0.2f, 0.2f, -1})[0], 0);
    EXPECT_EQ(run(true, n, {0.2f, 0.2f, -1})[0], 0);
    Mesh inf{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}};
    EXPECT_EQ(run(false, inf, {0.2f, 0.2f, -std::numeric_limits<float>::infinity()})[0], 0);
    EXPECT_EQ(run(true, inf, {0.2f, 0.2f, -std::numeric_limits<float>::infinity()})[0], 0);
}

TEST(BackfaceTriangles, ExactOnGridsNearAndFarFromTheOrigin) {
    // Culled => exactly back-facing (n . (e - p0) <= 0 in integer arithmetic), at unit scale,
    // tiny scale and 1e4 - 1e5 from the origin; and almost every clearly back-facing one culled.
    std::mt19937 rng(11);
    struct Scale {
        float step;
        double centre;
        int extent;
    };
    const Scale scales[] = {{1.0f / 1024, 0.0, 4096}, {1.0f / 1024, 3.0, 2048}, {std::ldexp(1.0f, -40), 0.0, 4096},
                            {1.0f / 128, 1e4, 4096},  {1.0f / 64, 1e5, 2048},   {1.0f / 16, -7.5e4, 8000}};
    std::size_t culled_total = 0, back_total = 0, on_plane = 0;
    for (const Scale& s : scales) {
        GridCase g = grid_case(rng, s.step, s.centre, s.extent, 301);
        for (Vec3 eye : g.eyes) {
            const auto sc = run(false, g.mesh, eye), si = run(true, g.mesh, eye);
            ASSERT_EQ(sc, si) << "scalar and SIMD differ, step " << s.step << " centre " << s.centre;
            for (std::size_t t = 0; t < g.mesh.triangles(); ++t) {
                const Vec3 p0 = g.mesh.vertices[3 * t], p1 = g.mesh.vertices[3 * t + 1],
                           p2 = g.mesh.vertices[3 * t + 2];
                const int sign = exact_sign(p0, p1, p2, eye, s.step);
                if (sc[t]) {
                    ++culled_total;
                    EXPECT_LE(sign, 0) << "front-facing triangle culled: step " << s.step << " centre " << s.centre;
                }
                if (sign < 0) ++back_total;
                if (sign == 0) ++on_plane;
            }
        }
    }
    EXPECT_GT(on_plane, 100u);  // the on-plane eyes were exercised
    // Rounding keeps only eyes within ~1e-6 relative of a plane (and collinear triangles).
    EXPECT_GT(culled_total, back_total * 95 / 100);
}

TEST(BackfaceTriangles, EyesOneGridStepOffThePlaneFarAlongIt) {
    // The hardest case for the float test: |eye - p0| ~ 1e7 grid steps along the plane and one
    // step off it, so the exact value is ~1e-7 of the terms. Rounding decides the sign of the
    // float value here; without the margin front-facing triangles were culled (checked by
    // setting kTriangleTestErrorBound to 0).
    std::mt19937 rng(14);
    std::uniform_int_distribution<int> edge(-1500, 1500), far(-5000, 5000), off(-1, 1), base(-3000, 3000);
    const float step = 1.0f / 8;
    std::size_t front = 0, culled_front = 0, back = 0, culled_back = 0;
    // Whole multiples of the edges (-5..5, the quotient truncated), so that the eyes stay on the
    // grid exact_sign reads.
    const auto whole = [&] { return far(rng) / 1000; };
    for (int t = 0; t < 400; ++t) {
        const Vec3 p0{base(rng) * step, base(rng) * step, base(rng) * step};
        const Vec3 p1 = p0 + Vec3{float(edge(rng)), float(edge(rng)), float(edge(rng))} * step;
        const Vec3 p2 = p0 + Vec3{float(edge(rng)), float(edge(rng)), float(edge(rng))} * step;
        Mesh m{{p0, p1, p2}, {0, 1, 2}};
        for (int k = 0; k < 50; ++k) {
            Vec3 e = p0 + (p1 - p0) * float(whole()) + (p2 - p0) * float(whole());
            e = e + Vec3{float(off(rng)), float(off(rng)), float(off(rng))} * step;
            const int sign = exact_sign(p0, p1, p2, e, step);
            const std::uint8_t sc = run(false, m, e)[0];
            ASSERT_EQ(sc, run(true, m, e)[0]);
            if (sign > 0) ++front, culled_front += sc;
            if (sign < 0) ++back, culled_back += sc;
        }
    }
    EXPECT_GT(front, 1000u);
    EXPECT_EQ(culled_front, 0u) << "front-facing triangles culled by rounding";
    EXPECT_GT(culled_back, 0u);
}

TEST(BackfaceTriangles, RandomFloatsAgainstDouble) {
    // Generic floats: culled => the double-precision value is <= its own rounding bound; clearly
    // back-facing triangles (value < -1e-5 of the permanent) are always culled.
    std::mt19937 rng(12);
    std::uniform_real_distribution<float> u(-1, 1);
    const float offsets[] = {0.0f, 1e4f, -3e4f, 1e5f};
    for (float off : offsets) {
        Mesh m;
        for (int t = 0; t < 997; ++t) {
            const Vec3 c{off + 5 * u(rng), off + 5 * u(rng), 5 * u(rng)};
            const float size = t % 3 == 0 ? 1e-3f : 0.5f;
            for (int k = 0; k < 3; ++k) {
                m.indices.push_back(static_cast<std::uint32_t>(m.vertices.size()));
                m.vertices.push_back(c + Vec3{size * u(rng), size * u(rng), size * u(rng)});
            }
        }
        for (int k = 0; k < 30; ++k) {
            const Vec3 eye{off + 10 * u(rng), off + 10 * u(rng), 10 * u(rng)};
            const auto sc = run(false, m, eye), si = run(true, m, eye);
            ASSERT_EQ(sc, si);
            for (std::size_t t = 0; t < m.triangles(); ++t) {
                const Vec3 p0 = m.vertices[3 * t], p1 = m.vertices[3 * t + 1], p2 = m.vertices[3 * t + 2];
                const double a[3] = {double(p1.x) - p0.x, double(p1.y) - p0.y, double(p1.z) - p0.z};
                const double b[3] = {double(p2.x) - p0.x, double(p2.y) - p0.y, double(p2.z) - p0.z};
                const double w[3] = {double(eye.x) - p0.x, double(eye.y) - p0.y, double(eye.z) - p0.z};
                const double n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
                const double s = n[0] * w[0] + n[1] * w[1] + n[2] * w[2];
                const double perm = (std::fabs(a[1] * b[2]) + std::fabs(a[2] * b[1])) * std::fabs(w[0]) +
                                    (std::fabs(a[2] * b[0]) + std::fabs(a[0] * b[2])) * std::fabs(w[1]) +
                                    (std::fabs(a[0] * b[1]) + std::fabs(a[1] * b[0])) * std::fabs(w[2]);
                if (sc[t]) {
                    EXPECT_LE(s, 1e-14 * perm) << "front-facing triangle culled, offset " << off;
                }
                if (s < -1e-5 * perm) {
                    EXPECT_EQ(sc[t], 1) << "clearly back-facing triangle kept, offset " << off;
                }
            }
        }
    }
}

TEST(BackfaceTriangles, ScalarEqualsSimdOnIndexedMeshesOfEverySize) {
    std::mt19937 rng(13);
    std::uniform_real_distribution<float> u(-2, 2);
    for (std::size_t n : {0u, 1u, 3u, 7u, 8u, 15u, 16u, 17u, 33u, 64u, 129u}) {
        Mesh m;
        for (int v = 0; v < 50; ++v) m.vertices.push_back({u(rng), u(rng), u(rng)});
        std::uniform_int_distribution<std::uint32_t> vi(0, 49);
        for (std::size_t t = 0; t < 3 * n; ++t) m.indices.push_back(vi(rng));
        for (int k = 0; k < 10; ++k) {
            const Vec3 eye{3 * u(rng), 3 * u(rng), 3 * u(rng)};
            const auto expected = run(false, m, eye);
            for_each_simd_target([&] { EXPECT_EQ(expected, run(true, m, eye)) << n << " triangles"; });
        }
    }
}

// ---- normal masks --------------------------------------------------------------------------

namespace {

struct Camera {
    Mat4 world_to_clip;
    double eye[3];     // the matrix's projection centre (double)
    double inv[4][4];  // inverse of world_to_clip (double)
};

bool invert4(const double a[4][4], double out[4][4]) {
    double m[4][8];
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 8; ++c) m[r][c] = c < 4 ? a[r][c] : (c - 4 == r);
    for (int c = 0; c < 4; ++c) {
        int p = c;
        for (int r = c + 1; r < 4; ++r)
            if (std::fabs(m[r][c]) > std::fabs(m[p][c])) p = r;
        if (m[p][c] == 0) return false;
        for (int k = 0; k < 8; ++k) std::swap(m[c][k], m[p][k]);
        const double f = 1 / m[c][c];
        for (int k = 0; k < 8; ++k) m[c][k] *= f;
        for (int r = 0; r < 4; ++r)
            if (r != c) {
                const double g = m[r][c];
                for (int k = 0; k < 8; ++k) m[r][k] -= g * m[c][k];
            }
    }
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) out[r][c] = m[r][c + 4];
    return true;
}

Camera make_camera(Vec3 eye, Vec3 target, float fovy, float aspect, ClipDepth depth = ClipDepth::zero_to_one) {
    Camera c;
    c.world_to_clip = perspective(fovy, aspect, 0.1f, 100.0f, depth) * look_at(eye, target, {0, 1, 0});
    double m[4][4];
    for (int r = 0; r < 4; ++r)
        for (int k = 0; k < 4; ++k) m[r][k] = c.world_to_clip.at(r, k);
    EXPECT_TRUE(invert4(m, c.inv));
    // Centre: inv * (0, 0, 1, 0), made Cartesian.
    double h[4];
    for (int r = 0; r < 4; ++r) h[r] = c.inv[r][2];
    for (int a = 0; a < 3; ++a) c.eye[a] = h[a] / h[3];
    return c;
}

// A point of the frustum at NDC (x, y) and zero-to-one depth z, in double.
void unproject(const Camera& c, double x, double y, double z, ClipDepth depth, double out[3]) {
    const double zc = depth == ClipDepth::zero_to_one ? z : 2 * z - 1;
    const double v[4] = {x, y, zc, 1};
    double h[4];
    for (int r = 0; r < 4; ++r)
        h[r] = c.inv[r][0] * v[0] + c.inv[r][1] * v[1] + c.inv[r][2] * v[2] + c.inv[r][3] * v[3];
    for (int a = 0; a < 3; ++a) out[a] = h[a] / h[3];
}

// A random direction of class cls (inside its cell, corners and edges included).
void random_class_normal(const NormalMaskGrid& g, std::uint16_t cls, std::mt19937& rng, double n[3]) {
    const int N = g.divisions(), face = cls / (N * N), j = (cls % (N * N)) / N, i = cls % N;
    const int a = face / 2, b = (a + 1) % 3, c = (a + 2) % 3;
    std::uniform_real_distribution<double> t(0, 1);
    std::uniform_int_distribution<int> pick(0, 5);
    auto coord = [&](int cell) {
        const int k = pick(rng);
        const double f = k == 0 ? 0.0 : (k == 1 ? 1.0 : t(rng));
        return -1.0 + 2.0 * (cell + f) / N;
    };
    n[a] = face % 2 ? -1.0 : 1.0;
    n[b] = coord(i);
    n[c] = coord(j);
}

std::vector<std::uint8_t> mask_lookup(bool simd, const std::vector<std::uint16_t>& classes, const BackMask& mask) {
    std::vector<std::uint8_t> out(classes.size() + 16, 0xCD);
    (simd ? cull_by_normal_mask_simd : cull_by_normal_mask_scalar)(classes.data(), classes.size(), mask, out.data());
    for (std::size_t k = 0; k < 16; ++k) EXPECT_EQ(out[classes.size() + k], 0xCD);
    out.resize(classes.size());
    return out;
}

}  // namespace

TEST(NormalMasks, ClassifyPutsEveryDirectionIntoItsCell) {
    EXPECT_THROW(NormalMaskGrid(0), Error);
    EXPECT_THROW(NormalMaskGrid(NormalMaskGrid::kMaxDivisions + 1), Error);
    const NormalMaskGrid big(NormalMaskGrid::kMaxDivisions);
    EXPECT_LE(big.unclassified(), 65535);
    for (int N : {1, 2, 5, 16}) {
        const NormalMaskGrid g(N);
        EXPECT_EQ(g.class_count(), 6 * N * N);
        EXPECT_EQ(g.classify({0, 0, 0}), g.unclassified());
        EXPECT_EQ(g.classify({std::numeric_limits<float>::quiet_NaN(), 1, 0}), g.unclassified());
        std::mt19937 rng(20 + N);
        std::normal_distribution<float> nd;
        std::vector<int> hits(g.class_count(), 0);
        for (int k = 0; k < 20000; ++k) {
            Vec3 n{nd(rng), nd(rng), nd(rng)};
            if (k % 7 == 0) n.y = n.x;  // ties between axes
            const std::uint16_t cls = g.classify(n);
            ASSERT_LT(cls, g.class_count());
            ++hits[cls];
            // n is a non-negative combination of the grown cell's corners: inside every side plane.
            double c[4][3];
            g.class_corners(cls, c);
            const double v[3] = {n.x, n.y, n.z};
            for (int e = 0; e < 4; ++e) {
                const double* p = c[e];
                const double* q = c[(e + 1) % 4];
                const double side[3] = {p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2],
                                        p[0] * q[1] - p[1] * q[0]};
                const double inward =
                    c[(e + 2) % 4][0] * side[0] + c[(e + 2) % 4][1] * side[1] + c[(e + 2) % 4][2] * side[2];
                const double s = v[0] * side[0] + v[1] * side[1] + v[2] * side[2];
                EXPECT_GE(s * (inward > 0 ? 1 : -1), 0) << "normal outside its class cone";
            }
        }
        for (int cls = 0; cls < g.class_count(); ++cls) EXPECT_GT(hits[cls], 0) << "class " << cls << " never hit";
    }
}

TEST(NormalMasks, MarkedClassesNeverFaceAnyPointOfTheFrustum) {
    const NormalMaskGrid grid(16);
    struct View {
        Vec3 eye, target;
        float fovy, aspect;
        ClipDepth depth;
    };
    const View views[] = {{{0, 0, 5}, {0, 0, 0}, 1.0f, 1.5f, ClipDepth::zero_to_one},
                          {{3, 4, -2}, {-1, 0.5f, 1}, 1.6f, 1.0f, ClipDepth::minus_one_to_one},
                          {{1e5f, 2e4f, -3e4f}, {1e5f - 10, 2e4f + 3, -3e4f + 7}, 0.7f, 2.0f, ClipDepth::zero_to_one}};
    std::mt19937 rng(31);
    std::uniform_real_distribution<double> ndc(-1, 1), z01(0, 1);
    for (const View& v : views) {
        const Camera cam = make_camera(v.eye, v.target, v.fovy, v.aspect, v.depth);
        BackMask mask;
        make_back_mask(grid, cam.world_to_clip, v.depth, 0, 0, 1, mask);
        // A 40-92 degree frustum: 146-302 of the 1536 classes are marked (cells whose whole cone
        // faces away from every corner ray).
        EXPECT_GT(mask.marked(), grid.class_count() / 20);
        EXPECT_LT(mask.marked(), grid.class_count() / 2);
        std::vector<double> pts;
        for (int k = 0; k < 400; ++k) {
            double p[3];
            const int edge = k % 4;  // corners and edges of the frustum too
            const double x = edge == 0 ? (k % 8 < 4 ? -1.0 : 1.0) : ndc(rng);
            const double y = edge == 1 ? (k % 8 < 4 ? -1.0 : 1.0) : ndc(rng);
            unproject(cam, x, y, z01(rng), v.depth, p);
            pts.insert(pts.end(), p, p + 3);
        }
        int checked = 0;
        for (int cls = 0; cls < grid.class_count(); ++cls) {
            if (!mask.test(static_cast<std::uint16_t>(cls))) continue;
            for (int s = 0; s < 20; ++s) {
                double n[3];
                random_class_normal(grid, static_cast<std::uint16_t>(cls), rng, n);
                for (std::size_t k = 0; k < pts.size(); k += 3) {
                    const double f = n[0] * (cam.eye[0] - pts[k]) + n[1] * (cam.eye[1] - pts[k + 1]) +
                                     n[2] * (cam.eye[2] - pts[k + 2]);
                    ASSERT_LE(f, 0) << "class " << cls << " is marked but faces a frustum point";
                    ++checked;
                }
            }
        }
        EXPECT_GT(checked, 100000);
    }
}

TEST(NormalMasks, SectorMasksHoldForTheirSubFrustaAndContainTheWholeMask) {
    const NormalMaskGrid grid(16);
    const Camera cam = make_camera({2, 1, 6}, {0, 0, 0}, 1.2f, 1.33f);
    BackMask whole;
    make_back_mask(grid, cam.world_to_clip, ClipDepth::zero_to_one, 0, 0, 1, whole);
    EXPECT_THROW(make_back_mask(grid, cam.world_to_clip, ClipDepth::zero_to_one, 4, 0, 4, whole), Error);
    EXPECT_THROW(make_back_mask(grid, cam.world_to_clip, ClipDepth::zero_to_one, 0, 0, 0, whole), Error);
    make_back_mask(grid, cam.world_to_clip, ClipDepth::zero_to_one, 0, 0, 1, whole);
    const int S = 4;
    std::mt19937 rng(32);
    std::uniform_real_distribution<double> t(0, 1);
    int sector_gain = 0;
    for (int sy = 0; sy < S; ++sy)
        for (int sx = 0; sx < S; ++sx) {
            BackMask m;
            make_back_mask(grid, cam.world_to_clip, ClipDepth::zero_to_one, sx, sy, S, m);
            for (int cls = 0; cls < grid.class_count(); ++cls)
                if (whole.test(cls)) {
                    EXPECT_TRUE(m.test(cls)) << "sector mask lost a class of the whole mask";
                }
            sector_gain += m.marked() - whole.marked();
            for (int cls = 0; cls < grid.class_count(); ++cls) {
                if (!m.test(static_cast<std::uint16_t>(cls))) continue;
                for (int s = 0; s < 10; ++s) {
                    double n[3];
                    random_class_normal(grid, static_cast<std::uint16_t>(cls), rng, n);
                    for (int k = 0; k < 30; ++k) {
                        const double x = -1 + 2 * (sx + (k == 0 ? 0.0 : k == 1 ? 1.0 : t(rng))) / S;
                        const double y = -1 + 2 * (sy + (k == 2 ? 0.0 : k == 3 ? 1.0 : t(rng))) / S;
                        double p[3];
                        unproject(cam, x, y, t(rng), ClipDepth::zero_to_one, p);
                        const double f =
                            n[0] * (cam.eye[0] - p[0]) + n[1] * (cam.eye[1] - p[1]) + n[2] * (cam.eye[2] - p[2]);
                        ASSERT_LE(f, 0) << "sector " << sx << "," << sy << " class " << cls;
                    }
                }
            }
        }
    EXPECT_GT(sector_gain, S * S * 10);  // sectors mark more classes (the lecture's reason for them)
}

TEST(NormalMasks, TrianglesCulledByMasksAreBackFacingAndAlsoByTheDotProduct) {
    // Random triangles around the view; classes from classify_triangles; a triangle uses the
    // whole mask, or the mask of the sector its first vertex projects into (sector_of_point).
    const NormalMaskGrid grid(16);
    std::mt19937 rng(33);
    std::uniform_real_distribution<float> u(-1, 1);
    for (float off : {0.0f, 2e4f}) {
        const Vec3 eye{off + 1, 2, 8};
        const Camera cam = make_camera(eye, {off, 0, 0}, 1.0f, 1.0f);
        Mesh m;
        for (int t = 0; t < 3000; ++t) {
            const Vec3 c{off + 4 * u(rng), 4 * u(rng), 4 * u(rng)};
            const float size = t % 5 == 0 ? 1e-4f : 0.3f;
            for (int k = 0; k < 3; ++k) {
                m.indices.push_back(static_cast<std::uint32_t>(m.vertices.size()));
                m.vertices.push_back(c + Vec3{size * u(rng), size * u(rng), size * u(rng)});
            }
        }
        std::vector<std::uint16_t> classes(m.triangles());
        grid.classify_triangles(m.vertices.data(), m.indices.data(), m.triangles(), classes.data());
        BackMask whole;
        make_back_mask(grid, cam.world_to_clip, ClipDepth::zero_to_one, 0, 0, 1, whole);
        const int S = 3;
        std::vector<BackMask> sectors(S * S);
        for (int s = 0; s < S * S; ++s)
            make_back_mask(grid, cam.world_to_clip, ClipDepth::zero_to_one, s % S, s / S, S, sectors[s]);
        const Vec3 ef{float(cam.eye[0]), float(cam.eye[1]), float(cam.eye[2])};
        const auto dot_culled = run(false, m, ef);
        const auto by_mask = mask_lookup(false, classes, whole);
        EXPECT_EQ(by_mask, mask_lookup(true, classes, whole));
        std::size_t mask_count = 0, sector_count = 0, dot_count = 0, not_by_dot = 0;
        for (std::size_t t = 0; t < m.triangles(); ++t) {
            const Vec3 p0 = m.vertices[3 * t], p1 = m.vertices[3 * t + 1], p2 = m.vertices[3 * t + 2];
            const double a[3] = {double(p1.x) - p0.x, double(p1.y) - p0.y, double(p1.z) - p0.z};
            const double b[3] = {double(p2.x) - p0.x, double(p2.y) - p0.y, double(p2.z) - p0.z};
            const double n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
            const double f = n[0] * (cam.eye[0] - p0.x) + n[1] * (cam.eye[1] - p0.y) + n[2] * (cam.eye[2] - p0.z);
            // Only triangles with a point in the frustum can have a pixel: the test is about those
            // (here: a vertex on screen in front of the eye).
            if (sector_of_point(cam.world_to_clip, p0, 1) < 0) continue;
            const int sector = sector_of_point(cam.world_to_clip, p0, S);
            const bool sec = sectors[sector].test(classes[t]);
            if (by_mask[t] || sec) {
                EXPECT_LE(f, 0) << "mask-culled triangle faces the eye";
                if (!dot_culled[t]) ++not_by_dot;
            }
            mask_count += by_mask[t];
            sector_count += sec;
            dot_count += dot_culled[t];
        }
        EXPECT_GT(mask_count, 50u);
        EXPECT_GT(sector_count, mask_count);  // sector masks hold the whole mask and mark more
        EXPECT_LE(mask_count, dot_count);     // the mask keeps more than the exact test
        EXPECT_LE(not_by_dot, 2u);            // only within the dot test's rounding margin
    }
}

TEST(NormalMasks, LookupScalarEqualsSimdForAnyClassValue) {
    const NormalMaskGrid grid(7);
    const Camera cam = make_camera({0, 0, 3}, {0, 0, 0}, 1.0f, 1.0f);
    BackMask mask;
    make_back_mask(grid, cam.world_to_clip, ClipDepth::zero_to_one, 0, 0, 1, mask);
    std::mt19937 rng(34);
    std::uniform_int_distribution<int> cls(0, 65535), small(0, grid.class_count());
    for (std::size_t n : {0u, 1u, 5u, 8u, 16u, 31u, 100u, 1001u}) {
        std::vector<std::uint16_t> c(n);
        for (auto& v : c) v = static_cast<std::uint16_t>(n % 2 ? cls(rng) : small(rng));
        const auto a = mask_lookup(false, c, mask);
        for_each_simd_target([&] { EXPECT_EQ(a, mask_lookup(true, c, mask)); });
        for (std::size_t k = 0; k < n; ++k) EXPECT_EQ(a[k], mask.test(c[k]) ? 1 : 0);
    }
    EXPECT_FALSE(mask.test(grid.unclassified()));
    BackMask empty;
    std::vector<std::uint16_t> c(20, 3);
    EXPECT_EQ(mask_lookup(true, c, empty), std::vector<std::uint8_t>(20, 0));
    EXPECT_EQ(mask_lookup(false, c, empty), std::vector<std::uint8_t>(20, 0));
}

TEST(NormalMasks, OrthographicAndDegenerateMatrices) {
    const NormalMaskGrid grid(8);
    // Orthographic: looking down -z; marked classes are exactly those whose whole grown cell has
    // n . (0, 0, -1) > 0, i.e. cells of the -z face (away from the viewer).
    Mat4 ortho;
    ortho.at(2, 2) = -0.1f;  // depth grows with -z
    ortho.at(2, 3) = 0.5f;
    BackMask mask;
    make_back_mask(grid, ortho, ClipDepth::zero_to_one, 0, 0, 1, mask);
    int expected = 0;
    for (int cls = 0; cls < grid.class_count(); ++cls) {
        double c[4][3];
        grid.class_corners(static_cast<std::uint16_t>(cls), c);
        const bool away = c[0][2] < 0 && c[1][2] < 0 && c[2][2] < 0 && c[3][2] < 0;
        expected += away;
        EXPECT_EQ(mask.test(static_cast<std::uint16_t>(cls)), away) << cls;
        if (cls / 64 == 5) {  // the whole -z face
            EXPECT_TRUE(away);
        }
    }
    EXPECT_EQ(mask.marked(), expected);
    EXPECT_EQ(expected, 64 + 4 * 24);
    Mat4 zero;
    for (float& v : zero.m) v = 0;
    make_back_mask(grid, zero, ClipDepth::zero_to_one, 0, 0, 1, mask);
    EXPECT_EQ(mask.marked(), 0);
    EXPECT_EQ(sector_of_point(zero, {0, 0, 0}, 2), -1);
}
