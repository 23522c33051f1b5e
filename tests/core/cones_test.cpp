// Cones of normals (patchcull/core/cones.h): the normal patch's Bezier form against direct evaluation,
// the Sederberg-Meyers combination against random vectors in random cones, every sampled normal
// inside the TCONE and NCONE cones, NCONE never wider than TCONE on average, the control-point
// sphere, and the back-facing test on hand-built cases (including the alpha + beta <= 90deg guard).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "core/cone_test_patches.h"
#include "core/cones_internal.h"
#include "patchcull/core/cones.h"
#include "patchcull/core/teapot.h"

using namespace patchcull;
using namespace patchcull::cone_test;

namespace {

constexpr double kPi = 3.14159265358979323846;

double binomial5(int i) {
    static const double c[6] = {1, 5, 10, 10, 5, 1};
    return c[i];
}

double bernstein5(int i, double t) { return binomial5(i) * std::pow(t, i) * std::pow(1 - t, 5 - i); }

// Angle (radians) between a non-zero double vector and a cone's axis.
double angle_to_axis(D3 n, const NormalCone& cone) {
    const D3 a = d3(cone.axis);
    const double c = dot(n, a) / (len(n) * len(a));
    return std::acos(std::clamp(c, -1.0, 1.0));
}

// True when the non-zero vector n lies inside the cone: cos angle(n, axis) >= cos_angle, in double.
bool inside(D3 n, const NormalCone& cone) {
    const D3 a = d3(cone.axis);
    return dot(n, a) / (len(n) * len(a)) >= double(cone.cos_angle);
}

double half_angle_deg(const NormalCone& cone) { return std::atan2(cone.sin_angle, cone.cos_angle) * 180 / kPi; }

// Checks every non-zero normal of a grid x grid sampling (plus random points) lies in the cone.
// Returns the number of samples outside (0 expected).
int normals_outside(const BezierPatch& patch, const NormalCone& cone, int grid, PatchGen& gen) {
    int outside = 0;
    auto check = [&](double u, double v) {
        const D3 n = evaluate_d(patch, u, v).normal();
        if (len(n) == 0) return;
        if (!inside(n, cone)) ++outside;
    };
    for (int j = 0; j < grid; ++j)
        for (int i = 0; i < grid; ++i) check(double(i) / (grid - 1), double(j) / (grid - 1));
    for (int k = 0; k < 64; ++k) check(gen.uniform(0, 1), gen.uniform(0, 1));
    return outside;
}

TEST(Cones, NormalPatchBezierFormMatchesDirectEvaluation) {
    PatchGen gen(11);
    double worst = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        const BezierPatch patch = trial % 3 == 0 ? gen.cloud(gen.uniform(0.1, 10)) : gen.any();
        Vec3 nv[36];
        float bound[36];
        cones_detail::normal_patch_vectors(patch, nv, bound);
        for (int s = 0; s < 8; ++s) {
            const double u = s == 0 ? 0.0 : s == 1 ? 1.0 : gen.uniform(0, 1);
            const double v = s == 2 ? 0.0 : s == 3 ? 1.0 : gen.uniform(0, 1);
            const SurfaceD sd = evaluate_d(patch, u, v);
            const D3 direct = sd.normal();
            D3 bezier;
            for (int j = 0; j < 6; ++j)
                for (int i = 0; i < 6; ++i) {
                    const double w = bernstein5(i, u) * bernstein5(j, v) * 9 / (binomial5(i) * binomial5(j));
                    bezier = bezier + d3(nv[6 * j + i]) * w;
                }
            // Scale of |B_u| |B_v| over the patch (the direct value can be ~0 at a collapsed edge).
            double mu = 0, mv = 0;
            for (int j = 0; j < 4; ++j)
                for (int i = 0; i < 3; ++i) {
                    mu = std::max(mu, 3 * len(d3(xyz(patch.cp[4 * j + i + 1])) - d3(xyz(patch.cp[4 * j + i]))));
                    mv = std::max(mv, 3 * len(d3(xyz(patch.cp[4 * i + 4 + j])) - d3(xyz(patch.cp[4 * i + j]))));
                }
            const double scale = mu * mv + 1e-300;
            const double err = len(bezier - direct) / scale;
            worst = std::max(worst, err);
            ASSERT_LT(err, 1e-5) << "trial " << trial << " u " << u << " v " << v;
        }
    }
    std::printf("[ normal patch ] worst |Bezier form - B_u x B_v| / (|B_u| |B_v|) = %.3g\n", worst);
}

// The rounding bound of the normal-patch control vectors holds: compare against a double
// computation of the same sums.
TEST(Cones, NormalPatchRoundingBoundHolds) {
    PatchGen gen(12);
    for (int trial = 0; trial < 3000; ++trial) {
        const BezierPatch patch = gen.any();
        Vec3 nv[36];
        float bound[36];
        cones_detail::normal_patch_vectors(patch, nv, bound);
        D3 U[12], V[12];
        for (int b = 0; b < 4; ++b)
            for (int a = 0; a < 3; ++a) {
                const Vec4 p0 = patch.cp[4 * b + a], p1 = patch.cp[4 * b + a + 1];
                U[3 * b + a] = D3{double(p1.x) - p0.x, double(p1.y) - p0.y, double(p1.z) - p0.z} *
                               (cones_detail::kC2[a] * cones_detail::kC3[b]);
            }
        for (int d = 0; d < 3; ++d)
            for (int c = 0; c < 4; ++c) {
                const Vec4 p0 = patch.cp[4 * d + c], p1 = patch.cp[4 * d + 4 + c];
                V[4 * d + c] = D3{double(p1.x) - p0.x, double(p1.y) - p0.y, double(p1.z) - p0.z} *
                               (cones_detail::kC3[c] * cones_detail::kC2[d]);
            }
        for (int j = 0; j < 6; ++j)
            for (int i = 0; i < 6; ++i) {
                D3 exact;
                for (int a = std::max(0, i - 3); a <= std::min(2, i); ++a)
                    for (int b = std::max(0, j - 2); b <= std::min(3, j); ++b)
                        exact = exact + cross(U[3 * b + a], V[4 * (j - b) + (i - a)]);
                const double err = len(d3(nv[6 * j + i]) - exact);
                ASSERT_LE(err, double(cones_detail::kNormalRoundoff) * bound[6 * j + i] * 0.5)
                    << "trial " << trial << " ij " << i << j;
            }
    }
}

// Random unit vector within angle alpha of unit axis a (on the boundary when boundary is set).
D3 in_cone(PatchGen& gen, D3 a, double alpha, bool boundary) {
    D3 p = cross(a, gen.unit());
    p = p * (1 / len(p));
    const double t = boundary ? alpha : std::acos(gen.uniform(std::cos(alpha), 1.0));
    return a * std::cos(t) + p * std::sin(t);
}

NormalCone make_cone(D3 axis, double alpha) {
    NormalCone c;
    c.axis = {float(axis.x), float(axis.y), float(axis.z)};
    c.cos_angle = float(std::cos(alpha));
    c.sin_angle = float(std::sin(alpha));
    c.valid = true;
    return c;
}

TEST(Cones, SederbergMeyersCombinationHolds) {
    PatchGen gen(21);
    int valid = 0, invalid = 0;
    double tightest = 0;  // max over tests of (observed angle / alpha_n)
    for (int trial = 0; trial < 20000 / kSanitizerDivisor; ++trial) {
        const double at = gen.uniform(0, 1.3), ab = gen.uniform(0, 1.3);
        const NormalCone t = make_cone(gen.unit(), at), b = make_cone(gen.unit(), ab);
        const NormalCone n = cones_detail::combine_cones(t, b);
        // Angles of the input cones as the float pair describes them.
        const double at_f = std::acos(double(t.cos_angle)), ab_f = std::acos(double(b.cos_angle));
        const D3 ta = d3(t.axis) * (1 / len(d3(t.axis))), ba = d3(b.axis) * (1 / len(d3(b.axis)));
        const double theta = std::acos(std::clamp(dot(ta, ba), -1.0, 1.0));
        if (!n.valid) {
            ++invalid;
            continue;
        }
        ++valid;
        // Valid implies disjoint cones that are not antipodal either.
        EXPECT_GT(theta, at_f + ab_f) << trial;
        EXPECT_LT(theta, kPi - at_f - ab_f) << trial;
        EXPECT_NEAR(double(n.cos_angle) * n.cos_angle + double(n.sin_angle) * n.sin_angle, 1.0, 1e-6);
        const double alpha_n = std::atan2(n.sin_angle, n.cos_angle);
        for (int s = 0; s < 200; ++s) {
            const D3 tv = in_cone(gen, ta, at_f, s % 2 == 0);
            const D3 bv = in_cone(gen, ba, ab_f, s % 4 < 2);
            const D3 x = cross(tv, bv) * gen.uniform(0.01, 100);
            ASSERT_GT(len(x), 0);
            ASSERT_TRUE(inside(x, n)) << "trial " << trial << " angle " << angle_to_axis(x, n) << " > " << alpha_n;
            if (alpha_n > 1e-3) tightest = std::max(tightest, angle_to_axis(x, n) / alpha_n);
        }
    }
    std::printf("[ S&M ] valid %d invalid %d, largest sampled angle / alpha_n = %.4f\n", valid, invalid, tightest);
    EXPECT_GT(valid, 2000 / kSanitizerDivisor);
    EXPECT_GT(tightest, 0.95);  // the bound is nearly reached: it is not loose
}

TEST(Cones, SederbergMeyersFailureCases) {
    const D3 x{1, 0, 0}, y{0, 1, 0};
    // Overlapping cones: 50 + 50 > 90 degrees.
    EXPECT_FALSE(cones_detail::combine_cones(make_cone(x, 50 * kPi / 180), make_cone(y, 50 * kPi / 180)).valid);
    // Antipodal overlap: axes 170 degrees apart, cones 10 degrees: -b is inside cone t.
    const D3 z170{std::cos(170 * kPi / 180), std::sin(170 * kPi / 180), 0};
    EXPECT_FALSE(cones_detail::combine_cones(make_cone(x, 10 * kPi / 180), make_cone(z170, 10 * kPi / 180)).valid);
    // Parallel axes.
    EXPECT_FALSE(cones_detail::combine_cones(make_cone(x, 0.01), make_cone(x, 0.01)).valid);
    // Just disjoint: 40 + 40 < 90: valid, with the 90 degree case at sin = sqrt(2 sin^2 40).
    const NormalCone ok = cones_detail::combine_cones(make_cone(x, 40 * kPi / 180), make_cone(y, 40 * kPi / 180));
    EXPECT_TRUE(ok.valid);
    EXPECT_NEAR(ok.sin_angle, std::sqrt(2.0) * std::sin(40 * kPi / 180), 1e-5);
    EXPECT_NEAR(ok.axis.z, 1.0f, 1e-6f);
    // An invalid input cone gives an invalid result.
    NormalCone bad = make_cone(y, 0.1);
    bad.valid = false;
    EXPECT_FALSE(cones_detail::combine_cones(make_cone(x, 0.1), bad).valid);
}

// Every sampled normal of random patches lies in both cones when they are valid; report how often
// they are valid and how wide.
TEST(Cones, SampledNormalsInsideBothCones) {
    PatchGen gen(31);
    int n_patches = 0, t_valid = 0, n_valid = 0, both = 0, n_only = 0, t_only = 0;
    double t_sum = 0, n_sum = 0;
    for (int trial = 0; trial < 4000 / kSanitizerDivisor; ++trial) {
        const BezierPatch patch = gen.any();
        ++n_patches;
        const NormalCone t = tangent_normal_cone(patch);
        const NormalCone n = normal_patch_cone(patch);
        if (t.valid) {
            ++t_valid;
            ASSERT_EQ(normals_outside(patch, t, 33, gen), 0) << "TCONE, trial " << trial;
            ASSERT_NEAR(std::hypot(double(t.axis.x), double(t.axis.y), double(t.axis.z)), 1.0, 1e-6);
        }
        if (n.valid) {
            ++n_valid;
            ASSERT_EQ(normals_outside(patch, n, 33, gen), 0) << "NCONE, trial " << trial;
            ASSERT_NEAR(std::hypot(double(n.axis.x), double(n.axis.y), double(n.axis.z)), 1.0, 1e-6);
        }
        if (t.valid && n.valid) {
            ++both;
            t_sum += half_angle_deg(t);
            n_sum += half_angle_deg(n);
        }
        n_only += n.valid && !t.valid;
        t_only += t.valid && !n.valid;
    }
    std::printf(
        "[ cones ] %d random patches: TCONE valid %d, NCONE valid %d (NCONE only %d, TCONE only %d); "
        "both valid %d: mean half-angle TCONE %.2f deg, NCONE %.2f deg\n",
        n_patches, t_valid, n_valid, n_only, t_only, both, t_sum / both, n_sum / both);
    EXPECT_GT(both, 1000 / kSanitizerDivisor);
    EXPECT_LE(n_sum, t_sum);  // NCONE never wider than TCONE on average
    EXPECT_GE(n_valid, t_valid);
}

// NCONE is not wider than TCONE on average, per family of patches (numbers are printed).
TEST(Cones, NconeNotWiderThanTconeOnAverage) {
    PatchGen gen(41);
    for (double bump : {0.001, 0.01, 0.1, 0.3}) {
        int both = 0, t_valid = 0, n_valid = 0, n_wider = 0;
        double t_sum = 0, n_sum = 0;
        for (int trial = 0; trial < 2000; ++trial) {
            const BezierPatch patch = gen.sheet(bump);
            const NormalCone t = tangent_normal_cone(patch), n = normal_patch_cone(patch);
            t_valid += t.valid;
            n_valid += n.valid;
            if (!(t.valid && n.valid)) continue;
            ++both;
            t_sum += half_angle_deg(t);
            n_sum += half_angle_deg(n);
            n_wider += half_angle_deg(n) > half_angle_deg(t);
        }
        std::printf(
            "[ cones ] sheets, bump %.3f: valid TCONE %d NCONE %d of 2000; mean half-angle TCONE %.2f "
            "NCONE %.2f deg (ratio %.2f), NCONE wider in %d\n",
            bump, t_valid, n_valid, t_sum / std::max(both, 1), n_sum / std::max(both, 1),
            n_sum / std::max(t_sum, 1e-30), n_wider);
        EXPECT_LE(n_sum, t_sum) << "bump " << bump;
        EXPECT_GE(n_valid, t_valid) << "bump " << bump;
    }
}

// Axis choice: three cheap axes for a set of control vectors, measured as the mean half-angle
// (degrees) of the resulting cone over random sheets, for the 36 NCONE vectors and the 12 + 12
// TCONE tangent vectors: the normalised sum of normalised vectors, the sum of the raw vectors, and
// the centre of the box of the normalised vectors (the one the library uses).
double mean_half_angle(const std::vector<std::vector<D3>>& sets, int method) {
    double sum = 0;
    int count = 0;
    for (const auto& vs : sets) {
        D3 sn, sr, lo{1e9, 1e9, 1e9}, hi{-1e9, -1e9, -1e9};
        for (const D3& v : vs) {
            const D3 h = v * (1 / len(v));
            sn = sn + h;
            sr = sr + v;
            lo = {std::min(lo.x, h.x), std::min(lo.y, h.y), std::min(lo.z, h.z)};
            hi = {std::max(hi.x, h.x), std::max(hi.y, h.y), std::max(hi.z, h.z)};
        }
        const D3 axis = method == 0 ? sn : method == 1 ? sr : (lo + hi) * 0.5;
        const D3 ax = axis * (1 / len(axis));
        double worst = 0;
        for (const D3& v : vs) worst = std::max(worst, std::acos(std::clamp(dot(ax, v) / len(v), -1.0, 1.0)));
        if (worst >= kPi / 2) continue;
        sum += worst * 180 / kPi;
        ++count;
    }
    return sum / std::max(count, 1);
}

TEST(Cones, AxisChoice) {
    PatchGen gen(51);
    std::vector<std::vector<D3>> nsets, tsets;
    for (int trial = 0; trial < 3000; ++trial) {
        const BezierPatch patch = gen.sheet(std::pow(10.0, gen.uniform(-3, -0.3)));
        Vec3 nv[36];
        float bound[36];
        cones_detail::normal_patch_vectors(patch, nv, bound);
        std::vector<D3> vs;
        for (const Vec3& v : nv)
            if (len(d3(v)) > 0) vs.push_back(d3(v));
        nsets.push_back(vs);
        Vec3 U[12], V[12];
        cones_detail::tangent_vectors(patch, U, V);
        std::vector<D3> us, ws;
        for (int k = 0; k < 12; ++k) {
            us.push_back(d3(U[k]));
            ws.push_back(d3(V[k]));
        }
        tsets.push_back(us);
        tsets.push_back(ws);
    }
    double n[3], t[3];
    for (int m = 0; m < 3; ++m) {
        n[m] = mean_half_angle(nsets, m);
        t[m] = mean_half_angle(tsets, m);
    }
    std::printf(
        "[ axis ] mean half-angle (deg), NCONE vectors / TCONE tangent vectors: normalised sum %.3f / %.3f, "
        "raw sum %.3f / %.3f, box centre %.3f / %.3f\n",
        n[0], t[0], n[1], t[1], n[2], t[2]);
    EXPECT_LE(n[2], n[0]);
    EXPECT_LE(t[2], t[0]);
}

TEST(Cones, TeapotCones) {
    PatchGen gen(61);
    const std::vector<BezierPatch> teapot = teapot_patches();
    int t_valid = 0, n_valid = 0;
    for (std::size_t p = 0; p < teapot.size(); ++p) {
        const NormalCone t = tangent_normal_cone(teapot[p]), n = normal_patch_cone(teapot[p]);
        t_valid += t.valid;
        n_valid += n.valid;
        if (t.valid) {
            EXPECT_EQ(normals_outside(teapot[p], t, 65, gen), 0) << "TCONE patch " << p;
        }
        if (n.valid) {
            EXPECT_EQ(normals_outside(teapot[p], n, 65, gen), 0) << "NCONE patch " << p;
        }
    }
    std::printf("[ teapot ] valid cones: TCONE %d / 32, NCONE %d / 32\n", t_valid, n_valid);
}

// A flat quarter disc with one edge collapsed to its centre (like the teapot's lid top and
// bottom, but planar): the zero control vectors along the collapsed edge are exactly zero (M = 0),
// so NCONE is a narrow cone around the plane normal; TCONE is much wider.
BezierPatch flat_fan() {
    BezierPatch fan;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            const double a = (kPi / 2) * i / 3.0, r = 1.5 * j / 3.0;
            fan.cp[4 * j + i] = {float(r * std::cos(a)), float(r * std::sin(a)), 0.0f, 1.0f};
        }
    return fan;
}

TEST(Cones, CollapsedEdge) {
    const BezierPatch fan = flat_fan();
    const D3 n0 = evaluate_d(fan, 0.5, 0.5).normal();
    const NormalCone n = normal_patch_cone(fan);
    ASSERT_TRUE(n.valid);
    EXPECT_EQ(n.axis.z, n0.z > 0 ? 1.0f : -1.0f);
    EXPECT_LT(half_angle_deg(n), 0.5);              // the rounding bound widens it a little (see cones.cpp)
    const NormalCone t = tangent_normal_cone(fan);  // valid here (tangents spread 30 / 45 deg), but wide
    EXPECT_TRUE(!t.valid || half_angle_deg(t) > 30);
    PatchGen gen(62);
    EXPECT_EQ(normals_outside(fan, n, 65, gen), 0);
}

TEST(Cones, InvalidInputs) {
    PatchGen gen(71);
    BezierPatch patch = gen.sheet(0.01);
    ASSERT_TRUE(tangent_normal_cone(patch).valid);
    ASSERT_TRUE(normal_patch_cone(patch).valid);
    // Rational: never a cone.
    BezierPatch rational = patch;
    rational.cp[5] = rational.cp[5] * 2.0f;
    EXPECT_FALSE(tangent_normal_cone(rational).valid);
    EXPECT_FALSE(normal_patch_cone(rational).valid);
    // NaN and inf.
    for (float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
        BezierPatch p = patch;
        p.cp[7].y = bad;
        EXPECT_FALSE(tangent_normal_cone(p).valid);
        EXPECT_FALSE(normal_patch_cone(p).valid);
    }
    // All points equal: no normal at all.
    BezierPatch point;
    for (auto& c : point.cp) c = {1, 2, 3, 1};
    EXPECT_FALSE(tangent_normal_cone(point).valid);
    EXPECT_FALSE(normal_patch_cone(point).valid);
    // A U-turn (a half tube): normals over 180 degrees.
    BezierPatch tube;
    const float prof[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) tube.cp[4 * j + i] = {prof[i][0], float(j), prof[i][1], 1};
    EXPECT_FALSE(tangent_normal_cone(tube).valid);
    EXPECT_FALSE(normal_patch_cone(tube).valid);
    // A planar patch: cones of (almost) zero width around the plane normal (outward du x dv = +z).
    BezierPatch flat;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) flat.cp[4 * j + i] = {float(i), float(j), 0, 1};
    for (const NormalCone& c : {tangent_normal_cone(flat), normal_patch_cone(flat)}) {
        ASSERT_TRUE(c.valid);
        EXPECT_EQ(c.axis.z, 1.0f);
        EXPECT_LT(half_angle_deg(c), 0.3);  // the float slack: ~0.16deg (TCONE), ~0.26deg (NCONE)
    }
}

TEST(Cones, ControlPointSphereHoldsPatch) {
    PatchGen gen(81);
    for (int trial = 0; trial < 2000; ++trial) {
        BezierPatch patch = gen.any();
        const bool rational = trial % 2 == 1;
        if (rational)
            for (auto& c : patch.cp) c = c * float(gen.uniform(0.25, 4));
        const PatchSphere s = control_point_sphere(patch);
        for (int j = 0; j <= 16; ++j)
            for (int i = 0; i <= 16; ++i) {
                const Vec3 p = evaluate_position(patch, i / 16.0f, j / 16.0f);
                if (!rational) {
                    const D3 pd = evaluate_d(patch, i / 16.0, j / 16.0).p;
                    ASSERT_LE(len(pd - d3(s.center)), double(s.radius)) << trial;
                } else {
                    // float evaluation of the rational patch: allow its own rounding.
                    ASSERT_LE(len(d3(p) - d3(s.center)), double(s.radius) * (1 + 1e-5)) << trial;
                }
            }
        for (const Vec4& c : patch.cp) ASSERT_LE(len(d3(cartesian(c)) - d3(s.center)), double(s.radius));
    }
}

// Hand-built cases of the runtime test.
TEST(Cones, BackFacingHandCases) {
    NormalCone up = make_cone({0, 0, 1}, 0.0);
    PatchSphere s{{0, 0, 0}, 1.0f};
    EXPECT_TRUE(cone_back_facing(up, s, {0, 0, -10}));
    EXPECT_FALSE(cone_back_facing(up, s, {0, 0, 10}));
    EXPECT_FALSE(cone_back_facing(up, s, {0, 0, -0.5f}));  // eye inside the sphere
    EXPECT_FALSE(cone_back_facing(up, s, {10, 0, 0}));     // in the plane
    // Perspective: beta = asin(1/2) = 30deg; a . d/|d| must be <= -sin(30deg).
    EXPECT_TRUE(cone_back_facing(up, s, {0, 0, -2}));
    // d at 61deg / 59deg from -z: angle(a, d) = 119deg (< 120deg) / 121deg.
    EXPECT_FALSE(
        cone_back_facing(up, s, {2 * std::sin(float(61 * kPi / 180)), 0, -2 * std::cos(float(61 * kPi / 180))}));
    EXPECT_TRUE(
        cone_back_facing(up, s, {2 * std::sin(float(59 * kPi / 180)), 0, -2 * std::cos(float(59 * kPi / 180))}));
    // With alpha = 20deg the limit moves to angle(a, d) >= 140deg.
    NormalCone up20 = make_cone({0, 0, 1}, 20 * kPi / 180);
    EXPECT_TRUE(
        cone_back_facing(up20, s, {2 * std::sin(float(39 * kPi / 180)), 0, -2 * std::cos(float(39 * kPi / 180))}));
    EXPECT_FALSE(
        cone_back_facing(up20, s, {2 * std::sin(float(41 * kPi / 180)), 0, -2 * std::cos(float(41 * kPi / 180))}));
    // alpha + beta > 90deg can never cull, though a . d/|d| <= -sin(alpha + beta) holds:
    // alpha = 80deg, beta = 80deg (|d| = 1/sin 80deg), angle(a, d) = 175deg.
    NormalCone wide = make_cone({0, 0, 1}, 80 * kPi / 180);
    const float dist = 1.0f / std::sin(float(80 * kPi / 180)) * 1.0001f;
    const Vec3 eye{dist * std::sin(float(5 * kPi / 180)), 0, -dist * std::cos(float(5 * kPi / 180))};
    EXPECT_LE(-std::cos(5 * kPi / 180), -std::sin(160 * kPi / 180));  // the bare inequality would cull
    EXPECT_FALSE(cone_back_facing(wide, s, eye));
    // Invalid cone: never.
    NormalCone invalid = up;
    invalid.valid = false;
    EXPECT_FALSE(cone_back_facing(invalid, s, {0, 0, -10}));
}

}  // namespace
