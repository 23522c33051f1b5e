// Clustered back-face culling (patchcull/objects/backface_clusters.h; Johannsen & Carter 1998 as
// G. Zachmann's lecture "Advanced Visibility Computations" presents it): the cluster test against
// every member's exact dot product, the merge, the choice of c, the culling probability against
// hand cases and Monte Carlo sampling, the merge criterion against the cost model, and the
// hierarchy against testing every leaf alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/objects/backface.h"
#include "patchcull/objects/backface_clusters.h"

using namespace patchcull;

namespace {

struct Mesh {
    std::vector<Vec3> vertices;
    std::vector<std::uint32_t> indices;
    std::size_t triangles() const { return indices.size() / 3; }
};

// n . (e - p0) in double and the magnitude of its terms.
double facing(const Mesh& m, std::size_t t, Vec3 e, double& mag) {
    const Vec3 p0 = m.vertices[m.indices[3 * t]], p1 = m.vertices[m.indices[3 * t + 1]],
               p2 = m.vertices[m.indices[3 * t + 2]];
    const double a[3] = {double(p1.x) - p0.x, double(p1.y) - p0.y, double(p1.z) - p0.z};
    const double b[3] = {double(p2.x) - p0.x, double(p2.y) - p0.y, double(p2.z) - p0.z};
    const double w[3] = {double(e.x) - p0.x, double(e.y) - p0.y, double(e.z) - p0.z};
    const double n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    mag = std::fabs(n[0] * w[0]) + std::fabs(n[1] * w[1]) + std::fabs(n[2] * w[2]) + 1e-300;
    return n[0] * w[0] + n[1] * w[1] + n[2] * w[2];
}

// A random cluster: count triangles around centre (spread s) whose normals lie within `cone`
// radians of axis; with degenerate = true, 1 in 10 degenerate (coincident or collinear vertices:
// a float-collinear sliver has a normal of rounding noise, which widens the normal box to hold
// 0, so clusters with one cull little).
Mesh random_cluster(std::mt19937& rng, Vec3 centre, float spread, float size, Vec3 axis, float cone, int count,
                    bool degenerate = true) {
    std::uniform_real_distribution<float> u(-1, 1);
    std::uniform_int_distribution<int> pick(0, 19);
    Mesh m;
    axis = normalize(axis);
    Vec3 t1 = normalize(cross(axis, std::fabs(axis.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
    Vec3 t2 = cross(axis, t1);
    for (int i = 0; i < count; ++i) {
        Vec3 n;
        do {
            n = axis + t1 * (std::tan(cone) * u(rng)) + t2 * (std::tan(cone) * u(rng));
        } while (std::acos(std::clamp(dot(normalize(n), axis), -1.0f, 1.0f)) > cone);
        n = normalize(n);
        const Vec3 a = normalize(cross(n, std::fabs(n.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
        const Vec3 b = cross(n, a);
        const Vec3 p = centre + Vec3{spread * u(rng), spread * u(rng), spread * u(rng)};
        // Counter-clockwise around n: p, p + a, p + b (a x b = n).
        Vec3 q[3] = {p, p + a * size, p + b * size};
        const int k = degenerate ? pick(rng) : 19;
        if (k == 0) q[2] = q[1];
        if (k == 1) q[2] = p + a * (2 * size);
        for (const Vec3& v : q) {
            m.indices.push_back(static_cast<std::uint32_t>(m.vertices.size()));
            m.vertices.push_back(v);
        }
    }
    return m;
}

// f(e - c) - d of the stored cluster in double (the exact value the float test bounds).
double cluster_value(const BackfaceCluster& c, Vec3 e) {
    const double x[3] = {double(e.x) - c.c.x, double(e.y) - c.c.y, double(e.z) - c.c.z};
    const double n[3] = {c.n_min.x, c.n_min.y, c.n_min.z}, m[3] = {c.m_max.x, c.m_max.y, c.m_max.z};
    double s = 0;
    for (int a = 0; a < 3; ++a) s += (x[a] > 0 ? m[a] : n[a]) * x[a];
    return s - c.d;
}

double f_dir(const BackfaceCluster& c, const double x[3]) {
    const double n[3] = {c.n_min.x, c.n_min.y, c.n_min.z}, m[3] = {c.m_max.x, c.m_max.y, c.m_max.z};
    double s = 0;
    for (int a = 0; a < 3; ++a) s += (x[a] > 0 ? m[a] : n[a]) * x[a];
    return s;
}

// Eyes: uniform in a box around the cluster, and on / just inside / just outside the culling
// volume's boundary along random rays from c.
std::vector<Vec3> test_eyes(std::mt19937& rng, const BackfaceCluster& c, Vec3 centre, float radius, int n) {
    std::uniform_real_distribution<float> u(-1, 1);
    std::normal_distribution<double> nd;
    std::vector<Vec3> eyes;
    eyes.reserve(6 * static_cast<std::size_t>(n));  // n in the box, up to 5 per ray
    for (int i = 0; i < n; ++i) eyes.push_back(centre + Vec3{radius * u(rng), radius * u(rng), radius * u(rng)});
    for (int i = 0; i < n; ++i) {
        double dir[3] = {nd(rng), nd(rng), nd(rng)};
        const double f = f_dir(c, dir);
        if (!(f > 0) || !(c.d > 0)) continue;
        const double t = c.d / f;
        for (double s : {1.0 - 1e-3, 1.0 - 1e-6, 1.0, 1.0 + 1e-6, 1.0 + 1e-3})
            eyes.push_back(
                {float(c.c.x + s * t * dir[0]), float(c.c.y + s * t * dir[1]), float(c.c.z + s * t * dir[2])});
    }
    return eyes;
}

}  // namespace

TEST(BackfaceClusters, CulledClustersHaveOnlyBackFacingMembers) {
    std::mt19937 rng(41);
    std::uniform_real_distribution<float> u(-1, 1);
    std::size_t culled = 0, tested = 0, front = 0;
    for (float off : {0.0f, 1e4f, -5e4f, 1e5f}) {
        for (int k = 0; k < 60; ++k) {
            const Vec3 centre{off + 3 * u(rng), off * 0.5f + 3 * u(rng), 3 * u(rng)};
            const float spread = k % 3 == 0 ? 1e-3f : 1.0f;
            const float cone = (k % 4) * 0.3f + 0.05f;
            Mesh m = random_cluster(rng, centre, spread, 0.2f * spread, {u(rng), u(rng), u(rng)}, cone, 1 + k % 40);
            const BackfaceCluster c = make_triangle_cluster(m.vertices.data(), m.indices.data(), 0,
                                                            static_cast<std::uint32_t>(m.triangles()));
            EXPECT_EQ(c.first, 0u);
            EXPECT_EQ(c.count, m.triangles());
            for (Vec3 e : test_eyes(rng, c, centre, 6 * spread + 2, 80)) {
                ++tested;
                const bool back = cluster_backfacing(c, e), fr = cluster_frontfacing(c, e);
                ASSERT_FALSE(back && fr);
                culled += back;
                front += fr;
                // The float test's margin: culled only inside the stored cluster's exact volume.
                if (back) {
                    ASSERT_LE(cluster_value(c, e), 0.0) << "culled outside the culling volume (rounding)";
                }
                for (std::size_t t = 0; t < m.triangles(); ++t) {
                    double mag;
                    const double f = facing(m, t, e, mag);
                    if (back) {
                        ASSERT_LE(f, 1e-12 * mag) << "cluster culled with a front-facing member, offset " << off;
                    }
                    if (fr) {
                        ASSERT_GT(f, -1e-12 * mag) << "cluster front-facing with a back-facing member";
                    }
                }
            }
        }
    }
    EXPECT_GT(culled, tested / 10);
    EXPECT_GT(front, tested / 30);
}

TEST(BackfaceClusters, DegenerateAndNonFiniteClusters) {
    // All triangles zero-area: always back-facing (nothing is drawn); a flat cluster (one plane)
    // culls exactly the half-space behind it; a NaN member: never culled.
    Mesh z{{{1, 1, 1}, {1, 1, 1}, {2, 3, 4}, {5, 5, 5}, {5, 5, 5}, {5, 5, 5}}, {0, 1, 2, 3, 4, 5}};
    const BackfaceCluster cz = make_triangle_cluster(z.vertices.data(), z.indices.data(), 0, 2);
    EXPECT_TRUE(cluster_backfacing(cz, {100, -3, 7}));
    EXPECT_FALSE(cluster_frontfacing(cz, {100, -3, 7}));
    EXPECT_DOUBLE_EQ(culling_probability(cz, {{-1, -1, -1}, {1, 1, 1}}), 1.0);
    Mesh flat{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}, {0, 1, 2, 1, 3, 2}};
    const BackfaceCluster cf = make_triangle_cluster(flat.vertices.data(), flat.indices.data(), 0, 2);
    EXPECT_TRUE(cluster_backfacing(cf, {0.5f, 0.5f, -1}));
    EXPECT_TRUE(cluster_backfacing(cf, {50, -20, -1e-3f}));
    EXPECT_FALSE(cluster_backfacing(cf, {0.5f, 0.5f, 1e-3f}));
    EXPECT_TRUE(cluster_frontfacing(cf, {0.5f, 0.5f, 1}));
    EXPECT_NEAR(culling_probability(cf, {{-1, -1, -1}, {2, 2, 1}}), 0.5, 1e-6);
    Mesh bad = flat;
    bad.vertices[3].x = std::numeric_limits<float>::quiet_NaN();
    const BackfaceCluster cb = make_triangle_cluster(bad.vertices.data(), bad.indices.data(), 0, 2);
    EXPECT_FALSE(cluster_backfacing(cb, {0.5f, 0.5f, -1}));
    EXPECT_FALSE(cluster_frontfacing(cb, {0.5f, 0.5f, 1}));
    EXPECT_EQ(culling_probability(cb, {{-1, -1, -1}, {2, 2, 1}}), 0.0);
    const BackfaceCluster mb = merge_clusters(cb, cf);
    EXPECT_FALSE(cluster_backfacing(mb, {0.5f, 0.5f, -1}));
    EXPECT_FALSE(cluster_backfacing(cf, {0.5f, 0.5f, -std::numeric_limits<float>::infinity()}));
}

TEST(BackfaceClusters, CIsTheBestOfTheBoxCentreAndCorners) {
    std::mt19937 rng(42);
    std::uniform_real_distribution<float> u(-1, 1);
    for (int k = 0; k < 50; ++k) {
        const Vec3 centre{1e4f * (k % 3) + 2 * u(rng), 2 * u(rng), 2 * u(rng)};
        Mesh m = random_cluster(rng, centre, 1.0f, 0.3f, {u(rng), u(rng), u(rng)}, 0.4f, 10 + k);
        const std::uint32_t T = static_cast<std::uint32_t>(m.triangles());
        const BackfaceCluster c = make_triangle_cluster(m.vertices.data(), m.indices.data(), 0, T);
        const Bounds& b = c.box;
        std::vector<Vec3> cands{b.center()};
        for (int i = 0; i < 8; ++i)
            cands.push_back({(i & 1) ? b.max.x : b.min.x, (i & 2) ? b.max.y : b.min.y, (i & 4) ? b.max.z : b.min.z});
        double best = -1e300;
        for (Vec3 cand : cands)
            best = std::max(best, triangle_cluster_d(m.vertices.data(), m.indices.data(), 0, T, cand));
        const double chosen = triangle_cluster_d(m.vertices.data(), m.indices.data(), 0, T, c.c);
        EXPECT_EQ(chosen, best);
        EXPECT_TRUE(std::find_if(cands.begin(), cands.end(),
                                 [&](Vec3 v) { return v.x == c.c.x && v.y == c.c.y && v.z == c.c.z; }) != cands.end());
        EXPECT_LE(double(c.d), chosen);  // rounded down
        EXPECT_GE(double(c.d), chosen - 1e-6 * (1 + std::fabs(chosen)));
        // The box holds every vertex.
        for (const Vec3& v : m.vertices) {
            EXPECT_GE(v.x, b.min.x);
            EXPECT_LE(v.x, b.max.x);
        }
    }
}

TEST(BackfaceClusters, MergedCullImpliesBothChildrenCull) {
    std::mt19937 rng(43);
    std::uniform_real_distribution<float> u(-1, 1);
    std::size_t merged_culled = 0, merged_front = 0;
    for (int k = 0; k < 200; ++k) {
        const float off = (k % 4) * 3e4f;
        const Vec3 axis{u(rng), u(rng), u(rng)};
        const Vec3 ca{off + 2 * u(rng), 2 * u(rng), 2 * u(rng)}, cb{off + 2 * u(rng), 2 * u(rng), 2 * u(rng)};
        Mesh a = random_cluster(rng, ca, 0.5f, 0.2f, axis, 0.3f, 8);
        Mesh b = random_cluster(rng, cb, 0.5f, 0.2f, axis + Vec3{0.3f * u(rng), 0.3f * u(rng), 0.3f * u(rng)}, 0.3f, 8);
        const BackfaceCluster A = make_triangle_cluster(a.vertices.data(), a.indices.data(), 0, 8);
        BackfaceCluster B = make_triangle_cluster(b.vertices.data(), b.indices.data(), 0, 8);
        B.first = 8;
        const BackfaceCluster M = merge_clusters(A, B);
        EXPECT_EQ(M.first, 0u);
        EXPECT_EQ(M.count, 16u);
        // Exact arithmetic on the stored clusters: the merged volume lies in both children's.
        for (Vec3 e : test_eyes(rng, M, (ca + cb) * 0.5f, 8, 60)) {
            if (cluster_value(M, e) <= 0) {
                EXPECT_LE(cluster_value(A, e), 1e-9 * (1 + std::fabs(A.d))) << k;
                EXPECT_LE(cluster_value(B, e), 1e-9 * (1 + std::fabs(B.d))) << k;
            }
            if (cluster_backfacing(M, e)) {
                ++merged_culled;
                for (const Mesh* m : {&a, &b})
                    for (std::size_t t = 0; t < 8; ++t) {
                        double mag = 0;
                        EXPECT_LE(facing(*m, t, e, mag), 1e-12 * mag);
                    }
                EXPECT_TRUE(cluster_backfacing(A, e) || cluster_value(A, e) > -1e-5 * (1 + std::fabs(A.d)));
                EXPECT_TRUE(cluster_backfacing(B, e) || cluster_value(B, e) > -1e-5 * (1 + std::fabs(B.d)));
            }
            if (cluster_frontfacing(M, e)) {
                ++merged_front;
                EXPECT_TRUE(cluster_frontfacing(A, e));
                EXPECT_TRUE(cluster_frontfacing(B, e));
            }
        }
    }
    EXPECT_GT(merged_culled, 500u);
    EXPECT_GT(merged_front, 500u);
}

TEST(BackfaceClusters, CullingProbabilityHandCases) {
    BackfaceCluster c;
    // One plane z = 0 through c = 0, normal +z: culled for z <= 0.
    c.n_min = c.m_max = {0, 0, 1};
    c.d = 0;
    c.c = {0, 0, 0};
    EXPECT_DOUBLE_EQ(culling_probability(c, {{-1, -1, -1}, {1, 1, 1}}), 0.5);
    EXPECT_DOUBLE_EQ(culling_probability(c, {{-1, -1, -1}, {1, 1, 3}}), 0.25);
    EXPECT_DOUBLE_EQ(culling_probability(c, {{-1, -1, 1}, {1, 1, 3}}), 0.0);
    // n = -1, m = +1 on every axis: f(x) = |x|_1, the culling volume an octahedron of radius d.
    c.n_min = {-1, -1, -1};
    c.m_max = {1, 1, 1};
    c.d = 1;
    EXPECT_NEAR(culling_probability(c, {{-1, -1, -1}, {1, 1, 1}}), (4.0 / 3.0) / 8.0, 1e-12);
    EXPECT_NEAR(culling_probability(c, {{0, 0, 0}, {1, 1, 1}}), 1.0 / 6.0, 1e-12);
    EXPECT_NEAR(culling_probability(c, {{-2, -2, -2}, {2, 2, 2}}), (4.0 / 3.0) / 64.0, 1e-12);
    // Shifted c and an anisotropic volume: the octant x, y, z >= 0 of 2x + y + 4z <= 2 (a
    // simplex of volume 2^3 / (6 * 2 * 1 * 4)) in U = c + [0, 10]^3.
    c.c = {5, -3, 2};
    c.n_min = {-100, -100, -100};
    c.m_max = {2, 1, 4};
    c.d = 2;
    EXPECT_NEAR(culling_probability(c, {{5, -3, 2}, {15, 7, 12}}), (8.0 / 48.0) / 1000.0, 1e-12);
    // Box cut by the half-space: x + y <= 1 in [0, 1]^2 x [0, 1] (m_z = 0): volume 1/2.
    c.c = {0, 0, 0};
    c.n_min = {-100, -100, -100};
    c.m_max = {1, 1, 0};
    c.d = 1;
    EXPECT_NEAR(culling_probability(c, {{0, 0, 0}, {1, 1, 1}}), 0.5, 1e-12);
    // Empty viewpoint box.
    EXPECT_EQ(culling_probability(c, {{0, 0, 0}, {1, 1, 0}}), 0.0);
}

TEST(BackfaceClusters, CullingProbabilityMatchesMonteCarlo) {
    std::mt19937 rng(44);
    std::uniform_real_distribution<float> u(-1, 1);
    std::uniform_real_distribution<double> unit(0, 1);
    for (int k = 0; k < 12; ++k) {
        const Vec3 centre{3 * u(rng), 3 * u(rng), 3 * u(rng)};
        Mesh m = random_cluster(rng, centre, 1.0f, 0.3f, {u(rng), u(rng), u(rng)}, 0.1f + 0.1f * k, 20, k % 2 == 1);
        const BackfaceCluster c = make_triangle_cluster(m.vertices.data(), m.indices.data(), 0, 20);
        const Bounds U{centre - Vec3{4 + u(rng), 5 + u(rng), 3 + u(rng)},
                       centre + Vec3{4 + u(rng), 3 + u(rng), 5 + u(rng)}};
        const double p = culling_probability(c, U);
        const int N = 200000;
        int hits = 0;
        for (int i = 0; i < N; ++i) {
            const Vec3 e{float(U.min.x + unit(rng) * (U.max.x - U.min.x)),
                         float(U.min.y + unit(rng) * (U.max.y - U.min.y)),
                         float(U.min.z + unit(rng) * (U.max.z - U.min.z))};
            hits += cluster_value(c, e) <= 0;
        }
        const double q = double(hits) / N;
        const double sigma = std::sqrt(std::max(p * (1 - p), 1e-6) / N);
        EXPECT_NEAR(p, q, 5 * sigma + 1e-4) << "cluster " << k;
        if (k < 4 && k % 2 == 0) {
            EXPECT_GT(p, 0.05) << "narrow cones cull from a good part of U";
        }
    }
}

TEST(BackfaceClusters, MergePaysIsTheCostModel) {
    // Hand numbers: P(A) = P(B) = 0.5, 10 members each, tC / r = 2: threshold (5 + 5 - 2) / 20.
    EXPECT_TRUE(merge_pays(0.41, 0.5, 10, 0.5, 10, 2.0));
    EXPECT_FALSE(merge_pays(0.39, 0.5, 10, 0.5, 10, 2.0));
    EXPECT_TRUE(merge_pays(0.5, 0.5, 10, 0.5, 10, 0.0) == false);  // equal P, free tests: no gain
    EXPECT_TRUE(merge_pays(0.5, 0.5, 10, 0.5, 10, 0.01));          // equal P: saves one test
    EXPECT_FALSE(merge_pays(1.0, 1.0, 0, 1.0, 0, 5.0));
    // Against T(C) < T(A) + T(B) with T(X) = tC + (1 - P(X)) n_X r on a grid of values.
    std::mt19937 rng(45);
    std::uniform_real_distribution<double> p(0, 1), t(0, 20);
    std::uniform_int_distribution<int> n(1, 200);
    for (int k = 0; k < 20000; ++k) {
        const double pa = p(rng), pb = p(rng), pc = p(rng), tc = t(rng), r = 0.5 + p(rng);
        const int na = n(rng), nb = n(rng);
        const double TA = tc + (1 - pa) * na * r, TB = tc + (1 - pb) * nb * r, TC = tc + (1 - pc) * (na + nb) * r;
        const double margin = std::fabs(TC - (TA + TB));
        if (margin < 1e-9) continue;
        EXPECT_EQ(merge_pays(pc, pa, na, pb, nb, tc / r), TC < TA + TB);
    }
}

namespace {

// A closed UV sphere (radius r around centre), outward counter-clockwise; the pole rows hold
// zero-area triangles (two corners on the pole vertex).
Mesh sphere(Vec3 centre, float r, int stacks, int slices) {
    Mesh m;
    const double pi = 3.14159265358979323846;
    for (int i = 0; i <= stacks; ++i)
        for (int j = 0; j < slices; ++j) {
            const double th = pi * i / stacks, ph = 2 * pi * j / slices;
            m.vertices.push_back(centre + Vec3{float(r * std::sin(th) * std::cos(ph)),
                                               float(r * std::sin(th) * std::sin(ph)), float(r * std::cos(th))});
        }
    auto id = [&](int i, int j) {
        if (i == 0) return 0u;
        if (i == stacks) return static_cast<std::uint32_t>(stacks * slices);
        return static_cast<std::uint32_t>(i * slices + j % slices);
    };
    for (int i = 0; i < stacks; ++i)
        for (int j = 0; j < slices; ++j) {
            const std::uint32_t a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
            for (auto tri : {std::array<std::uint32_t, 3>{a, b, c}, std::array<std::uint32_t, 3>{a, c, d}}) {
                const Vec3 p0 = m.vertices[tri[0]], p1 = m.vertices[tri[1]], p2 = m.vertices[tri[2]];
                if (dot(cross(p1 - p0, p2 - p0), (p0 + p1 + p2) * (1.0f / 3) - centre) < 0) std::swap(tri[1], tri[2]);
                m.indices.insert(m.indices.end(), tri.begin(), tri.end());
            }
        }
    return m;
}

// A closed box [centre - h, centre + h]^3, each face a k x k grid of quads (two triangles
// each), outward counter-clockwise.
Mesh tessellated_box(Vec3 centre, float h, int k) {
    Mesh m;
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            const int b = (axis + 1) % 3, c = (axis + 2) % 3;
            const std::uint32_t base = static_cast<std::uint32_t>(m.vertices.size());
            for (int j = 0; j <= k; ++j)
                for (int i = 0; i <= k; ++i) {
                    float p[3];
                    p[axis] = side ? h : -h;
                    p[b] = -h + 2 * h * i / k;
                    p[c] = -h + 2 * h * j / k;
                    m.vertices.push_back(centre + Vec3{p[0], p[1], p[2]});
                }
            for (int j = 0; j < k; ++j)
                for (int i = 0; i < k; ++i) {
                    const std::uint32_t a = base + j * (k + 1) + i, bb = a + 1, cc = a + k + 2, d = a + k + 1;
                    // (e_b x e_c) = +e_axis: counter-clockwise seen from +axis.
                    if (side)
                        m.indices.insert(m.indices.end(), {a, bb, cc, a, cc, d});
                    else
                        m.indices.insert(m.indices.end(), {a, cc, bb, a, d, cc});
                }
        }
    return m;
}

void check_structure(const ClusterHierarchy& h, std::size_t members) {
    ASSERT_EQ(h.skip.size(), h.nodes.size());
    ASSERT_EQ(h.leaf_begin.size(), h.nodes.size());
    std::uint32_t next = 0;
    for (std::size_t l = 0; l < h.leaves.size(); ++l) {
        const BackfaceCluster& c = cluster_leaf(h, l);
        EXPECT_EQ(c.first, next);
        EXPECT_GE(c.count, 1u);
        next = c.first + c.count;
        EXPECT_EQ(h.leaf_begin[h.leaves[l]], l);
        EXPECT_EQ(h.leaf_end[h.leaves[l]], l + 1);
        EXPECT_EQ(h.skip[h.leaves[l]], h.leaves[l] + 1);
    }
    EXPECT_EQ(next, members);
    for (std::size_t i = 0; i < h.nodes.size(); ++i) {
        if (h.leaf_end[i] - h.leaf_begin[i] == 1) continue;
        const std::size_t a = i + 1, b = h.skip[a];
        ASSERT_LT(b, h.skip[i]);
        EXPECT_EQ(h.skip[b], h.skip[i]);
        EXPECT_EQ(h.leaf_begin[a], h.leaf_begin[i]);
        EXPECT_EQ(h.leaf_end[a], h.leaf_begin[b]);
        EXPECT_EQ(h.leaf_end[b], h.leaf_end[i]);
        EXPECT_EQ(h.nodes[i].first, h.nodes[a].first);
        EXPECT_EQ(h.nodes[i].count, h.nodes[a].count + h.nodes[b].count);
    }
    std::size_t r = 0;
    for (std::uint32_t root : h.roots) {
        EXPECT_EQ(root, r);
        r = h.skip[root];
    }
    EXPECT_EQ(r, h.nodes.size());
}

}  // namespace

TEST(BackfaceClusters, HierarchyOnAClosedMeshEqualsLeavesAloneAndTestsFewer) {
    EXPECT_THROW(build_triangle_clusters({{0, 0, 0}}, {0, 0}, 1.0, 8), Error);
    EXPECT_THROW(build_triangle_clusters({{0, 0, 0}}, {0, 0, 1}, 1.0, 8), Error);
    EXPECT_THROW(build_triangle_clusters({{0, 0, 0}}, {0, 0, 0}, 1.0, 0), Error);
    EXPECT_TRUE(build_triangle_clusters({}, {}, 1.0, 8).nodes.empty());
    std::mt19937 rng(46);
    std::uniform_real_distribution<float> u(-1, 1);
    for (int shape = 0; shape < 4; ++shape) {
        const bool box = shape >= 2;
        const float off = shape % 2 ? 5e4f : 0.0f;
        const Vec3 centre{off, -off * 0.3f, 1};
        const Mesh m = box ? tessellated_box(centre, 1.5f, 12) : sphere(centre, 2.0f, 24, 32);
        for (double tcr : {0.5, 4.0, 40.0}) {
            const ClusterHierarchy h = build_triangle_clusters(m.vertices, m.indices, tcr, 32);
            check_structure(h, m.triangles());
            ASSERT_EQ(h.indices.size(), m.indices.size());
            // A permutation of the input triangles.
            std::vector<std::uint32_t> seen(h.triangle_order);
            std::sort(seen.begin(), seen.end());
            for (std::size_t t = 0; t < seen.size(); ++t) ASSERT_EQ(seen[t], t);
            for (std::size_t t = 0; t < m.triangles(); ++t)
                for (int k = 0; k < 3; ++k) ASSERT_EQ(h.indices[3 * t + k], m.indices[3 * h.triangle_order[t] + k]);
            Mesh reordered{m.vertices, h.indices};
            std::size_t hier_tests = 0, leaf_tests = 0, cluster_culled = 0, tri_culled = 0, differ = 0;
            for (int k = 0; k < 200; ++k) {
                Vec3 dir{u(rng), u(rng), u(rng)};
                const float dist = k % 2 ? 3.0f : 20.0f;
                const Vec3 eye = centre + normalize(dir) * dist;
                std::vector<std::uint8_t> culled(cluster_leaf_count(h), 7);
                std::uint32_t tests = 0;
                cull_cluster_hierarchy(h, eye, culled.data(), tests);
                hier_tests += tests;
                leaf_tests += cluster_leaf_count(h);
                for (std::size_t l = 0; l < cluster_leaf_count(h); ++l) {
                    const BackfaceCluster& c = cluster_leaf(h, l);
                    ASSERT_LE(culled[l], 1);
                    const bool alone = cluster_backfacing(c, eye);
                    ASSERT_FALSE(alone && !culled[l]) << "the hierarchy lost a cull";
                    if (culled[l] && !alone) {
                        ++differ;  // only within float rounding of the leaf's boundary
                        EXPECT_GT(cluster_value(c, eye), -1e-5 * (1 + std::fabs(c.d)));
                    }
                    if (culled[l]) {
                        cluster_culled += c.count;
                        for (std::size_t t = c.first; t < c.first + c.count; ++t) {
                            double mag;
                            ASSERT_LE(facing(reordered, t, eye, mag), 1e-12 * mag);
                        }
                    }
                }
                std::vector<std::uint8_t> per(m.triangles());
                cull_backfacing_triangles_scalar(reordered.vertices.data(), reordered.indices.data(), m.triangles(),
                                                 eye, per.data());
                tri_culled += std::accumulate(per.begin(), per.end(), std::size_t{0});
            }
            EXPECT_EQ(differ, 0u);
            if (box) {
                EXPECT_LT(hier_tests, leaf_tests) << "tC/r " << tcr;      // flat faces: whole subtrees decide at once
                EXPECT_EQ(cluster_culled, tri_culled) << "tC/r " << tcr;  // flat faces cull exactly
            } else {
                EXPECT_GT(cluster_culled, tri_culled / 4) << "tC/r " << tcr;
                EXPECT_LE(cluster_culled, tri_culled);
            }
            std::printf(
                "[ info ] %s offset %g tC/r %g: %zu leaves, %zu nodes, tests/frame %.1f (leaves alone %.1f), "
                "culled %.3f of triangles (per-triangle test %.3f)\n",
                box ? "box" : "sphere", off, tcr, cluster_leaf_count(h), h.nodes.size(), hier_tests / 200.0,
                leaf_tests / 200.0, cluster_culled / (200.0 * m.triangles()), tri_culled / (200.0 * m.triangles()));
        }
    }
}

TEST(BackfaceClusters, TriangleSoupWithoutSharedVerticesStillClusters) {
    std::mt19937 rng(47);
    Mesh soup;
    const Mesh s = sphere({0, 0, 0}, 1.0f, 12, 16);
    for (std::uint32_t i : s.indices) {
        soup.indices.push_back(static_cast<std::uint32_t>(soup.vertices.size()));
        soup.vertices.push_back(s.vertices[i]);
    }
    const ClusterHierarchy h = build_triangle_clusters(soup.vertices, soup.indices, 4.0, 16);
    check_structure(h, soup.triangles());
    EXPECT_LT(cluster_leaf_count(h), soup.triangles() / 4);
}
