// Cameras: projection conventions and the random view generators' guarantees.
#include <gtest/gtest.h>

#include "patchcull/core/camera.h"
#include "patchcull/core/ground_truth.h"

using namespace patchcull;

TEST(Camera, PerspectiveMapsNearToZeroAndFarToOne) {
    const Mat4 p = perspective(1.0f, 1.5f, 0.5f, 20.0f);
    const Vec4 n = p * Vec4{0, 0, -0.5f, 1};
    const Vec4 f = p * Vec4{0, 0, -20.0f, 1};
    EXPECT_NEAR(n.z / n.w, 0.0f, 1e-6f);
    EXPECT_NEAR(f.z / f.w, 1.0f, 1e-6f);
    EXPECT_GT(n.w, 0.0f);
}

TEST(Camera, LookAtPutsTargetOnTheViewAxis) {
    const Mat4 v = look_at({1, 2, 3}, {4, -1, 7}, {0, 1, 0});
    const Vec4 t = v * Vec4{4, -1, 7, 1};
    EXPECT_NEAR(t.x, 0.0f, 1e-5f);
    EXPECT_NEAR(t.y, 0.0f, 1e-5f);
    EXPECT_LT(t.z, 0.0f);
    Mat4 inv;
    ASSERT_TRUE(invert(v, inv));
    const Vec4 eye = inv * Vec4{0, 0, 0, 1};
    EXPECT_NEAR(eye.x, 1.0f, 1e-5f);
    EXPECT_NEAR(eye.z, 3.0f, 1e-5f);
}

TEST(Camera, ContainViewsHoldTheWholeBoundingBox) {
    const Bounds b{{-1, -2, -0.5f}, {3, 1, 0.25f}};
    for (float aspect : {1.0f, 0.5f, 1.777f}) {
        ViewGenerator views(b, ViewMode::contain, 42, aspect);
        for (int i = 0; i < 3000; ++i) {
            const Camera c = views.next();
            const Mat4 m = c.view_projection();
            for (int k = 0; k < 8; ++k) {
                const Vec3 corner{k & 1 ? b.max.x : b.min.x, k & 2 ? b.max.y : b.min.y, k & 4 ? b.max.z : b.min.z};
                ASSERT_TRUE(any_point_in_clip_volume(m, &corner, 1)) << "view " << i << " corner " << k;
            }
        }
    }
}

TEST(Camera, FreeViewsGoInsideTheObjectAndCutWithTheNearPlane) {
    const Bounds b{{-1, -1, -1}, {1, 1, 1}};
    ViewGenerator views(b, ViewMode::free, 7);
    int inside = 0, small_near = 0;
    for (int i = 0; i < 2000; ++i) {
        const Camera c = views.next();
        if (std::abs(c.eye.x) < 1 && std::abs(c.eye.y) < 1 && std::abs(c.eye.z) < 1) ++inside;
        if (c.z_near < 0.01f * b.radius()) ++small_near;
        EXPECT_GT(c.z_far, c.z_near);
    }
    EXPECT_GT(inside, 100);
    EXPECT_GT(small_near, 50);
}

TEST(Camera, GeneratorsAreDeterministicPerSeed) {
    const Bounds b{{0, 0, 0}, {1, 1, 1}};
    ViewGenerator a(b, ViewMode::free, 5), c(b, ViewMode::free, 5), d(b, ViewMode::free, 6);
    const Camera ca = a.next(), cc = c.next(), cd = d.next();
    EXPECT_EQ(ca.eye.x, cc.eye.x);
    EXPECT_EQ(ca.target.z, cc.target.z);
    EXPECT_NE(ca.eye.x, cd.eye.x);
}

TEST(Camera, OrbitSequenceTurnsAroundTheObject) {
    const Bounds b{{-1, -1, -1}, {1, 1, 1}};
    const auto cams = orbit_sequence(b, 8, 45.0f);
    ASSERT_EQ(cams.size(), 8u);
    EXPECT_NEAR(cams[0].eye.x, -cams[4].eye.x, 1e-4f);
    EXPECT_NEAR(cams[0].eye.z, -cams[4].eye.z, 1e-4f);
    for (const Camera& c : cams)
        for (int k = 0; k < 8; ++k) {
            const Vec3 corner{k & 1 ? 1.f : -1.f, k & 2 ? 1.f : -1.f, k & 4 ? 1.f : -1.f};
            EXPECT_TRUE(any_point_in_clip_volume(c.view_projection(), &corner, 1));
        }
}

TEST(GroundTruth, SphereShortcutNeverHidesAVisiblePoint) {
    // For random point clouds and views: whenever the sphere test says "outside", no point may be
    // inside; and the shortcut must fire sometimes (or it would be useless, not wrong).
    std::uint32_t state = 12345;
    auto next = [&state]() {
        state = state * 1664525u + 1013904223u;
        return (state >> 8) * (1.0f / 16777216.0f);
    };
    const Bounds b{{-1, -1, -1}, {1, 1, 1}};
    ViewGenerator views(b, ViewMode::free, 3);
    int fired = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        const Mat4 m = views.next().view_projection();
        Vec3 pts[40];
        const Vec3 c{4 * next() - 2, 4 * next() - 2, 4 * next() - 2};
        const float spread = 0.5f * next();
        for (Vec3& p : pts) p = c + Vec3{spread * (next() - 0.5f), spread * (next() - 0.5f), spread * (next() - 0.5f)};
        const SampleSphere s = bounding_sphere(pts, 40);
        for (const Vec3& p : pts) ASSERT_LE(length(p - s.center), s.radius);
        if (sphere_outside_clip_volume(m, s)) {
            ++fired;
            ASSERT_FALSE(any_point_in_clip_volume(m, pts, 40)) << trial;
        }
    }
    EXPECT_GT(fired, 500);
}
