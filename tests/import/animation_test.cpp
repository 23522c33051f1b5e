// Procedural control-mesh animation (src/import/animation.cpp), and the mesh.h helpers it uses
// (compute_bounds, ControlMesh::all_quads; src/core/mesh.cpp) as AnimationSupport.*.
#include "patchcull/import/animation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "patchcull/core/mesh.h"

namespace patchcull {
namespace {

constexpr float kPi = 3.14159265358979f;

float component(Vec3 v, int axis) { return axis == 0 ? v.x : (axis == 1 ? v.y : v.z); }

// A deterministic, irregular point cloud: a box of size (sx, sy, sz) with corner lo, filled with
// a low-discrepancy sequence (no RNG, so it is the same on every platform).
std::vector<Vec3> cloud(Vec3 lo, Vec3 size, int n) {
    std::vector<Vec3> points;
    for (int k = 0; k < n; ++k) {
        const float a = std::fmod(0.5f + k * 0.6180339887f, 1.0f);
        const float b = std::fmod(0.5f + k * 0.7548776662f, 1.0f);
        const float c = std::fmod(0.5f + k * 0.5698402910f, 1.0f);
        points.push_back({lo.x + a * size.x, lo.y + b * size.y, lo.z + c * size.z});
    }
    // Make sure the corners are there, so the bounds are exactly the box.
    points.push_back(lo);
    points.push_back(lo + size);
    return points;
}

float max_displacement(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
    float m = 0;
    for (std::size_t k = 0; k < a.size(); ++k) m = std::max(m, length(a[k] - b[k]));
    return m;
}

float diagonal(const std::vector<Vec3>& points) {
    const Bounds b = compute_bounds(points);
    return length(b.max - b.min);
}

// The documented bound (src/import/animation.cpp): D * (A/2 + (1 + A)(T/4 + B)).
float documented_bound(const AnimationParams& p) {
    const float a = std::fabs(p.breathe_amplitude), t = std::fabs(p.twist_radians), b = std::fabs(p.bend_radians);
    return a / 2 + (1 + a) * (t / 4 + b);
}

// A y-up "character": taller along y than wide.
const std::vector<Vec3>& character() {
    static const std::vector<Vec3> points = cloud({-1.0f, 0.5f, -0.6f}, {2.0f, 4.0f, 1.2f}, 500);
    return points;
}

TEST(AnimationSupport, ComputeBoundsIsTheTightBox) {
    const Bounds b = compute_bounds({{1, -2, 3}, {-4, 5, 0.5f}, {0, 0, 7}});
    EXPECT_EQ(b.min.x, -4);
    EXPECT_EQ(b.min.y, -2);
    EXPECT_EQ(b.min.z, 0.5f);
    EXPECT_EQ(b.max.x, 1);
    EXPECT_EQ(b.max.y, 5);
    EXPECT_EQ(b.max.z, 7);
    const Bounds one = compute_bounds({{2, 3, 4}});
    EXPECT_EQ(one.min.x, 2);
    EXPECT_EQ(one.max.z, 4);
    EXPECT_EQ(one.radius(), 0);
    const Bounds none = compute_bounds({});
    EXPECT_EQ(none.radius(), 0);
}

TEST(AnimationSupport, ControlMeshAllQuads) {
    ControlMesh mesh;
    EXPECT_TRUE(mesh.all_quads());
    mesh.face_offsets = {0, 4, 8};
    mesh.face_vertices = {0, 1, 2, 3, 1, 4, 5, 2};
    EXPECT_TRUE(mesh.all_quads());
    mesh.face_offsets.push_back(11);
    mesh.face_vertices.insert(mesh.face_vertices.end(), {4, 6, 5});
    EXPECT_FALSE(mesh.all_quads());
}

TEST(Animation, IsTheIdentityAtTimeZero) {
    std::vector<Vec3> out;
    animate(character(), 0.0f, AnimationParams{}, out);
    ASSERT_EQ(out.size(), character().size());
    for (std::size_t k = 0; k < out.size(); ++k) {
        EXPECT_EQ(out[k].x, character()[k].x);
        EXPECT_EQ(out[k].y, character()[k].y);
        EXPECT_EQ(out[k].z, character()[k].z);
    }
    // And again after whole periods (up to float rounding of the phase).
    animate(character(), 3 * AnimationParams{}.period_seconds, AnimationParams{}, out);
    EXPECT_LT(max_displacement(out, character()), 1e-5f * diagonal(character()));
}

TEST(Animation, DeformsNoticeablyAtAQuarterPeriod) {
    const AnimationParams params;
    std::vector<Vec3> out;
    animate(character(), params.period_seconds / 4, params, out);
    const float d = diagonal(character());
    // The top leans over by about bend_radians * height: far more than float noise.
    EXPECT_GT(max_displacement(out, character()), 0.2f * d);
    // Half a period later the motion reverses: a different shape.
    std::vector<Vec3> later;
    animate(character(), 3 * params.period_seconds / 4, params, later);
    EXPECT_GT(max_displacement(out, later), 0.2f * d);
    for (const Vec3& p : out) EXPECT_TRUE(is_finite(p));
}

TEST(Animation, IsContinuousInTime) {
    const AnimationParams params;
    const float d = diagonal(character());
    std::vector<Vec3> a, b;
    for (float t : {0.0f, 0.1f, 0.5f, 0.77f, 1.0f, 1.5f, 1.99f, 2.0f, 13.3f}) {
        animate(character(), t, params, a);
        animate(character(), t + 1e-3f, params, b);
        // The speed is at most 2*pi/period times the documented bound per unit phase.
        const float limit = 2 * kPi / params.period_seconds * documented_bound(params) * d * 1e-3f;
        EXPECT_LE(max_displacement(a, b), limit) << "t = " << t;
        EXPECT_GT(max_displacement(a, b), 0.0f) << "t = " << t;
    }
}

TEST(Animation, IsSmoothInSpace) {
    // Two nearby rest points stay nearby: the map's local stretch is bounded.
    const AnimationParams params;
    std::vector<Vec3> rest = character();
    const std::size_t n = rest.size();
    const Vec3 offset{1e-3f, -7e-4f, 5e-4f};
    for (std::size_t k = 0; k < n; ++k) rest.push_back(rest[k] + offset);
    std::vector<Vec3> out;
    for (float t : {0.5f, 1.3f}) {
        animate(rest, t, params, out);
        for (std::size_t k = 0; k < n; ++k) EXPECT_LT(length(out[k + n] - out[k]), 2.0f * length(offset)) << k;
    }
}

TEST(Animation, StaysWithinTheDocumentedBound) {
    for (const AnimationParams& params :
         {AnimationParams{}, AnimationParams{1.0f, 2.0f, 0.3f, 1.0f}, AnimationParams{-0.5f, -1.0f, -0.2f, 3.0f}}) {
        for (const std::vector<Vec3>& rest :
             {character(), cloud({10, 20, -5}, {3, 1, 8}, 300), cloud({0, 0, 0}, {5, 5, 5}, 300)}) {
            const float bound = documented_bound(params) * diagonal(rest);
            float worst = 0;
            std::vector<Vec3> out;
            for (int f = 0; f < 64; ++f) {
                animate(rest, f * params.period_seconds / 64, params, out);
                worst = std::max(worst, max_displacement(out, rest));
            }
            EXPECT_LE(worst, bound);
            // The bound is not vacuous: the motion reaches a good part of it.
            EXPECT_GT(worst, 0.25f * bound);
        }
    }
}

TEST(Animation, UsesTheLongestExtentAsTheVerticalAxis) {
    // A tall column along each axis in turn: the points on its central axis are not moved by
    // twist or breathing, and without bend they do not move at all; off-axis points do move.
    for (int axis = 0; axis < 3; ++axis) {
        Vec3 size{1, 1, 1};
        (axis == 0 ? size.x : axis == 1 ? size.y : size.z) = 6;
        std::vector<Vec3> rest = cloud({-0.5f, -0.5f, -0.5f}, size, 200);
        const std::size_t first_axis_point = rest.size();
        for (int k = 0; k <= 10; ++k) {
            Vec3 p{0, 0, 0};
            (axis == 0 ? p.x : axis == 1 ? p.y : p.z) = -0.5f + 0.6f * k;
            rest.push_back(p);
        }
        AnimationParams params;
        params.bend_radians = 0;
        std::vector<Vec3> out;
        animate(rest, params.period_seconds / 4, params, out);
        for (std::size_t k = first_axis_point; k < rest.size(); ++k)
            EXPECT_LT(length(out[k] - rest[k]), 1e-5f) << "axis " << axis << " point " << k;
        EXPECT_GT(max_displacement(out, rest), 0.05f);
        // Heights (along the vertical axis) never change without bend.
        for (std::size_t k = 0; k < rest.size(); ++k)
            EXPECT_NEAR(component(out[k], axis), component(rest[k], axis), 1e-5f);
    }
}

TEST(Animation, TwistTurnsTopAgainstBottom) {
    // Twist only, z-up column: at the peak the top ring turns by +twist/2, the bottom by -twist/2.
    std::vector<Vec3> rest;
    for (int k = 0; k < 8; ++k) {
        const float a = k * kPi / 4;
        rest.push_back({std::cos(a), std::sin(a), 0.0f});
        rest.push_back({std::cos(a), std::sin(a), 5.0f});
    }
    AnimationParams params;
    params.bend_radians = 0;
    params.breathe_amplitude = 0;
    params.twist_radians = 0.4f;
    std::vector<Vec3> out;
    animate(rest, params.period_seconds / 4, params, out);
    for (std::size_t k = 0; k < rest.size(); ++k) {
        const float turned = std::atan2(out[k].y, out[k].x) - std::atan2(rest[k].y, rest[k].x);
        const float wrapped = std::remainder(turned, 2 * kPi);
        EXPECT_NEAR(wrapped, rest[k].z > 1 ? 0.2f : -0.2f, 1e-5f) << k;
        EXPECT_NEAR(std::hypot(out[k].x, out[k].y), 1.0f, 1e-5f);
    }
}

TEST(Animation, BreathingScalesRadially) {
    std::vector<Vec3> rest = cloud({-1, -1, 0}, {2, 2, 5}, 100);
    AnimationParams params;
    params.bend_radians = 0;
    params.twist_radians = 0;
    params.breathe_amplitude = 0.1f;
    std::vector<Vec3> out;
    animate(rest, params.period_seconds / 4, params, out);
    for (std::size_t k = 0; k < rest.size(); ++k) {
        EXPECT_NEAR(out[k].x, 1.1f * rest[k].x, 1e-5f);
        EXPECT_NEAR(out[k].y, 1.1f * rest[k].y, 1e-5f);
        EXPECT_EQ(out[k].z, rest[k].z);
    }
}

TEST(Animation, BendLeansTheTopAndKeepsTheBase) {
    // Bend only: the bottom centre stays, the top centre moves sideways by about
    // height * sin(bend) and distances from the bottom centre are kept (a rotation per height).
    std::vector<Vec3> rest = cloud({-1, -1, 0}, {2, 2, 5}, 100);
    rest.push_back({0, 0, 0});
    rest.push_back({0, 0, 5});
    AnimationParams params;
    params.twist_radians = 0;
    params.breathe_amplitude = 0;
    params.bend_radians = 0.3f;
    std::vector<Vec3> out;
    animate(rest, params.period_seconds / 4, params, out);
    const Vec3 base = out[rest.size() - 2], top = out[rest.size() - 1];
    EXPECT_LT(length(base), 1e-6f);
    EXPECT_NEAR(std::hypot(top.x, top.y), 5 * std::sin(0.3f), 1e-4f);
    EXPECT_NEAR(top.z, 5 * std::cos(0.3f), 1e-4f);
    for (std::size_t k = 0; k < rest.size(); ++k) EXPECT_NEAR(length(out[k]), length(rest[k]), 1e-4f);
}

TEST(Animation, IsDeterministicAndReusesTheOutput) {
    const AnimationParams params;
    std::vector<Vec3> a, b;
    animate(character(), 0.37f, params, a);
    const Vec3* storage = a.data();
    animate(character(), 0.37f, params, b);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
        EXPECT_EQ(a[k].x, b[k].x);
        EXPECT_EQ(a[k].y, b[k].y);
        EXPECT_EQ(a[k].z, b[k].z);
    }
    // A second frame into the same vector reuses its storage (no reallocation per frame).
    animate(character(), 0.91f, params, a);
    EXPECT_EQ(a.data(), storage);
    // In place (out is rest) gives the same result as a separate output.
    std::vector<Vec3> in_place = character();
    animate(in_place, 0.37f, params, in_place);
    for (std::size_t k = 0; k < b.size(); ++k) {
        EXPECT_EQ(in_place[k].x, b[k].x);
        EXPECT_EQ(in_place[k].y, b[k].y);
        EXPECT_EQ(in_place[k].z, b[k].z);
    }
}

TEST(Animation, DegenerateInputsStayFinite) {
    std::vector<Vec3> out{{1, 2, 3}};
    animate({}, 0.5f, AnimationParams{}, out);
    EXPECT_TRUE(out.empty());
    // A single point (zero extent) and a flat sheet (zero extent along two axes).
    const std::vector<Vec3> single{{4, 5, 6}};
    animate(single, 0.5f, AnimationParams{}, out);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].x, 4);
    const std::vector<Vec3> line = cloud({0, 0, 0}, {3, 0, 0}, 50);
    animate(line, 0.5f, AnimationParams{}, out);
    for (const Vec3& p : out) EXPECT_TRUE(is_finite(p));
    // A non-positive period leaves the mesh at rest; a huge time stays finite.
    AnimationParams frozen;
    frozen.period_seconds = 0;
    animate(character(), 0.5f, frozen, out);
    EXPECT_EQ(max_displacement(out, character()), 0.0f);
    animate(character(), 1e9f, AnimationParams{}, out);
    for (const Vec3& p : out) EXPECT_TRUE(is_finite(p));
    EXPECT_LE(max_displacement(out, character()), documented_bound(AnimationParams{}) * diagonal(character()));
}

}  // namespace
}  // namespace patchcull
