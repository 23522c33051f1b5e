// Bounding volumes and their frustum tests (patchcull/objects/bounding_volumes.h), against ground truth:
// points sampled inside each volume (in double, so they are points of the exact volume) are
// tested against the clip volume of the float matrix in double. "outside" must never be reported
// for a volume with such a point inside; "inside" only when every sampled point is inside. Random
// frusta near the origin and 1e4 / 1e5 away, volumes touching planes within float rounding,
// degenerate volumes; scalar == SIMD on every compiled target; masking and coherence never change
// an answer; meta-BVs; detail culling against an explicit projection.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "patchcull/core/frustum.h"
#include "patchcull/core/ground_truth.h"
#include "patchcull/objects/bounding_volumes.h"

using namespace patchcull;

namespace {

constexpr double kPiD = 3.14159265358979323846;

struct P3 {
    double x = 0, y = 0, z = 0;
};
P3 operator+(P3 a, P3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
P3 operator-(P3 a, P3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
P3 operator*(P3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dotp(P3 a, P3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
P3 p3(Vec3 v) { return {v.x, v.y, v.z}; }
double comp(P3 a, int i) { return i == 0 ? a.x : i == 1 ? a.y : a.z; }

// The clip-volume test of ground_truth.h (-w<=x<=w, -w<=y<=w, 0<=z<=w, w>0) for a double point.
bool in_clip(const Mat4& m, P3 p) {
    double c[4];
    for (int r = 0; r < 4; ++r) c[r] = m.at(r, 0) * p.x + m.at(r, 1) * p.y + m.at(r, 2) * p.z + double(m.at(r, 3));
    return c[3] > 0 && -c[3] <= c[0] && c[0] <= c[3] && -c[3] <= c[1] && c[1] <= c[3] && 0 <= c[2] && c[2] <= c[3];
}
// Inside every plane (w >= 0 follows from left + right).
bool in_all_planes(const Mat4& m, P3 p) {
    double c[4];
    for (int r = 0; r < 4; ++r) c[r] = m.at(r, 0) * p.x + m.at(r, 1) * p.y + m.at(r, 2) * p.z + double(m.at(r, 3));
    return -c[3] <= c[0] && c[0] <= c[3] && -c[3] <= c[1] && c[1] <= c[3] && 0 <= c[2] && c[2] <= c[3];
}

struct Camera {
    Mat4 world_to_clip;
    FrustumPlanes planes;
    P3 eye, dir;
    double near = 0, far = 0, scale = 1;
};

// A random perspective camera around offset (scale: the scene's size).
Camera random_camera(std::mt19937& rng, P3 offset, double scale) {
    std::uniform_real_distribution<double> u(-1, 1), unit(0, 1);
    Camera cam;
    cam.scale = scale;
    const P3 eye = offset + P3{u(rng), u(rng), u(rng)} * scale;
    P3 dir{u(rng), u(rng), u(rng)};
    if (dotp(dir, dir) < 1e-3) dir = {0, 0, -1};
    dir = dir * (1 / std::sqrt(dotp(dir, dir)));
    const Vec3 eyef{float(eye.x), float(eye.y), float(eye.z)};
    const Vec3 target{float(eye.x + dir.x * scale), float(eye.y + dir.y * scale), float(eye.z + dir.z * scale)};
    const float fovy = float((20 + 90 * unit(rng)) * kPiD / 180);
    const float aspect = float(0.5 + 1.5 * unit(rng));
    cam.near = scale * (0.01 + 0.2 * unit(rng));
    cam.far = cam.near * (5 + 200 * unit(rng));
    cam.world_to_clip = perspective(fovy, aspect, float(cam.near), float(cam.far)) * look_at(eyef, target, {0, 1, 0});
    cam.planes = make_frustum_planes(cam.world_to_clip, ClipDepth::zero_to_one);
    cam.eye = p3(eyef);
    cam.dir = dir;
    return cam;
}

// A random centre around the frustum: along the view direction from behind the eye to past the
// far plane, spread sideways about as wide as the frustum there.
P3 random_centre(std::mt19937& rng, const Camera& cam) {
    std::uniform_real_distribution<double> u(-1, 1), unit(0, 1);
    const double t = -0.2 * cam.far + 1.5 * cam.far * unit(rng) * unit(rng);
    const double spread = 1.5 * (std::fabs(t) + cam.near);
    return cam.eye + cam.dir * t + P3{u(rng), u(rng), u(rng)} * spread;
}

double random_size(std::mt19937& rng, const Camera& cam) {
    std::uniform_real_distribution<double> unit(0, 1);
    const int kind = int(unit(rng) * 10);
    if (kind == 0) return 0;                                // zero-size
    if (kind == 1) return cam.far * (1 + unit(rng));        // huge: may hold the eye / the frustum
    return cam.near * std::pow(10.0, 3 * unit(rng) - 1.5);  // tiny to large
}

Vec3 to_f(P3 p) { return {float(p.x), float(p.y), float(p.z)}; }

Sphere random_sphere(std::mt19937& rng, const Camera& cam) {
    return {to_f(random_centre(rng, cam)), float(random_size(rng, cam))};
}

Bounds random_box(std::mt19937& rng, const Camera& cam) {
    std::uniform_real_distribution<double> unit(0, 1);
    const P3 c = random_centre(rng, cam);
    const double s = random_size(rng, cam);
    P3 h{s * unit(rng), s * unit(rng), s * unit(rng)};
    if (unit(rng) < 0.1) h.y = 0;  // flat
    Bounds b;
    b.min = to_f(c - h);
    b.max = to_f(c + h);
    return b;
}

Obb random_obb(std::mt19937& rng, const Camera& cam) {
    std::uniform_real_distribution<double> u(-1, 1), unit(0, 1);
    Obb o;
    o.center = to_f(random_centre(rng, cam));
    const double s = random_size(rng, cam);
    // Random rotation from a random unit quaternion.
    double q[4] = {u(rng), u(rng), u(rng), u(rng)};
    double ql = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (ql < 1e-3) q[0] = ql = 1;
    for (double& v : q) v /= ql;
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                            {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                            {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
    for (int i = 0; i < 3; ++i) o.axes[i] = {float(r[0][i]), float(r[1][i]), float(r[2][i])};
    for (int i = 0; i < 3; ++i) o.half_extents[i] = float(s * unit(rng));
    if (unit(rng) < 0.1) o.half_extents[2] = 0;  // flat
    return o;
}

// Points of each volume, in double: extremes (surface, corners) and random interior points.
std::vector<P3> sample(std::mt19937& rng, const Sphere& s, int n) {
    std::normal_distribution<double> g;
    std::uniform_real_distribution<double> unit(0, 1);
    std::vector<P3> pts;
    for (int i = 0; i < n; ++i) {
        P3 d{g(rng), g(rng), g(rng)};
        const double l = std::sqrt(dotp(d, d));
        if (l == 0) continue;
        const double rr = i % 2 ? double(s.radius) : double(s.radius) * std::cbrt(unit(rng));
        pts.push_back(p3(s.center) + d * (rr / l));
    }
    return pts;
}
std::vector<P3> sample(std::mt19937& rng, const Bounds& b, int n) {
    std::uniform_real_distribution<double> unit(0, 1);
    std::vector<P3> pts;
    pts.reserve(8 + static_cast<std::size_t>(n));
    for (int i = 0; i < 8; ++i)
        pts.push_back({(i & 1) ? b.max.x : b.min.x, (i & 2) ? b.max.y : b.min.y, (i & 4) ? b.max.z : b.min.z});
    for (int i = 0; i < n; ++i) {
        double t[3] = {unit(rng), unit(rng), unit(rng)};
        if (i % 2) t[i % 3] = std::round(t[i % 3]);  // on a face
        pts.push_back({b.min.x + (double(b.max.x) - b.min.x) * t[0], b.min.y + (double(b.max.y) - b.min.y) * t[1],
                       b.min.z + (double(b.max.z) - b.min.z) * t[2]});
    }
    return pts;
}
std::vector<P3> sample(std::mt19937& rng, const Obb& o, int n) {
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<P3> pts;
    pts.reserve(8 + static_cast<std::size_t>(n));
    auto at = [&](double t0, double t1, double t2) {
        const double t[3] = {t0, t1, t2};
        P3 p = p3(o.center);
        for (int i = 0; i < 3; ++i) p = p + p3(o.axes[i]) * (t[i] * o.half_extents[i]);
        return p;
    };
    for (int i = 0; i < 8; ++i) pts.push_back(at((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1));
    for (int i = 0; i < n; ++i) {
        double t[3] = {u(rng), u(rng), u(rng)};
        if (i % 2) t[i % 3] = t[i % 3] < 0 ? -1 : 1;
        pts.push_back(at(t[0], t[1], t[2]));
    }
    return pts;
}

// Checks one answer against the samples; returns false (with a message) on a violation.
template <class V>
void check_against_samples(const Camera& cam, const V& v, Containment c, const std::vector<P3>& pts, const char* what) {
    if (c == Containment::outside) {
        for (const P3& p : pts)
            ASSERT_FALSE(in_clip(cam.world_to_clip, p)) << what << ": outside, but the point (" << p.x << ", " << p.y
                                                        << ", " << p.z << ") is inside the frustum";
    } else if (c == Containment::inside) {
        for (const P3& p : pts)
            ASSERT_TRUE(in_all_planes(cam.world_to_clip, p))
                << what << ": inside, but the point (" << p.x << ", " << p.y << ", " << p.z << ") is outside a plane";
    }
    (void)v;
}

struct Tally {
    int outside = 0, intersecting = 0, inside = 0;
    void add(Containment c) {
        (c == Containment::outside ? outside : c == Containment::inside ? inside : intersecting)++;
    }
};

void run_ground_truth(P3 offset, double scale, unsigned seed) {
    std::mt19937 rng(seed);
    Tally ts, ta, to;
    for (int f = 0; f < 40; ++f) {
        const Camera cam = random_camera(rng, offset, scale);
        for (int i = 0; i < 60; ++i) {
            std::uint32_t tests = 0;
            PlaneCullState st;
            const Sphere s = random_sphere(rng, cam);
            const Containment cs = classify_sphere(cam.planes, s, st, tests);
            ts.add(cs);
            check_against_samples(cam, s, cs, sample(rng, s, 200), "sphere");

            const Bounds b = random_box(rng, cam);
            st = {};
            const Containment cb = classify_aabb(cam.planes, b, st, tests);
            ta.add(cb);
            check_against_samples(cam, b, cb, sample(rng, b, 200), "aabb");
            std::uint32_t ct = 0;
            ASSERT_EQ(classify_aabb_corners(cam.planes, b, ct), cb) << "corners test differs from n/p-vertex";

            const Obb o = random_obb(rng, cam);
            st = {};
            const Containment co = classify_obb(cam.planes, o, st, tests);
            to.add(co);
            check_against_samples(cam, o, co, sample(rng, o, 200), "obb");
            if (::testing::Test::HasFatalFailure()) return;
        }
        // Volumes built from point clouds, checked with the enclosed points themselves
        // (any_point_in_clip_volume, double precision).
        for (int i = 0; i < 20; ++i) {
            const P3 c = random_centre(rng, cam);
            const double s = random_size(rng, cam);
            std::uniform_real_distribution<double> u(-1, 1);
            const int n = 1 + i * 3;
            std::vector<Vec3> pts;
            pts.reserve(n);
            for (int k = 0; k < n; ++k) pts.push_back(to_f(c + P3{u(rng), (i % 4 == 0) ? 0.0 : u(rng), u(rng)} * s));
            const bool any_in = any_point_in_clip_volume(cam.world_to_clip, pts.data(), pts.size());
            const bool all_in =
                std::all_of(pts.begin(), pts.end(), [&](Vec3 p) { return in_all_planes(cam.world_to_clip, p3(p)); });
            std::uint32_t t = 0;
            PlaneCullState st;
            const Containment r[3] = {classify_sphere(cam.planes, sphere_of_points(pts.data(), pts.size()), st, t),
                                      classify_aabb(cam.planes, aabb_of_points(pts.data(), pts.size()), st = {}, t),
                                      classify_obb(cam.planes, obb_of_points(pts.data(), pts.size()), st = {}, t)};
            for (Containment x : r) {
                if (any_in) {
                    ASSERT_NE(x, Containment::outside) << "a volume of points, one of them in the frustum, culled";
                }
                if (!all_in) {
                    ASSERT_NE(x, Containment::inside) << "a volume of points, one of them outside, inside";
                }
            }
        }
    }
    // The mix must exercise all three answers (else the test shows nothing).
    for (const Tally* t : {&ts, &ta, &to}) {
        EXPECT_GT(t->outside, 100);
        EXPECT_GT(t->intersecting, 100);
        EXPECT_GT(t->inside, 50);
    }
}

TEST(BoundingVolumes, GroundTruthNearOrigin) { run_ground_truth({0, 0, 0}, 10, 1); }
TEST(BoundingVolumes, GroundTruthFar1e4) { run_ground_truth({1.3e4, -0.7e4, 2.1e4}, 50, 2); }
TEST(BoundingVolumes, GroundTruthFar1e5) { run_ground_truth({-0.9e5, 1e5, 0.4e5}, 200, 3); }

// Volumes that touch a frustum plane within float rounding: a sphere (or box corner) placed at
// signed distance delta (a few ulps, either side) outside the middle of a frustum face. The point
// of the volume nearest to the face is checked in double; when it is inside the frustum the volume
// must not be outside. Far from the origin this is where unpadded float tests fail.
void run_touching(P3 offset, double scale, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1), unit(0, 1);
    int inside_points = 0;
    for (int f = 0; f < 30; ++f) {
        const Camera cam = random_camera(rng, offset, scale);
        Mat4 inv;
        ASSERT_TRUE(invert(cam.world_to_clip, inv));
        for (int k = 0; k < 6; ++k) {
            // The exact plane of the float matrix, in double.
            const Mat4& m = cam.world_to_clip;
            auto row = [&](int r, int c) { return double(m.at(r, c)); };
            double pl[4];
            for (int c = 0; c < 4; ++c) {
                const double x = row(0, c), y = row(1, c), z = row(2, c), w = row(3, c);
                const double vals[6] = {w + x, w - x, w + y, w - y, z, w - z};
                pl[c] = vals[k];
            }
            const double nl = std::sqrt(pl[0] * pl[0] + pl[1] * pl[1] + pl[2] * pl[2]);
            const P3 n{pl[0] / nl, pl[1] / nl, pl[2] / nl};  // inward unit normal
            for (int i = 0; i < 40; ++i) {
                // A point on face k near its middle: NDC of the face centre with a random offset.
                double ndc[3] = {0.6 * u(rng), 0.6 * u(rng), 0.3 + 0.4 * unit(rng)};
                const int a = k / 2;
                if (a < 2)
                    ndc[a] = (k % 2) ? 1 : -1;
                else
                    ndc[2] = (k % 2) ? 1 : 0;
                const Vec4 h = inv * Vec4{float(ndc[0]), float(ndc[1]), float(ndc[2]), 1};
                P3 q{double(h.x) / h.w, double(h.y) / h.w, double(h.z) / h.w};
                // Project q onto the plane exactly (double).
                const double dq = (pl[0] * q.x + pl[1] * q.y + pl[2] * q.z + pl[3]) / nl;
                q = q - n * dq;
                const double ulp = 1.2e-7 * std::max({std::fabs(q.x), std::fabs(q.y), std::fabs(q.z), cam.far});
                const double delta = ulp * 8 * u(rng);
                const double r = cam.near * std::pow(10.0, 2 * unit(rng) - 1);
                // Sphere beyond the face: centre at distance r + delta outside it.
                Sphere s{to_f(q - n * (r + delta)), float(r)};
                const P3 nearest = p3(s.center) + n * double(s.radius);
                PlaneCullState st;
                std::uint32_t t = 0;
                if (in_clip(cam.world_to_clip, nearest)) {
                    ++inside_points;
                    ASSERT_NE(classify_sphere(cam.planes, s, st, t), Containment::outside)
                        << "sphere touching plane " << k << " culled; delta " << delta;
                    std::uint32_t t2 = 0;
                    Containment one;
                    classify_spheres_simd(cam.planes, &s, 1, &one);
                    ASSERT_NE(one, Containment::outside);
                    (void)t2;
                }
                // Box whose p-vertex for plane k sits at q + delta n (beyond or inside the face).
                Bounds b;
                const double size = r;
                double lo[3], hi[3];
                for (int c = 0; c < 3; ++c) {
                    const double pc = comp(q, c) + comp(n, c) * delta;
                    if (pl[c] >= 0)
                        hi[c] = pc, lo[c] = pc - size;
                    else
                        lo[c] = pc, hi[c] = pc + size;
                }
                b.min = {float(lo[0]), float(lo[1]), float(lo[2])};
                b.max = {float(hi[0]), float(hi[1]), float(hi[2])};
                bool any_in = false;
                for (int c = 0; c < 8 && !any_in; ++c)
                    any_in = in_clip(cam.world_to_clip, {(c & 1) ? b.max.x : b.min.x, (c & 2) ? b.max.y : b.min.y,
                                                         (c & 4) ? b.max.z : b.min.z});
                if (any_in) {
                    ++inside_points;
                    st = {};
                    ASSERT_NE(classify_aabb(cam.planes, b, st, t), Containment::outside) << "box touching plane " << k;
                    Obb o = obb_of_aabb(b);
                    st = {};
                    ASSERT_NE(classify_obb(cam.planes, o, st, t), Containment::outside) << "obb touching plane " << k;
                }
            }
        }
    }
    EXPECT_GT(inside_points, 1000);
}

TEST(BoundingVolumes, TouchingPlanesNearOrigin) { run_touching({0, 0, 0}, 10, 11); }
TEST(BoundingVolumes, TouchingPlanesFar1e5) { run_touching({1e5, -0.6e5, 0.8e5}, 100, 12); }

// Eye inside the volume, volumes around the near plane and behind the eye, degenerate volumes.
TEST(BoundingVolumes, SpecialCases) {
    const Mat4 m = perspective(float(kPiD / 2), 1, 1, 100) * look_at({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
    const FrustumPlanes planes = make_frustum_planes(m, ClipDepth::zero_to_one);
    std::uint32_t t = 0;
    auto sphere = [&](Sphere s) {
        PlaneCullState st;
        return classify_sphere(planes, s, st, t);
    };
    auto box = [&](Bounds b) {
        PlaneCullState st;
        return classify_aabb(planes, b, st, t);
    };
    auto obb = [&](Obb o) {
        PlaneCullState st;
        return classify_obb(planes, o, st, t);
    };
    // Eye inside: intersecting (the near plane cuts the volume).
    EXPECT_EQ(sphere({{0, 0, 0}, 5}), Containment::intersecting);
    EXPECT_EQ(box({{-5, -5, -5}, {5, 5, 5}}), Containment::intersecting);
    EXPECT_EQ(obb(obb_of_aabb({{-5, -5, -5}, {5, 5, 5}})), Containment::intersecting);
    // Straddling the near plane (z = -1) in front of the eye.
    EXPECT_EQ(box({{-0.1f, -0.1f, -1.5f}, {0.1f, 0.1f, -0.5f}}), Containment::intersecting);
    // Between eye and near plane, or behind the eye: outside.
    EXPECT_EQ(sphere({{0, 0, -0.5f}, 0.2f}), Containment::outside);
    EXPECT_EQ(box({{-0.1f, -0.1f, 1}, {0.1f, 0.1f, 3}}), Containment::outside);
    EXPECT_EQ(obb(obb_of_aabb({{-0.1f, -0.1f, 1}, {0.1f, 0.1f, 3}})), Containment::outside);
    // Behind the eye but huge: reaches into the frustum.
    EXPECT_EQ(sphere({{0, 0, 10}, 20}), Containment::intersecting);
    // Fully inside.
    EXPECT_EQ(sphere({{0, 0, -50}, 1}), Containment::inside);
    EXPECT_EQ(box({{-1, -1, -51}, {1, 1, -49}}), Containment::inside);
    // Zero-size and zero-radius volumes: a point.
    EXPECT_EQ(sphere({{0, 0, -50}, 0}), Containment::inside);
    EXPECT_EQ(box({{0, 0, -50}, {0, 0, -50}}), Containment::inside);
    EXPECT_EQ(box({{0, 0, 50}, {0, 0, 50}}), Containment::outside);
    // Flat box straddling the left plane.
    EXPECT_EQ(box({{-60, -1, -50}, {-40, 1, -50}}), Containment::intersecting);
    // Empty volumes: outside, no plane test.
    t = 0;
    EXPECT_EQ(sphere(sphere_of_points(nullptr, 0)), Containment::outside);
    EXPECT_EQ(box(aabb_of_points(nullptr, 0)), Containment::outside);
    EXPECT_EQ(obb(obb_of_points(nullptr, 0)), Containment::outside);
    std::uint32_t ct = 0;
    EXPECT_EQ(classify_aabb_corners(planes, aabb_of_points(nullptr, 0), ct), Containment::outside);
    EXPECT_EQ(t + ct, 0u);
    EXPECT_EQ(sphere(sphere_of_aabb(aabb_of_points(nullptr, 0))), Containment::outside);
    EXPECT_EQ(obb(obb_of_aabb(aabb_of_points(nullptr, 0))), Containment::outside);
    // NaN: never outside.
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_NE(sphere({{nan, 0, -50}, 1}), Containment::outside);
    EXPECT_NE(box({{nan, 0, -50}, {1, 1, 1}}), Containment::outside);
    EXPECT_STREQ(containment_name(Containment::outside), "outside");
    EXPECT_STREQ(containment_name(Containment::intersecting), "intersecting");
    EXPECT_STREQ(containment_name(Containment::inside), "inside");
}

// ---- enclosing volumes ---------------------------------------------------------------------------

bool sphere_holds(const Sphere& s, Vec3 p) {
    const P3 d = p3(p) - p3(s.center);
    return dotp(d, d) <= double(s.radius) * double(s.radius);
}
bool box_holds(const Bounds& b, Vec3 p) {
    return b.min.x <= p.x && p.x <= b.max.x && b.min.y <= p.y && p.y <= b.max.y && b.min.z <= p.z && p.z <= b.max.z;
}
// Coordinates of p in the OBB's float axes, solved in long double.
bool obb_holds(const Obb& o, Vec3 p) {
    using LD = long double;
    const LD a[3][3] = {{o.axes[0].x, o.axes[1].x, o.axes[2].x},
                        {o.axes[0].y, o.axes[1].y, o.axes[2].y},
                        {o.axes[0].z, o.axes[1].z, o.axes[2].z}};
    const LD det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                   a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                   a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    const LD d[3] = {LD(p.x) - o.center.x, LD(p.y) - o.center.y, LD(p.z) - o.center.z};
    for (int i = 0; i < 3; ++i) {  // Cramer's rule: replace column i by d
        LD m[3][3];
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) m[r][c] = c == i ? d[r] : a[r][c];
        const LD di = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                      m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                      m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
        if (std::fabs(di / det) > LD(o.half_extents[i])) return false;
    }
    return true;
}

TEST(BoundingVolumes, EnclosingVolumesHoldEveryPoint) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1, 1), unit(0, 1);
    for (int trial = 0; trial < 300; ++trial) {
        const double off = trial % 3 == 0 ? 0 : trial % 3 == 1 ? 1e4 : 1e5;
        const P3 o{off * u(rng), off * u(rng), off};
        const double size = std::pow(10.0, 4 * unit(rng) - 2);
        const int kind = trial % 6;  // 0 cloud, 1 stretched, 2 collinear, 3 coplanar, 4 one point, 5 duplicates
        const int n = kind == 4 ? 1 : 1 + int(unit(rng) * 300);
        const P3 dir{u(rng), u(rng), u(rng)}, dir2{u(rng), u(rng), u(rng)};
        std::vector<Vec3> pts;
        for (int i = 0; i < n; ++i) {
            P3 p;
            switch (kind) {
                case 0:
                    p = o + P3{u(rng), u(rng), u(rng)} * size;
                    break;
                case 1:
                    p = o + dir * (10 * size * u(rng)) + P3{u(rng), u(rng), u(rng)} * (0.1 * size);
                    break;
                case 2:
                    p = o + dir * (size * u(rng));
                    break;
                case 3:
                    p = o + dir * (size * u(rng)) + dir2 * (size * u(rng));
                    break;
                default:
                    p = o;
                    break;
            }
            pts.push_back(to_f(p));
        }
        const Sphere s = sphere_of_points(pts.data(), pts.size());
        const Bounds b = aabb_of_points(pts.data(), pts.size());
        const Obb ob = obb_of_points(pts.data(), pts.size());
        const Sphere sb = sphere_of_aabb(b);
        const Obb obb_b = obb_of_aabb(b);
        for (const Vec3& p : pts) {
            ASSERT_TRUE(sphere_holds(s, p)) << "trial " << trial;
            ASSERT_TRUE(box_holds(b, p));
            ASSERT_TRUE(obb_holds(ob, p)) << "trial " << trial << " kind " << kind;
            ASSERT_TRUE(sphere_holds(sb, p));
            ASSERT_TRUE(obb_holds(obb_b, p));
        }
        // Every corner of the box is in its sphere and OBB.
        for (int c = 0; c < 8; ++c) {
            const Vec3 p{(c & 1) ? b.max.x : b.min.x, (c & 2) ? b.max.y : b.min.y, (c & 4) ? b.max.z : b.min.z};
            ASSERT_TRUE(sphere_holds(sb, p));
            ASSERT_TRUE(obb_holds(obb_b, p));
        }
        // Tightness: Ritter's sphere is at most ~5% above the minimal one's lower bound (half the
        // largest pairwise distance is <= the minimal radius); the sphere of the box is tight.
        double diam2 = 0;
        for (std::size_t i = 0; i < pts.size(); i += 7)
            for (std::size_t j = 0; j < pts.size(); ++j)
                diam2 = std::max(diam2, dotp(p3(pts[i]) - p3(pts[j]), p3(pts[i]) - p3(pts[j])));
        EXPECT_LE(s.radius, 1.2 * std::sqrt(sb.radius * double(sb.radius)) + 1e-6 * (off + size));
        EXPECT_GE(s.radius, 0.5 * std::sqrt(diam2) * (1 - 1e-6));
        // The PCA box never has more volume than the axis-aligned one; on stretched clouds much less.
        const double vol_obb = double(ob.half_extents[0]) * ob.half_extents[1] * ob.half_extents[2];
        const double vol_aabb = double(obb_b.half_extents[0]) * obb_b.half_extents[1] * obb_b.half_extents[2];
        EXPECT_LE(vol_obb, vol_aabb * (1 + 1e-5));
        if (kind == 2 || kind == 4 || kind == 5) {  // collinear or a point: two extents ~0
            float h[3] = {ob.half_extents[0], ob.half_extents[1], ob.half_extents[2]};
            std::sort(h, h + 3);
            EXPECT_LE(h[1], 1e-5 * size + 1e-6 * off) << "collinear points, trial " << trial;
        }
        // Axes orthonormal.
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) EXPECT_NEAR(dot(ob.axes[i], ob.axes[j]), i == j ? 1.0 : 0.0, 1e-6);
    }
}

TEST(BoundingVolumes, ObbOfStretchedCloudIsTighterThanAabb) {
    std::mt19937 rng(6);
    std::uniform_real_distribution<double> u(-1, 1);
    const P3 dir = P3{1, 1, 1} * (1 / std::sqrt(3.0));
    std::vector<Vec3> pts;
    pts.reserve(500);
    for (int i = 0; i < 500; ++i) pts.push_back(to_f(dir * (10 * u(rng)) + P3{u(rng), u(rng), u(rng)} * 0.2));
    const Obb ob = obb_of_points(pts.data(), pts.size());
    const Obb ab = obb_of_aabb(aabb_of_points(pts.data(), pts.size()));
    const double vol_obb = double(ob.half_extents[0]) * ob.half_extents[1] * ob.half_extents[2];
    const double vol_aabb = double(ab.half_extents[0]) * ab.half_extents[1] * ab.half_extents[2];
    EXPECT_LT(vol_obb, 0.1 * vol_aabb);
    EXPECT_NEAR(std::fabs(dot(ob.axes[0], to_f(dir))), 1.0, 1e-3);  // the main axis follows the cloud
}

TEST(BoundingVolumes, TransformedAabbHoldsTheTransformedBox) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1, 1), unit(0, 1);
    for (int trial = 0; trial < 500; ++trial) {
        const double off = trial % 2 ? 1e5 : 10;
        Mat4 m;
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) m.at(r, c) = float(2 * u(rng));
        for (int r = 0; r < 3; ++r) m.at(r, 3) = float(off * u(rng));
        Bounds b;
        const P3 c{u(rng), u(rng), u(rng)};
        const double s = unit(rng) * (trial % 5 == 0 ? 0 : 3);
        b.min = to_f(c - P3{s, s * unit(rng), s});
        b.max = to_f(c + P3{s * unit(rng), s, s});
        const Bounds t = transformed_aabb(b, m);
        P3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
        for (int k = 0; k < 8; ++k) {
            const P3 p{(k & 1) ? b.max.x : b.min.x, (k & 2) ? b.max.y : b.min.y, (k & 4) ? b.max.z : b.min.z};
            P3 q;
            double* qc = &q.x;
            for (int r = 0; r < 3; ++r)
                qc[r] = m.at(r, 0) * p.x + m.at(r, 1) * p.y + m.at(r, 2) * p.z + double(m.at(r, 3));
            ASSERT_TRUE(t.min.x <= q.x && q.x <= t.max.x && t.min.y <= q.y && q.y <= t.max.y && t.min.z <= q.z &&
                        q.z <= t.max.z)
                << "trial " << trial;
            lo = {std::min(lo.x, q.x), std::min(lo.y, q.y), std::min(lo.z, q.z)};
            hi = {std::max(hi.x, q.x), std::max(hi.y, q.y), std::max(hi.z, q.z)};
        }
        // Tight: the exact box of the transformed corners, up to float rounding.
        const double tol = 1e-6 * (off + 10);
        EXPECT_NEAR(t.min.x, lo.x, tol);
        EXPECT_NEAR(t.max.y, hi.y, tol);
        EXPECT_NEAR(t.max.z, hi.z, tol);
    }
    Bounds empty = aabb_of_points(nullptr, 0);
    const Bounds te = transformed_aabb(empty, Mat4{});
    EXPECT_GT(te.min.x, te.max.x);
}

TEST(BoundingVolumes, GrowBoundsRoundsOutwards) {
    std::mt19937 rng(8);
    std::uniform_real_distribution<double> u(-1, 1), unit(0, 1);
    int rounded = 0;
    for (int i = 0; i < 2000; ++i) {
        const double off = i % 2 ? 1e5 : 1;
        const Vec3 c = to_f(P3{u(rng), u(rng), u(rng)} * off);
        const Bounds b{c, c + Vec3{float(unit(rng)), 0, float(unit(rng))}};
        const float m = float(unit(rng) * 0.01);
        const Bounds g = grow_bounds(b, m);
        const float* lo = &g.min.x;
        const float* hi = &g.max.x;
        const float* blo = &b.min.x;
        const float* bhi = &b.max.x;
        for (int a = 0; a < 3; ++a) {
            ASSERT_LE(double(lo[a]), double(blo[a]) - m);
            ASSERT_GE(double(hi[a]), double(bhi[a]) + m);
            ASSERT_LE(double(hi[a]) - (double(bhi[a]) + m), std::fabs(double(bhi[a]) + m) * 1.2e-7 + 1e-30);
            if (blo[a] - m > double(blo[a]) - m) ++rounded;  // where plain float subtraction falls short
        }
    }
    EXPECT_GT(rounded, 100);
    const Bounds e = grow_bounds(aabb_of_points(nullptr, 0), 1);
    EXPECT_GT(e.min.x, e.max.x);
}

// ---- scalar == SIMD --------------------------------------------------------------------------------

void for_each_simd_target(const std::function<void()>& body) {
    for (std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
        hwy::SetSupportedTargetsForTest(target);
        SCOPED_TRACE(std::string("SIMD target ") + hwy::TargetName(target));
        body();
    }
    hwy::SetSupportedTargetsForTest(0);
}

template <class V, class Scalar, class Simd, class Single>
void check_batches(std::mt19937& rng, const Camera& cam, const std::vector<V>& pool, Scalar scalar, Simd simd,
                   Single single) {
    constexpr std::size_t kGuard = 32;
    for (std::size_t n : {0, 1, 2, 3, 5, 7, 8, 9, 15, 16, 17, 31, 33, 100, 257}) {
        std::uniform_int_distribution<std::size_t> pick(0, pool.size() - n);
        const std::size_t first = pick(rng);
        std::vector<Containment> a(n + kGuard, Containment(0xAB)), b(n + kGuard, Containment(0xAB));
        scalar(cam.planes, pool.data() + first, n, a.data());
        simd(cam.planes, pool.data() + first, n, b.data());
        for (std::size_t i = n; i < n + kGuard; ++i) {
            ASSERT_EQ(std::uint8_t(a[i]), 0xAB) << "scalar wrote past n";
            ASSERT_EQ(std::uint8_t(b[i]), 0xAB) << "simd wrote past n";
        }
        for (std::size_t i = 0; i < n; ++i) {
            ASSERT_EQ(a[i], b[i]) << "n " << n << " volume " << first + i;
            PlaneCullState st;
            std::uint32_t t = 0;
            ASSERT_EQ(a[i], single(cam.planes, pool[first + i], st, t)) << "batch differs from the single test";
        }
    }
}

TEST(BoundingVolumes, ScalarEqualsSimd) {
    std::mt19937 rng(9);
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    for (int f = 0; f < 12; ++f) {
        const Camera cam = random_camera(rng, f % 3 == 0 ? P3{} : P3{1e5, 2e4, -3e4}, f % 3 == 0 ? 10 : 100);
        std::vector<Sphere> spheres;
        std::vector<Bounds> boxes;
        std::vector<Obb> obbs;
        for (int i = 0; i < 600; ++i) {
            spheres.push_back(random_sphere(rng, cam));
            boxes.push_back(random_box(rng, cam));
            obbs.push_back(random_obb(rng, cam));
        }
        // Empty, NaN and infinite volumes among them.
        spheres[5].radius = -1;
        spheres[6].center.x = nan;
        spheres[7].radius = inf;
        boxes[5] = aabb_of_points(nullptr, 0);
        boxes[6].min.y = nan;
        boxes[7].max.z = inf;
        obbs[5] = obb_of_points(nullptr, 0);
        obbs[6].axes[1].x = nan;
        obbs[7].half_extents[2] = inf;
        for_each_simd_target([&] {
            check_batches(rng, cam, spheres, classify_spheres_scalar, classify_spheres_simd, classify_sphere);
            check_batches(rng, cam, boxes, classify_aabbs_scalar, classify_aabbs_simd, classify_aabb);
            check_batches(rng, cam, obbs, classify_obbs_scalar, classify_obbs_simd, classify_obb);
            // Whole pool, and the mix of answers it holds.
            std::vector<Containment> a(boxes.size()), b(boxes.size());
            classify_aabbs_scalar(cam.planes, boxes.data(), boxes.size(), a.data());
            classify_aabbs_simd(cam.planes, boxes.data(), boxes.size(), b.data());
            EXPECT_EQ(a, b);
        });
    }
}

// Random volumes are rarely within an ulp of a decision, so the batches above would not notice a
// kernel that rounds differently. Here volumes are moved (bisection on their distance from a
// frustum face) to where the scalar answer flips from outside to intersecting and from
// intersecting to inside; each of their floats is then perturbed by a few ulps, so the batch holds
// both answers, and scalar and SIMD must still agree on every volume.
template <class V, class Make, class Scalar, class Simd>
void check_at_boundary(std::mt19937& rng, const FrustumPlanes& planes, Make make, double t_out, double t_in,
                       Scalar scalar, Simd simd, int& mixed) {
    auto answer = [&](double t) {
        const V v = make(t);
        Containment c;
        scalar(planes, &v, 1, &c);
        return c;
    };
    for (Containment flip : {Containment::outside, Containment::inside}) {
        // answer(a) == flip, answer(b) != flip.
        double a = flip == Containment::outside ? t_out : t_in, b = 0;
        if (answer(a) != flip || answer(b) == flip) continue;
        for (int it = 0; it < 80; ++it) {
            const double m = 0.5 * (a + b);
            (answer(m) == flip ? a : b) = m;
        }
        std::vector<V> batch;
        std::uniform_int_distribution<int> ulps(-3, 3);
        for (double t : {a, b}) {
            for (int i = 0; i < 40; ++i) {
                V v = make(t);
                float f[sizeof(V) / sizeof(float)];
                std::memcpy(f, &v, sizeof(V));
                for (float& x : f) {
                    const int k = ulps(rng);
                    for (int s = 0; s < std::abs(k); ++s) x = std::nextafter(x, k > 0 ? 1e38f : -1e38f);
                }
                std::memcpy(&v, f, sizeof(V));
                batch.push_back(v);
            }
        }
        std::vector<Containment> x(batch.size()), y(batch.size());
        scalar(planes, batch.data(), batch.size(), x.data());
        simd(planes, batch.data(), batch.size(), y.data());
        ASSERT_EQ(x, y);
        if (std::count(x.begin(), x.end(), flip) > 0 && std::count(x.begin(), x.end(), flip) < std::ptrdiff_t(x.size()))
            ++mixed;
    }
}

TEST(BoundingVolumes, ScalarEqualsSimdAtTheDecisionBoundary) {
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> u(-1, 1), unit(0, 1);
    int mixed = 0;
    for (int f = 0; f < 8; ++f) {
        const Camera cam = random_camera(rng, f % 2 ? P3{-3e4, 6e4, 1e5} : P3{}, f % 2 ? 100 : 10);
        Mat4 inv;
        ASSERT_TRUE(invert(cam.world_to_clip, inv));
        for (int k = 0; k < 6; ++k) {
            double ndc[3] = {0.5 * u(rng), 0.5 * u(rng), 0.5};
            if (k < 4)
                ndc[k / 2] = (k % 2) ? 1 : -1;
            else
                ndc[2] = k == 4 ? 0 : 1;
            const Vec4 h = inv * Vec4{float(ndc[0]), float(ndc[1]), float(ndc[2]), 1};
            const P3 q{double(h.x) / h.w, double(h.y) / h.w, double(h.z) / h.w};
            const Vec4 r = cam.planes.rows[k];
            P3 n{r.x, r.y, r.z};
            n = n * (1 / std::sqrt(dotp(n, n)));  // inward
            const double size = cam.near * (0.1 + unit(rng));
            // t > 0 moves the volume out of the face, t < 0 into the frustum.
            auto sphere = [&](double t) { return Sphere{to_f(q - n * t), float(size)}; };
            auto box = [&](double t) {
                const P3 c = q - n * t;
                return Bounds{to_f(c - P3{size, size * 0.5, size}), to_f(c + P3{size, size * 0.5, size})};
            };
            const Obb base = random_obb(rng, cam);
            auto obb = [&](double t) {
                Obb o = base;
                o.center = to_f(q - n * t);
                for (float& e : o.half_extents) e = float(size);
                return o;
            };
            const double far_out = 4 * size + 1e-3 * cam.far, far_in = -std::min(3 * size, 0.2 * cam.near);
            for_each_simd_target([&] {
                check_at_boundary<Sphere>(rng, cam.planes, sphere, far_out, -size * 1.01 - 1e-4 * cam.far,
                                          classify_spheres_scalar, classify_spheres_simd, mixed);
                check_at_boundary<Bounds>(rng, cam.planes, box, far_out, far_in, classify_aabbs_scalar,
                                          classify_aabbs_simd, mixed);
                check_at_boundary<Obb>(rng, cam.planes, obb, far_out, far_in, classify_obbs_scalar, classify_obbs_simd,
                                       mixed);
            });
        }
    }
    EXPECT_GT(mixed, 100) << "the boundary batches must hold both answers";
}

// ---- n/p-vertex vs corners, meta-BVs --------------------------------------------------------------

// The lecture's false negative: a box beyond the far-left edge of the frustum straddles both the
// left and the far plane, so neither the corners test nor the n/p-vertex test rejects it, although
// it is disjoint from the frustum. The frustum's AABB (meta-BV) separates it.
TEST(BoundingVolumes, MetaBoxRejectsTheCornerTestsFalseNegative) {
    const Mat4 m = perspective(float(kPiD / 2), 1, 1, 100) * look_at({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
    const FrustumPlanes planes = make_frustum_planes(m, ClipDepth::zero_to_one);
    const Bounds box{{-140, -5, -150}, {-105, 5, -95}};
    PlaneCullState st;
    std::uint32_t t = 0, ct = 0;
    EXPECT_EQ(classify_aabb(planes, box, st, t), Containment::intersecting);
    EXPECT_EQ(classify_aabb_corners(planes, box, ct), Containment::intersecting);
    EXPECT_EQ(t, 6u);
    EXPECT_EQ(ct, 6u);
    const FrustumMetaBounds meta = frustum_meta_bounds(m, ClipDepth::zero_to_one);
    EXPECT_TRUE(meta_rejects(meta, box));
    // Ground truth: no point of the box is in the frustum.
    std::mt19937 rng(3);
    for (const P3& p : sample(rng, box, 20000)) ASSERT_FALSE(in_clip(m, p));
    // The meta box is the frustum's: x, y in [-100, 100], z in [-100, -1] (grown by 1e-5).
    EXPECT_NEAR(meta.box.min.x, -100, 0.01);
    EXPECT_NEAR(meta.box.max.y, 100, 0.01);
    EXPECT_NEAR(meta.box.max.z, -1, 0.01);
    EXPECT_NEAR(meta.box.min.z, -100, 0.01);
    // A box straddling the far-left edge that does reach in is kept by all tests.
    const Bounds in_box{{-110, -5, -110}, {-95, 5, -95}};
    st = {};
    EXPECT_EQ(classify_aabb(planes, in_box, st, t), Containment::intersecting);
    EXPECT_FALSE(meta_rejects(meta, in_box));
}

TEST(BoundingVolumes, MetaBoundsAreConservative) {
    std::mt19937 rng(13);
    int rejected = 0, kept_outside = 0;
    for (int f = 0; f < 40; ++f) {
        const double off = f % 2 ? 1e5 : 0;
        const Camera cam = random_camera(rng, {off, -off, off}, f % 2 ? 100 : 10);
        const FrustumMetaBounds meta = frustum_meta_bounds(cam.world_to_clip, ClipDepth::zero_to_one);
        // Both conventions give the same frustum.
        const Mat4 gl = cam.world_to_clip;  // zero_to_one here; the minus_one_to_one version of it:
        Mat4 m11 = gl;
        for (int c = 0; c < 4; ++c) m11.at(2, c) = 2 * gl.at(2, c) - gl.at(3, c);
        const FrustumMetaBounds meta11 = frustum_meta_bounds(m11, ClipDepth::minus_one_to_one);
        EXPECT_NEAR(meta11.sphere.radius, meta.sphere.radius, 1e-4 * meta.sphere.radius);
        for (int i = 0; i < 100; ++i) {
            const Sphere s = random_sphere(rng, cam);
            const Bounds b = random_box(rng, cam);
            const std::vector<P3> ps = sample(rng, s, 100), pb = sample(rng, b, 100);
            const bool s_in = std::any_of(ps.begin(), ps.end(), [&](P3 p) { return in_clip(cam.world_to_clip, p); });
            const bool b_in = std::any_of(pb.begin(), pb.end(), [&](P3 p) { return in_clip(cam.world_to_clip, p); });
            if (s_in) {
                ASSERT_FALSE(meta_rejects(meta, s)) << "meta rejected a sphere with a point inside";
            }
            if (b_in) {
                ASSERT_FALSE(meta_rejects(meta, b)) << "meta rejected a box with a point inside";
            }
            if (meta_rejects(meta, b)) {
                ++rejected;
                PlaneCullState st;
                std::uint32_t t = 0;
                if (classify_aabb(cam.planes, b, st, t) != Containment::outside) ++kept_outside;
            }
        }
    }
    EXPECT_GT(rejected, 500);
    // Boxes the planes keep but the meta box rejects exist in a random mix, too.
    EXPECT_GT(kept_outside, 0);
    // An infinite far plane: unbounded meta bounds that never reject.
    Mat4 inf_proj = perspective(1.0f, 1.0f, 0.1f, 100.0f);
    inf_proj.at(2, 2) = -1;
    inf_proj.at(2, 3) = -0.1f;  // z_clip = -z - n: depth 0 at the near plane, 1 at infinity
    const FrustumMetaBounds unbounded = frustum_meta_bounds(inf_proj, ClipDepth::zero_to_one);
    EXPECT_TRUE(std::isinf(unbounded.sphere.radius));
    EXPECT_FALSE(meta_rejects(unbounded, Bounds{{1e30f, 1e30f, -1e30f}, {1e30f, 1e30f, -1e30f}}));
    EXPECT_TRUE(meta_rejects(unbounded, aabb_of_points(nullptr, 0)));
    EXPECT_TRUE(meta_rejects(unbounded, sphere_of_points(nullptr, 0)));
}

// ---- plane masking and coherence ----------------------------------------------------------------

TEST(BoundingVolumes, MaskingAndCoherenceNeverChangeTheAnswer) {
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(-1, 1), unit(0, 1);
    for (int seq = 0; seq < 6; ++seq) {
        const P3 offset = seq % 2 ? P3{2e4, 1e4, -5e4} : P3{};
        const double scale = seq % 2 ? 100 : 10;
        // A camera that turns and moves a little per frame.
        Camera cam = random_camera(rng, offset, scale);
        std::vector<Sphere> spheres;
        std::vector<Bounds> boxes;
        std::vector<Obb> obbs;
        for (int i = 0; i < 300; ++i) {
            spheres.push_back(random_sphere(rng, cam));
            boxes.push_back(random_box(rng, cam));
            obbs.push_back(random_obb(rng, cam));
        }
        std::vector<PlaneCullState> ss(300), sb(300), so(300);
        std::uint64_t coherent_tests = 0, fresh_tests = 0;
        P3 eye = cam.eye, dir = cam.dir;
        for (int frame = 0; frame < 30; ++frame) {
            eye = eye + P3{u(rng), u(rng), u(rng)} * (0.02 * scale);
            dir = dir + P3{u(rng), u(rng), u(rng)} * 0.05;
            dir = dir * (1 / std::sqrt(dotp(dir, dir)));
            cam.world_to_clip = perspective(1.2f, 1.5f, float(cam.near), float(cam.far)) *
                                look_at(to_f(eye), to_f(eye + dir * scale), {0, 1, 0});
            cam.planes = make_frustum_planes(cam.world_to_clip, ClipDepth::zero_to_one);
            for (int i = 0; i < 300; ++i) {
                std::uint32_t tc = 0, tf = 0;
                PlaneCullState fresh;
                ss[i].plane_mask = 0x3f;
                const std::int8_t last = ss[i].last_plane;
                const Containment a = classify_sphere(cam.planes, spheres[i], ss[i], tc);
                const Containment b = classify_sphere(cam.planes, spheres[i], fresh, tf);
                ASSERT_EQ(a, b);
                ASSERT_EQ(ss[i].plane_mask, a == Containment::outside ? 0x3f : fresh.plane_mask);
                // A volume rejected by plane k last frame and still outside it costs one test.
                if (last >= 0 && a == Containment::outside) {
                    PlaneCullState only;
                    only.plane_mask = std::uint8_t(1u << last);
                    std::uint32_t t1 = 0;
                    if (classify_sphere(cam.planes, spheres[i], only, t1) == Containment::outside) {
                        EXPECT_EQ(tc, 1u);
                    }
                }
                coherent_tests += tc;
                fresh_tests += tf;
                tc = tf = 0;
                sb[i].plane_mask = 0x3f;
                fresh = {};
                ASSERT_EQ(classify_aabb(cam.planes, boxes[i], sb[i], tc),
                          classify_aabb(cam.planes, boxes[i], fresh, tf));
                so[i].plane_mask = 0x3f;
                fresh = {};
                ASSERT_EQ(classify_obb(cam.planes, obbs[i], so[i], tc), classify_obb(cam.planes, obbs[i], fresh, tf));
                coherent_tests += tc;
                fresh_tests += tf;
            }
        }
        // Most outside volumes stay outside the same plane from frame to frame.
        EXPECT_LT(coherent_tests, fresh_tests) << "coherence did not reduce plane tests";
    }
}

// Plane masking: a box inside its parent box, tested with the parent's output mask, gets the
// answer of a fresh test, and tests only the planes the parent straddles.
TEST(BoundingVolumes, PlaneMaskingOfNestedBoxes) {
    std::mt19937 rng(19);
    std::uniform_real_distribution<double> unit(0, 1);
    int masked_planes = 0;
    for (int f = 0; f < 30; ++f) {
        const Camera cam = random_camera(rng, f % 2 ? P3{1e5, 0, 1e5} : P3{}, f % 2 ? 100 : 10);
        for (int i = 0; i < 200; ++i) {
            const Bounds parent = random_box(rng, cam);
            Bounds child;
            float* lo = &child.min.x;
            float* hi = &child.max.x;
            const float* plo = &parent.min.x;
            const float* phi = &parent.max.x;
            for (int a = 0; a < 3; ++a) {
                double x = plo[a] + (double(phi[a]) - plo[a]) * unit(rng),
                       y = plo[a] + (double(phi[a]) - plo[a]) * unit(rng);
                if (x > y) std::swap(x, y);
                lo[a] = std::clamp(float(x), plo[a], phi[a]);
                hi[a] = std::clamp(float(y), plo[a], phi[a]);
            }
            PlaneCullState ps;
            std::uint32_t t = 0;
            const Containment pc = classify_aabb(cam.planes, parent, ps, t);
            if (pc == Containment::outside) {
                PlaneCullState cs;
                ASSERT_EQ(classify_aabb(cam.planes, child, cs, t), Containment::outside) << "child of an outside box";
                continue;
            }
            PlaneCullState cs, fresh;
            cs.plane_mask = ps.plane_mask;
            std::uint32_t tm = 0, tf = 0;
            const Containment cm = classify_aabb(cam.planes, child, cs, tm);
            ASSERT_EQ(cm, classify_aabb(cam.planes, child, fresh, tf));
            if (cm != Containment::outside) {
                EXPECT_EQ(tm, std::uint32_t(std::popcount(ps.plane_mask)));
            }
            masked_planes += int(tf) - int(tm);
            // The same for spheres and OBBs of the child box (inside the parent box too).
            PlaneCullState s1, s2;
            s1.plane_mask = ps.plane_mask;
            ASSERT_EQ(classify_obb(cam.planes, obb_of_aabb(child), s1, tm),
                      classify_obb(cam.planes, obb_of_aabb(child), s2, tf));
        }
    }
    EXPECT_GT(masked_planes, 1000);
}

// ---- detail culling -----------------------------------------------------------------------------------

TEST(BoundingVolumes, DetailCullingMatchesAnExplicitProjection) {
    const float fovy = 1.0f, height = 720;
    const float n = projection_pixel_scale(fovy, height);
    EXPECT_NEAR(n, 720 / (2 * std::tan(0.5)), 1e-3);
    const Vec3 eye{3, 1, -2}, target{10, 2, -30};
    const Mat4 m = perspective(fovy, 16.0f / 9, 0.1f, 1000) * look_at(eye, target, {0, 1, 0});
    const P3 fwd = [&] {
        P3 d = p3(target) - p3(eye);
        return d * (1 / std::sqrt(dotp(d, d)));
    }();
    // The camera's up vector: row 1 of the view matrix.
    const Mat4 view = look_at(eye, target, {0, 1, 0});
    const P3 up{view.at(1, 0), view.at(1, 1), view.at(1, 2)};
    for (double d : {1.0, 5.0, 40.0, 300.0}) {
        for (double r : {0.001, 0.05, 0.3}) {
            const Sphere s{to_f(p3(eye) + fwd * d), float(r)};
            // Explicit projection of the point r above the centre (perpendicular to the view axis).
            const P3 top = p3(s.center) + up * r;
            const Vec4 ct = m * Vec4{float(top.x), float(top.y), float(top.z), 1};
            const Vec4 cc = m * Vec4{s.center.x, s.center.y, s.center.z, 1};
            const double pixels = (double(ct.y) / ct.w - double(cc.y) / cc.w) * height / 2;
            const float pr = projected_radius_pixels(s, eye, n);
            EXPECT_NEAR(pr, pixels, 1e-3 * pixels + 1e-4) << "d " << d << " r " << r;
            const double area = kPiD * pr * pr;
            EXPECT_TRUE(detail_culled(s, eye, n, float(area * 1.01)));
            EXPECT_FALSE(detail_culled(s, eye, n, float(area * 0.99)));
        }
    }
    // Eye inside: never culled; no threshold: never culled; empty: culled.
    EXPECT_FALSE(detail_culled({eye, 0.5f}, eye, n, 1e9f));
    EXPECT_FALSE(detail_culled({{100, 0, 0}, 0.001f}, eye, n, 0));
    EXPECT_TRUE(detail_culled(sphere_of_points(nullptr, 0), eye, n, 1));
}

}  // namespace
