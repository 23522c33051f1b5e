// The back-facing ground truth itself (eq. 1 of Loop, Niessner & Eisenacher, "Effective Back-Patch Culling for
// Hardware Tessellation"): tangent planes and tessellation
// triangles, checked on cases whose answer is known.
#include <gtest/gtest.h>

#include <random>

#include "patchcull/core/ground_truth.h"
#include "patchcull/core/teapot.h"

using namespace patchcull;

namespace {

// A bilinear-like flat patch in the z = 0 plane, du x dv = +z.
BezierPatch flat_patch() {
    BezierPatch p;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) p.cp[4 * j + i] = {float(i), float(j), 0, 1};
    return p;
}

std::vector<PlaneD> planes_of(const BezierPatch& p, int grid) {
    std::vector<PlaneD> planes(grid * grid);
    sample_tangent_planes(p, grid, planes.data());
    return planes;
}

std::vector<PointD> points_of(const BezierPatch& p, int grid) {
    std::vector<PointD> pts(grid * grid);
    sample_patch_points(p, grid, pts.data());
    return pts;
}

}  // namespace

TEST(BackfaceTruth, FlatPatchFacesOnlyEyesOnItsNormalSide) {
    const BezierPatch p = flat_patch();
    const auto planes = planes_of(p, 17);
    const auto pts = points_of(p, 17);
    EXPECT_TRUE(any_plane_faces_eye(planes.data(), planes.size(), {1.5f, 1.5f, 2.0f}));
    EXPECT_FALSE(any_plane_faces_eye(planes.data(), planes.size(), {1.5f, 1.5f, -2.0f}));
    EXPECT_FALSE(any_plane_faces_eye(planes.data(), planes.size(), {10.0f, 1.5f, 0.0f}));  // edge-on
    EXPECT_TRUE(any_tessellation_triangle_faces_eye(pts.data(), 17, {1.5f, 1.5f, 2.0f}));
    EXPECT_FALSE(any_tessellation_triangle_faces_eye(pts.data(), 17, {1.5f, 1.5f, -2.0f}));
    EXPECT_FALSE(any_tessellation_triangle_faces_eye(pts.data(), 17, {10.0f, 1.5f, 0.0f}));
}

TEST(BackfaceTruth, TangentPlaneIsNormalAndPositionForPolynomialPatches) {
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> c(-1, 1);
    BezierPatch p;
    for (int k = 0; k < 16; ++k) {
        const int col = k % 4, row = k / 4;
        p.cp[k] = {float(col) + 0.3f * c(rng), float(row) + 0.3f * c(rng), c(rng), 1};
    }
    const auto planes = planes_of(p, 5);
    for (int j = 0; j < 5; ++j)
        for (int i = 0; i < 5; ++i) {
            const SurfacePoint s = evaluate_surface(p, i / 4.0f, j / 4.0f);
            const PlaneD& t = planes[j * 5 + i];
            EXPECT_NEAR(t.x, s.normal.x, 1e-4);
            EXPECT_NEAR(t.y, s.normal.y, 1e-4);
            EXPECT_NEAR(t.z, s.normal.z, 1e-4);
            EXPECT_NEAR(t.w, -dot(s.normal, s.position), 1e-4);
        }
}

TEST(BackfaceTruth, RationalWeightsScaleThePlaneNotItsSide) {
    // Multiplying every homogeneous control point by c > 0 leaves the surface unchanged and
    // scales T by c^3: the facing decision must not change.
    std::mt19937 rng(10);
    std::uniform_real_distribution<float> c(-1, 1), w(0.5f, 2.0f);
    for (int trial = 0; trial < 50; ++trial) {
        BezierPatch p, q;
        for (int k = 0; k < 16; ++k) {
            const int col = k % 4, row = k / 4;
            p.cp[k] = homogeneous({float(col) + 0.4f * c(rng), float(row) + 0.4f * c(rng), 0.6f * c(rng)}, w(rng));
            q.cp[k] = p.cp[k] * 3.0f;
        }
        const auto a = planes_of(p, 9), b = planes_of(q, 9);
        const Vec3 eye{2 * c(rng), 2 * c(rng), 3 * c(rng)};
        EXPECT_EQ(any_plane_faces_eye(a.data(), a.size(), eye), any_plane_faces_eye(b.data(), b.size(), eye));
    }
}

TEST(BackfaceTruth, TeapotDegenerateTopHasZeroPlanesOnItsCollapsedEdge) {
    // The lid knob's v = 0 edge collapses to a point: T vanishes there (the reason for Loop, Niessner &
    // Eisenacher's Pcnt rule). Patches 20-23 are the knob.
    const auto patches = teapot_patches();
    const auto planes = planes_of(patches[20], 17);
    for (int i = 0; i < 17; ++i) {
        const PlaneD& t = planes[i];
        EXPECT_NEAR(t.x * t.x + t.y * t.y + t.z * t.z, 0.0, 1e-10);
    }
    // The zero planes never count as facing, whichever the eye; the knob's top faces an eye above.
    EXPECT_FALSE(any_plane_faces_eye(planes.data(), 17, {0, 0, 100.0f}));
    EXPECT_FALSE(any_plane_faces_eye(planes.data(), 17, {0, 0, -100.0f}));
    EXPECT_TRUE(any_plane_faces_eye(planes.data(), planes.size(), {0, 0, 100.0f}));
}
