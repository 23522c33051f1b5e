// The depth conventions engines use (clip_space.h): zero-to-one, minus-one-to-one, reversed and
// reversed with an infinite far plane. One camera written in each convention, with its own depth
// buffer, gets the decisions of the zero-to-one form from every depth-sensitive CPU entry (up to
// patches within float rounding of a plane), none of them culls a patch that has a dense sample
// visible in that convention, and a matrix that contradicts its declared convention is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "patchcull/core/camera.h"
#include "patchcull/core/clip_space.h"
#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/fused_cull.h"
#include "patchcull/core/ground_truth.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/teapot.h"

#include "core/test_patches.h"

using namespace patchcull;

namespace {

constexpr ClipDepth kConventions[] = {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one, ClipDepth::reversed,
                                      ClipDepth::reversed_infinite};

// Window depth (glDepthRange(0, 1)) of view distance t under projection p of convention depth.
double window_depth(const Mat4& p, ClipDepth depth, double t) {
    const double z = -double(p.at(2, 2)) * t + double(p.at(2, 3));  // view z = -t, w_view = 1
    const double ndc = z / t;
    return depth == ClipDepth::minus_one_to_one ? 0.5 * (ndc + 1.0) : ndc;
}

// True when the world point s is inside the clip volume of convention depth (double).
bool visible_in(const Mat4& object_to_clip, ClipDepth depth, Vec3 s) {
    double c[4];
    for (int r = 0; r < 4; ++r)
        c[r] = double(object_to_clip.at(r, 0)) * s.x + double(object_to_clip.at(r, 1)) * s.y +
               double(object_to_clip.at(r, 2)) * s.z + double(object_to_clip.at(r, 3));
    const double x = c[0], y = c[1], z = c[2], w = c[3];
    const double slack = 1e-5 * w;  // a sample this close to a plane may go either way
    if (!(w > 0) || x < -w - slack || x > w + slack || y < -w - slack || y > w + slack) return false;
    switch (depth) {
        case ClipDepth::zero_to_one:
        case ClipDepth::reversed:
            return z >= -slack && z <= w + slack;
        case ClipDepth::minus_one_to_one:
            return z >= -w - slack && z <= w + slack;
        case ClipDepth::reversed_infinite:
            return z <= w + slack;
    }
    return false;
}

std::size_t count_differences(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < a.size(); ++i) n += a[i] != b[i];
    return n;
}

}  // namespace

TEST(DepthConventions, PerspectiveMapsNearAndFarInEachConvention) {
    for (ClipDepth depth : kConventions) {
        const Mat4 p = perspective(1.0f, 1.5f, 0.5f, 20.0f, depth);
        const Vec4 n = p * Vec4{0, 0, -0.5f, 1}, f = p * Vec4{0, 0, -20.0f, 1};
        const float near_depth = depth == ClipDepth::zero_to_one        ? 0.0f
                                 : depth == ClipDepth::minus_one_to_one ? -1.0f
                                                                        : 1.0f;
        EXPECT_NEAR(n.z / n.w, near_depth, 1e-6f) << clip_depth_name(depth);
        if (depth == ClipDepth::reversed_infinite) {
            EXPECT_NEAR(f.z / f.w, 0.5f / 20.0f, 1e-6f);  // near / distance
        } else {
            EXPECT_NEAR(f.z / f.w, is_reversed(depth) ? 0.0f : 1.0f, 1e-6f) << clip_depth_name(depth);
        }
        ClipDepth parsed;
        ASSERT_TRUE(parse_clip_depth(clip_depth_name(depth), parsed));
        EXPECT_EQ(parsed, depth);
    }
    // An infinite far plane gives a finite matrix.
    const Mat4 inf =
        perspective(1.0f, 1.0f, 0.1f, std::numeric_limits<float>::infinity(), ClipDepth::reversed_infinite);
    for (float v : inf.m) EXPECT_TRUE(std::isfinite(v));
    ClipDepth unused;
    EXPECT_FALSE(parse_clip_depth("reverse", unused));
}

// Every CPU entry with a depth convention, on one camera written in each convention, with a wall
// at view distance between the teapot's near and far ends covering the left half of the screen.
TEST(DepthConventions, EveryEntryDecidesAsZeroToOneAndCullsNothingVisible) {
    const std::vector<BezierPatch> patches = test_patches::split_teapot(2);
    const PatchBatch batch = make_batch(patches);
    const std::size_t n = patches.size();
    constexpr int kGrid = 9;
    std::vector<Vec3> samples(n * kGrid * kGrid);
    const Vec2 uv[4] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
    for (std::size_t i = 0; i < n; ++i)
        sample_displaced_patch(patches[i], nullptr, uv, nullptr, kGrid, &samples[i * kGrid * kGrid]);
    constexpr int W = 64, H = 48;
    ViewGenerator views(test_patches::control_point_bounds(patches), ViewMode::free, 23, float(W) / H);
    std::size_t differences = 0, decisions = 0;
    std::size_t culled[4] = {}, occluded[4] = {};
    for (int v = 0; v < 40; ++v) {
        const Camera camera = views.next();
        const Mat4 view = camera.view();
        // The wall's distance: the teapot's centre distance (so some patches are in front of it).
        const Vec4 centre = view * Vec4{0, 0, 0.75f, 1};
        const double t_wall = std::max(double(-centre.z), 2.0 * camera.z_near);
        std::vector<std::uint8_t> reference[4];  // zero-to-one: frustum, frustum-disp, occlusion, displaced
        for (int ci = 0; ci < 4; ++ci) {
            const ClipDepth depth = kConventions[ci];
            const Mat4 proj = perspective(camera.fovy_radians, camera.aspect, camera.z_near, camera.z_far, depth);
            const Mat4 m = proj * view;
            const float wall = static_cast<float>(window_depth(proj, depth, t_wall));
            std::vector<float> buffer(W * H, is_reversed(depth) ? 0.0f : 1.0f);
            for (int y = 0; y < H; ++y)
                for (int x = 0; x < W / 2; ++x) buffer[y * W + x] = wall;
            HiZPyramid hiz;
            hiz.build(buffer.data(), W, H, depth);

            std::vector<std::uint8_t> frustum(n), frustum_simd(n), disp(n), disp_simd(n), occ(n), occ_simd(n), fused(n),
                displaced(n), displaced_occ(n);
            const FrustumPlanes planes = make_frustum_planes(m, depth);
            cull_frustum_scalar(batch.view(), nullptr, planes, frustum.data());
            cull_frustum_simd(batch.view(), nullptr, planes, frustum_simd.data());
            EXPECT_EQ(frustum, frustum_simd);
            cull_frustum_disp_scalar(batch.view(), nullptr, m, depth, disp.data());
            cull_frustum_disp_simd(batch.view(), nullptr, m, depth, disp_simd.data());
            EXPECT_EQ(disp, disp_simd);
            cull_occlusion_scalar(batch.view(), m, depth, hiz, occ.data());
            cull_occlusion_simd(batch.view(), m, depth, hiz, occ_simd.data());
            EXPECT_EQ(occ, occ_simd);
            FusedPlan fh;
            fh.stages[0] = FusedStage::frustum;
            fh.stages[1] = FusedStage::occlusion;
            fh.count = 2;
            cull_fused_simd(batch.view(), make_fused_setup(m, depth, camera.eye, BackPatchCone::tcone, &hiz), fh,
                            fused.data(), nullptr);
            EXPECT_EQ(fused, occ);
            const DisplacedCullView dview = make_displaced_cull_view(view, proj, depth);
            cull_displaced_occlusion(batch.view(), nullptr, DisplacedBoundKind::caf, NormalConeKind::full, dview, hiz,
                                     displaced_occ.data());
            cull_displaced_frustum(batch.view(), nullptr, DisplacedBoundKind::caf, NormalConeKind::full, dview,
                                   displaced.data());

            // Ground truth: a visible sample in front of the wall or right of it keeps its patch.
            for (std::size_t i = 0; i < n; ++i) {
                bool any_visible = false, any_unhidden = false;
                for (int s = 0; s < kGrid * kGrid; ++s) {
                    const Vec3 p = samples[i * kGrid * kGrid + s];
                    if (!visible_in(m, depth, p)) continue;
                    any_visible = true;
                    const Vec4 c = m * Vec4{p.x, p.y, p.z, 1};
                    const double t = -double((view * Vec4{p.x, p.y, p.z, 1}).z);
                    if (c.x / c.w >= -1e-4f || t < t_wall * (1 - 1e-5)) any_unhidden = true;
                }
                const std::string where =
                    std::string(clip_depth_name(depth)) + " view " + std::to_string(v) + " patch " + std::to_string(i);
                if (any_visible) {
                    EXPECT_EQ(frustum[i], 0) << where;
                    EXPECT_EQ(disp[i], 0) << where;
                    EXPECT_NE(occ[i], kHiZFrustumCulled) << where;
                    EXPECT_EQ(displaced[i], 0) << where;
                }
                if (any_unhidden) {
                    EXPECT_EQ(occ[i], kHiZVisible) << where;
                    EXPECT_EQ(displaced_occ[i], kHiZVisible) << where;
                }
                culled[ci] += frustum[i];
                occluded[ci] += occ[i] == kHiZOccluded;
            }
            if (ci == 0) {
                reference[0] = frustum;
                reference[1] = disp;
                reference[2] = occ;
                reference[3] = displaced_occ;
            } else if (depth != ClipDepth::reversed_infinite) {  // same clip volume as zero-to-one
                differences += count_differences(reference[0], frustum) + count_differences(reference[1], disp) +
                               count_differences(reference[2], occ) + count_differences(reference[3], displaced_occ);
                decisions += 4 * n;
            }
        }
    }
    EXPECT_LE(differences, decisions / 1000) << differences << " of " << decisions;
    for (int ci = 0; ci < 4; ++ci) {  // not vacuous: every convention culls and occludes
        EXPECT_GT(culled[ci], n) << clip_depth_name(kConventions[ci]);
        EXPECT_GT(occluded[ci], n / 4) << clip_depth_name(kConventions[ci]);
    }
}

// A reversed matrix declared forward (what the old API forced on engines: 139-147 visible patches
// culled per frame) and a forward one declared reversed are refused, with one line naming the
// entry; so is a pyramid of the other direction. Orthographic matrices cannot be told apart.
TEST(DepthConventions, ContradictingMatricesAndPyramidsAreRefused) {
    const Camera camera;
    const std::vector<BezierPatch> patches = teapot_patches();
    const PatchBatch batch = make_batch(patches);
    std::vector<std::uint8_t> out(patches.size());
    HiZPyramid forward_hiz, reversed_hiz;
    const std::vector<float> depth(16 * 16, 0.5f);
    forward_hiz.build(depth.data(), 16, 16, ClipDepth::zero_to_one);
    reversed_hiz.build(depth.data(), 16, 16, ClipDepth::reversed);
    EXPECT_TRUE(reversed_hiz.reversed());
    EXPECT_EQ(reversed_hiz.texel(0, 0, 0), -0.5f);
    for (ClipDepth made : kConventions) {
        const Mat4 proj = perspective(camera.fovy_radians, 1.0f, 0.1f, 100.0f, made);
        const Mat4 m = proj * camera.view();
        for (ClipDepth declared : kConventions) {
            const bool contradicts = is_reversed(made) != is_reversed(declared);
            const HiZPyramid& hiz = is_reversed(declared) ? reversed_hiz : forward_hiz;
            auto expect = [&](const char* entry, auto&& call) {  // entry: what a failure names
                if (!contradicts) {
                    EXPECT_NO_THROW(call()) << entry;
                    return;
                }
                try {
                    call();
                    ADD_FAILURE() << entry << " accepted a " << clip_depth_name(made) << " matrix declared "
                                  << clip_depth_name(declared);
                } catch (const Error& e) {
                    const std::string what = e.what();
                    EXPECT_NE(what.find(std::string("declared ") + clip_depth_name(declared)), std::string::npos)
                        << what;
                    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
                }
            };
            expect("make_frustum_planes", [&] { (void)make_frustum_planes(m, declared); });
            expect("cull_frustum_disp_simd",
                   [&] { cull_frustum_disp_simd(batch.view(), nullptr, m, declared, out.data()); });
            expect("cull_occlusion_scalar", [&] { cull_occlusion_scalar(batch.view(), m, declared, hiz, out.data()); });
            expect("cull_occlusion_simd", [&] { cull_occlusion_simd(batch.view(), m, declared, hiz, out.data()); });
            expect("make_displaced_cull_view", [&] { (void)make_displaced_cull_view(camera.view(), proj, declared); });
            expect("make_frustum_planes",
                   [&] { (void)make_fused_setup(m, declared, camera.eye, BackPatchCone::tcone, &hiz); });
        }
        // A pyramid of the other direction.
        const HiZPyramid& wrong = is_reversed(made) ? forward_hiz : reversed_hiz;
        EXPECT_THROW(cull_occlusion_scalar(batch.view(), m, made, wrong, out.data()), Error);
        EXPECT_THROW(cull_occlusion_simd(batch.view(), m, made, wrong, out.data()), Error);
        EXPECT_THROW((void)make_fused_setup(m, made, camera.eye, BackPatchCone::tcone, &wrong), Error);
    }
    // Orthographic: the eye is at infinity, nothing to detect; accepted in every convention.
    Mat4 ortho;
    ortho.at(0, 0) = 0.1f;
    ortho.at(1, 1) = 0.1f;
    ortho.at(2, 2) = -0.01f;
    ortho.at(2, 3) = 0.0f;
    for (ClipDepth declared : kConventions) EXPECT_NO_THROW((void)make_frustum_planes(ortho * camera.view(), declared));
    HiZPyramid never_built;
    EXPECT_THROW(
        cull_occlusion_scalar(batch.view(), camera.view_projection(), ClipDepth::zero_to_one, never_built, out.data()),
        Error);
}

// No far plane: a patch a million near distances away in view is kept by every kernel with
// reversed_infinite (no far plane test, no division by zero), and culled beyond a finite far plane.
TEST(DepthConventions, InfiniteFarPlaneKeepsDistantPatches) {
    BezierPatch far_patch;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i)
            far_patch.cp[4 * j + i] = {1000.0f * (i - 1.5f), 1000.0f * (j - 1.5f), -1.0e6f, 1.0f};
    const PatchBatch batch = make_batch({far_patch});
    const Camera camera;  // at (0, 0, 5) looking down -z
    for (ClipDepth depth : {ClipDepth::reversed_infinite, ClipDepth::reversed}) {
        const Mat4 proj =
            perspective(camera.fovy_radians, 1.0f, 0.1f,
                        depth == ClipDepth::reversed ? 1000.0f : std::numeric_limits<float>::infinity(), depth);
        const Mat4 m = proj * camera.view();
        const std::uint8_t expected = depth == ClipDepth::reversed ? 1 : 0;
        std::uint8_t a = 9, b = 9, c = 9, d = 9;
        cull_frustum_scalar(batch.view(), nullptr, make_frustum_planes(m, depth), &a);
        cull_frustum_simd(batch.view(), nullptr, make_frustum_planes(m, depth), &b);
        cull_frustum_disp_scalar(batch.view(), nullptr, m, depth, &c);
        cull_frustum_disp_simd(batch.view(), nullptr, m, depth, &d);
        EXPECT_EQ(a, expected) << clip_depth_name(depth);
        EXPECT_EQ(b, expected) << clip_depth_name(depth);
        EXPECT_EQ(c, expected) << clip_depth_name(depth);
        EXPECT_EQ(d, expected) << clip_depth_name(depth);
        std::uint8_t disp = 9;
        cull_displaced_frustum(batch.view(), nullptr, DisplacedBoundKind::caf, NormalConeKind::full,
                               make_displaced_cull_view(camera.view(), proj, depth), &disp);
        EXPECT_EQ(disp, expected) << clip_depth_name(depth);
    }
}

// 24-bit depth: each texel key is at least the far end of the depths that store the same integer,
// forward and reversed, in both word layouts.
TEST(DepthConventions, Unorm24PyramidKeysCoverTheQuantizedDepths) {
    std::mt19937 rng(7);
    constexpr int W = 5, H = 3;
    const long double kMax = 16777215.0L;
    for (int trial = 0; trial < 200; ++trial) {
        std::vector<std::uint32_t> u(W * H), words_high(W * H);
        for (std::uint32_t& v : u) {
            const int kind = trial % 4;
            v = kind == 0 ? 0u : kind == 1 ? 0xFFFFFFu : static_cast<std::uint32_t>(rng() & 0xFFFFFFu);
        }
        for (int i = 0; i < W * H; ++i) words_high[i] = (u[i] << 8) | 0x5Au;  // stencil in the low byte
        for (ClipDepth depth : {ClipDepth::zero_to_one, ClipDepth::reversed}) {
            HiZPyramid low, high;
            low.build_unorm24(u.data(), W, H, 0, depth);
            high.build_unorm24(words_high.data(), W, H, 8, depth);
            ASSERT_EQ(low.size(), high.size());
            for (std::size_t t = 0; t < low.size(); ++t) EXPECT_EQ(low.data()[t], high.data()[t]);
            // The top texel covers every pixel.
            const float top = low.texel(low.levels() - 1, 0, 0);
            for (std::uint32_t v : u) {
                const long double far_end = is_reversed(depth) ? -(v - 0.5L) / kMax : (v + 0.5L) / kMax;
                EXPECT_GE(static_cast<long double>(top), far_end) << v;
            }
        }
    }
}
