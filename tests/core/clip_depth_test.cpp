// The clip-depth convention is explicit (clip_space.h): one camera written as a
// zero-to-one projection (patchcull's, GL_ZERO_TO_ONE) or as a standard OpenGL one (depth
// -1..1) gets the same decisions from every depth-sensitive entry, when the caller names the
// convention. Before, the entries took a bare matrix and read every matrix as zero-to-one: an
// OpenGL projection then had its near plane at about twice the distance and the frustum test
// culled most visible patches (1146 of BigGuy's 1450 in one view), which the last test shows
// is what such a misreading does.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/camera.h"
#include "patchcull/core/clip_space.h"
#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/ground_truth.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/teapot.h"

#include "core/test_patches.h"

using namespace patchcull;

namespace {

struct Pair {
    Mat4 zo, no;  // the same camera: zero_to_one and minus_one_to_one object_to_clip
    Mat4 view, proj_zo, proj_no;
    float alpha_zo, alpha_no;
};

Pair both_conventions(const Camera& c) {
    Pair p;
    p.view = c.view();
    p.proj_zo = perspective(c.fovy_radians, c.aspect, c.z_near, c.z_far, ClipDepth::zero_to_one);
    p.proj_no = perspective(c.fovy_radians, c.aspect, c.z_near, c.z_far, ClipDepth::minus_one_to_one);
    p.zo = p.proj_zo * p.view;
    p.no = p.proj_no * p.view;
    p.alpha_zo = clip_space_eye_alpha(p.proj_zo);
    p.alpha_no = clip_space_eye_alpha(p.proj_no);
    return p;
}

std::size_t count_differences(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < a.size(); ++i) n += a[i] != b[i];
    return n;
}

std::size_t count_set(const std::vector<std::uint8_t>& a) {
    std::size_t n = 0;
    for (std::uint8_t v : a) n += v != 0;
    return n;
}

}  // namespace

TEST(ClipDepth, PerspectiveMapsNearAndFarToEachConventionsDepth) {
    for (ClipDepth depth : {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one}) {
        const Mat4 p = perspective(1.0f, 1.5f, 0.5f, 20.0f, depth);
        const Vec4 near_point = p * Vec4{0, 0, -0.5f, 1}, far_point = p * Vec4{0, 0, -20.0f, 1};
        EXPECT_NEAR(near_point.z / near_point.w, depth == ClipDepth::zero_to_one ? 0.0f : -1.0f, 1e-6f);
        EXPECT_NEAR(far_point.z / far_point.w, 1.0f, 1e-6f);
        // to_zero_to_one gives patchcull's convention from either.
        const Mat4 q = to_zero_to_one(p, depth);
        const Vec4 n2 = q * Vec4{0, 0, -0.5f, 1}, f2 = q * Vec4{0, 0, -20.0f, 1};
        EXPECT_NEAR(n2.z / n2.w, 0.0f, 1e-6f);
        EXPECT_NEAR(f2.z / f2.w, 1.0f, 1e-6f);
    }
    EXPECT_STREQ(clip_depth_name(ClipDepth::minus_one_to_one), "minus-one-to-one");
}

// frustum, frustum-disp, the Hi-Z test, the displaced-patch bounds and ptp: the same decisions
// for one camera in either convention (up to patches within float rounding of a plane: the two
// matrices' z rows differ by a rounding), and none of them culls a patch with a sample inside
// the view volume.
TEST(ClipDepth, EveryDepthSensitiveEntryDecidesAlikeInBothConventions) {
    const std::vector<BezierPatch> patches = test_patches::split_teapot(2);
    const PatchBatch batch = make_batch(patches);
    const std::size_t n = patches.size();
    constexpr int kGrid = 9;
    std::vector<Vec3> samples(n * kGrid * kGrid);
    const Vec2 uv[4] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
    for (std::size_t i = 0; i < n; ++i)
        sample_displaced_patch(patches[i], nullptr, uv, nullptr, kGrid, &samples[i * kGrid * kGrid]);
    // A Hi-Z pyramid of a wall at window depth 0.2 over the left half of a 64x64 screen.
    constexpr int W = 64, H = 64;
    std::vector<float> depth(W * H, 1.0f);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W / 2; ++x) depth[y * W + x] = 0.2f;
    HiZPyramid hiz;
    hiz.build(depth.data(), W, H);

    ViewGenerator views(test_patches::control_point_bounds(patches), ViewMode::free, 11);
    std::size_t decisions = 0, differences = 0, frustum_culled = 0, occluded = 0, ptp_culled = 0;
    for (int v = 0; v < 60; ++v) {
        const Pair c = both_conventions(views.next());
        std::vector<std::uint8_t> a(n), b(n);
        cull_frustum_scalar(batch.view(), nullptr, make_frustum_planes(c.zo, ClipDepth::zero_to_one), a.data());
        cull_frustum_simd(batch.view(), nullptr, make_frustum_planes(c.no, ClipDepth::minus_one_to_one), b.data());
        differences += count_differences(a, b);
        frustum_culled += count_set(b);
        for (std::size_t i = 0; i < n; ++i)
            if (b[i]) {
                EXPECT_FALSE(any_point_in_clip_volume(c.zo, &samples[i * kGrid * kGrid], kGrid * kGrid))
                    << v << " " << i;
            }

        cull_frustum_disp_scalar(batch.view(), nullptr, c.zo, ClipDepth::zero_to_one, a.data());
        cull_frustum_disp_simd(batch.view(), nullptr, c.no, ClipDepth::minus_one_to_one, b.data());
        differences += count_differences(a, b);

        cull_occlusion_scalar(batch.view(), c.zo, ClipDepth::zero_to_one, hiz, a.data());
        cull_occlusion_simd(batch.view(), c.no, ClipDepth::minus_one_to_one, hiz, b.data());
        differences += count_differences(a, b);
        for (std::uint8_t d : b) occluded += d == kHiZOccluded;

        cull_displaced_frustum(batch.view(), nullptr, DisplacedBoundKind::caf, NormalConeKind::full,
                               make_displaced_cull_view(c.view, c.proj_zo, ClipDepth::zero_to_one), a.data());
        cull_displaced_frustum(batch.view(), nullptr, DisplacedBoundKind::caf, NormalConeKind::full,
                               make_displaced_cull_view(c.view, c.proj_no, ClipDepth::minus_one_to_one), b.data());
        differences += count_differences(a, b);

        // ptp reads rows x, y, w and the sign of alpha only: identical in both conventions.
        cull_ptp_scalar(batch.view(), c.zo, c.alpha_zo, PtpRule::ncnt, a.data());
        cull_ptp_scalar(batch.view(), c.no, c.alpha_no, PtpRule::ncnt, b.data());
        EXPECT_EQ(count_differences(a, b), 0u) << v;
        ptp_culled += count_set(b);
        decisions += 4 * n;
    }
    EXPECT_LE(differences, decisions / 2000) << differences << " of " << decisions;
    // Not vacuous: each test culls in these views.
    EXPECT_GT(frustum_culled, n * 60 / 5);
    EXPECT_GT(occluded, 100u);
    EXPECT_GT(ptp_culled, 100u);
}

// What naming the convention prevents: an OpenGL matrix read as zero-to-one (all the old API
// could do) has its near plane at 2fn/(f+n) and culls patches that are in view.
TEST(ClipDepth, MisreadingAnOpenGlMatrixCullsVisiblePatches) {
    const std::vector<BezierPatch> patches = test_patches::split_teapot(2);
    const PatchBatch batch = make_batch(patches);
    const std::size_t n = patches.size();
    ViewGenerator views(test_patches::control_point_bounds(patches), ViewMode::contain, 5);
    std::size_t right = 0, misread = 0;
    for (int v = 0; v < 20; ++v) {
        const Pair c = both_conventions(views.next());
        std::vector<std::uint8_t> culled(n);
        cull_frustum_scalar(batch.view(), nullptr, make_frustum_planes(c.no, ClipDepth::minus_one_to_one),
                            culled.data());
        right += count_set(culled);
        cull_frustum_scalar(batch.view(), nullptr, make_frustum_planes(c.no, ClipDepth::zero_to_one), culled.data());
        misread += count_set(culled);
    }
    EXPECT_EQ(right, 0u);   // contain views: the whole teapot is in view
    EXPECT_GT(misread, n);  // the misread near plane cuts into the teapot in many views
}
