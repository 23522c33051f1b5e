// Hi-Z pyramid and occlusion test (patchcull/core/hiz.h): the pyramid against brute-force maxima over
// exact footprints (NPOT sizes, and against the POT-enlarged, zero-padded map of Niessner & Loop,
// "Patch-Based Occlusion Culling for Hardware Tessellation"), level
// selection against a brute-force search (and a `floor` level that under-covers), hand-built
// decisions, SIMD == scalar on every target, and ground truth: a tiny CPU rasterizer (pixel centres,
// interpolated depth, less-test) draws random occluders, and no sample of an occluded patch's
// dense 17x17 grid may be in front of the depth buffer. Deliberately broken deciders (floor level,
// max z instead of min z) run through the same check and must be caught.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "patchcull/core/frustum.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"

using namespace patchcull;

namespace {

constexpr float kPi = 3.14159265358979f;

// ---- brute-force pyramid ----------------------------------------------------------------------

// T_l(tx, ty) by definition: the max over every depth pixel (x, y) with x >> (l+1) == tx and
// y >> (l+1) == ty.
std::vector<std::vector<float>> brute_pyramid(const std::vector<float>& depth, int W, int H, const HiZPyramid& hiz) {
    std::vector<std::vector<float>> levels(hiz.levels());
    for (int l = 0; l < hiz.levels(); ++l) {
        const HiZLevel& lv = hiz.level(l);
        levels[l].assign(static_cast<std::size_t>(lv.width) * lv.height, -1.0f);  // below every depth
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                float& t = levels[l][static_cast<std::size_t>(y >> (l + 1)) * lv.width + (x >> (l + 1))];
                t = std::max(t, depth[static_cast<std::size_t>(y) * W + x]);
            }
    }
    return levels;
}

std::vector<float> random_depth(std::mt19937& rng, int W, int H) {
    std::uniform_real_distribution<float> u(0, 1);
    std::vector<float> d(static_cast<std::size_t>(W) * H);
    // Piecewise-constant blobs plus noise, so maxima are not all 1-ish.
    const float base = u(rng);
    for (auto& v : d) v = base * u(rng);
    for (int b = 0; b < 6; ++b) {
        const int x0 = static_cast<int>(rng() % W), y0 = static_cast<int>(rng() % H);
        const int bw = 1 + static_cast<int>(rng() % std::max(1, W / 3)),
                  bh = 1 + static_cast<int>(rng() % std::max(1, H / 3));
        const float v = u(rng);
        for (int y = y0; y < std::min(H, y0 + bh); ++y)
            for (int x = x0; x < std::min(W, x0 + bw); ++x) d[static_cast<std::size_t>(y) * W + x] = v;
    }
    if (rng() % 4 == 0) d[rng() % d.size()] = 1.0f;  // a single far pixel must propagate to the top
    return d;
}

}  // namespace

TEST(HiZPyramid, LevelSizesRoundUpDownTo1x1) {
    struct Case {
        int w, h;
        std::vector<std::pair<int, int>> sizes;
    };
    const Case cases[] = {
        {1, 1, {{1, 1}}},
        {2, 1, {{1, 1}}},
        {3, 1, {{2, 1}, {1, 1}}},
        {5, 5, {{3, 3}, {2, 2}, {1, 1}}},  // seed: 5x5 goes to 3x3, not 2x2
        {8, 8, {{4, 4}, {2, 2}, {1, 1}}},
        {9, 2, {{5, 1}, {3, 1}, {2, 1}, {1, 1}}},
        {257, 131, {{129, 66}, {65, 33}, {33, 17}, {17, 9}, {9, 5}, {5, 3}, {3, 2}, {2, 1}, {1, 1}}},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(std::to_string(c.w) + "x" + std::to_string(c.h));
        const HiZPyramid hiz(c.w, c.h);
        ASSERT_EQ(hiz.levels(), static_cast<int>(c.sizes.size()));
        EXPECT_EQ(HiZPyramid::level_count(c.w, c.h), hiz.levels());
        std::size_t offset = 0;
        for (int l = 0; l < hiz.levels(); ++l) {
            EXPECT_EQ(hiz.level(l).width, c.sizes[l].first);
            EXPECT_EQ(hiz.level(l).height, c.sizes[l].second);
            EXPECT_EQ(hiz.level(l).offset, offset);
            offset += static_cast<std::size_t>(c.sizes[l].first) * c.sizes[l].second;
        }
        EXPECT_EQ(hiz.size(), offset);
    }
    EXPECT_EQ(HiZPyramid::level_count(1920, 1080), 11);  // 960x540 ... 1x1
    EXPECT_EQ(HiZPyramid::level_count(4096, 4096), 12);  // 2048^2 ... 1x1
}

// Every texel of every level equals the max over exactly its footprint (hence >= each pixel it
// covers), for random NPOT sizes.
TEST(HiZPyramid, EveryTexelIsTheMaxOverExactlyItsFootprint) {
    std::mt19937 rng(7);
    std::vector<std::pair<int, int>> sizes = {{1, 1}, {1, 7},     {7, 1},     {2, 2},  {3, 3},
                                              {5, 5}, {257, 131}, {131, 257}, {64, 64}};
    for (int i = 0; i < 25; ++i)
        sizes.push_back({1 + static_cast<int>(rng() % 300), 1 + static_cast<int>(rng() % 300)});
    for (const auto& [W, H] : sizes) {
        SCOPED_TRACE(std::to_string(W) + "x" + std::to_string(H));
        const std::vector<float> depth = random_depth(rng, W, H);
        HiZPyramid hiz;
        hiz.build(depth.data(), W, H);
        const auto ref = brute_pyramid(depth, W, H, hiz);
        std::size_t mismatches = 0;
        for (int l = 0; l < hiz.levels(); ++l)
            for (int ty = 0; ty < hiz.level(l).height; ++ty)
                for (int tx = 0; tx < hiz.level(l).width; ++tx) {
                    const float want = ref[l][static_cast<std::size_t>(ty) * hiz.level(l).width + tx];
                    ASSERT_GE(want, 0.0f) << "texel with an empty footprint at level " << l;
                    if (hiz.texel(l, tx, ty) != want && mismatches++ < 3)
                        ADD_FAILURE() << "level " << l << " texel " << tx << "," << ty << ": " << hiz.texel(l, tx, ty)
                                      << " != " << want;
                }
        EXPECT_EQ(mismatches, 0u);
        const float global = *std::max_element(depth.begin(), depth.end());
        EXPECT_EQ(hiz.texel(hiz.levels() - 1, 0, 0), global);
    }
}

// Niessner & Loop's construction: enlarge to the next power of two, unused texels 0, plain 2x2 max mips
// (what a GL implementation with a POT texture does). Its used texels equal ours, bit for bit.
TEST(HiZPyramid, EqualsTheSeedsZeroPaddedPowerOfTwoMap) {
    std::mt19937 rng(11);
    for (int iter = 0; iter < 12; ++iter) {
        const int W = 1 + static_cast<int>(rng() % 200), H = 1 + static_cast<int>(rng() % 200);
        SCOPED_TRACE(std::to_string(W) + "x" + std::to_string(H));
        const std::vector<float> depth = random_depth(rng, W, H);
        HiZPyramid hiz;
        hiz.build(depth.data(), W, H);
        const int P = static_cast<int>(std::bit_ceil(static_cast<unsigned>(std::max({W, H, 2}))));
        std::vector<float> cur(static_cast<std::size_t>(P) * P, 0.0f);  // unused texels: 0
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x)
                cur[static_cast<std::size_t>(y) * P + x] = depth[static_cast<std::size_t>(y) * W + x];
        int size = P;
        for (int l = 0; l < hiz.levels(); ++l) {
            const int half = size / 2;
            std::vector<float> next(static_cast<std::size_t>(half) * half);
            for (int y = 0; y < half; ++y)
                for (int x = 0; x < half; ++x) {
                    auto at = [&](int xx, int yy) { return cur[static_cast<std::size_t>(yy) * size + xx]; };
                    next[static_cast<std::size_t>(y) * half + x] =
                        std::max(std::max(at(2 * x, 2 * y), at(2 * x + 1, 2 * y)),
                                 std::max(at(2 * x, 2 * y + 1), at(2 * x + 1, 2 * y + 1)));
                }
            for (int ty = 0; ty < hiz.level(l).height; ++ty)
                for (int tx = 0; tx < hiz.level(l).width; ++tx)
                    ASSERT_EQ(hiz.texel(l, tx, ty), next[static_cast<std::size_t>(ty) * half + tx]) << "level " << l;
            cur.swap(next);
            size = half;
        }
    }
}

TEST(HiZPyramid, RebuildAtTheSameSizeKeepsItsStorage) {
    std::mt19937 rng(3);
    const std::vector<float> a = random_depth(rng, 100, 60), b = random_depth(rng, 100, 60);
    HiZPyramid hiz;
    hiz.build(a.data(), 100, 60);
    const float* storage = hiz.data();
    hiz.build(b.data(), 100, 60);
    EXPECT_EQ(hiz.data(), storage);
    EXPECT_EQ(hiz.texel(hiz.levels() - 1, 0, 0), *std::max_element(b.begin(), b.end()));
}

// ---- level selection ----------------------------------------------------------------------------

namespace {

int texels_spanned(int lo, int hi, int level) { return (hi >> (level + 1)) - (lo >> (level + 1)) + 1; }

// The `floor` variant: Niessner & Loop's formula with floor instead of ceil, in this pyramid's levels
// (level l has texels of 2^(l+1) pixels): floor(log2(span)) - 1.
int floor_level(const PixelRect& r, int levels) {
    const int span = std::max(r.x1 - r.x0, r.y1 - r.y0);
    const int l = span <= 1 ? 0 : static_cast<int>(std::bit_width(static_cast<unsigned>(span))) - 2;
    return std::clamp(l, 0, levels - 1);
}

// Max of the four corner texels (tx0|tx1, ty0|ty1) at a given level: what hiz_rect_max reads.
float corner_max(const HiZPyramid& hiz, const PixelRect& r, int l) {
    const int s = l + 1;
    return std::max(std::max(hiz.texel(l, r.x0 >> s, r.y0 >> s), hiz.texel(l, r.x1 >> s, r.y0 >> s)),
                    std::max(hiz.texel(l, r.x0 >> s, r.y1 >> s), hiz.texel(l, r.x1 >> s, r.y1 >> s)));
}

PixelRect random_rect(std::mt19937& rng, int W, int H) {
    auto pick = [&](int n) {
        int a = static_cast<int>(rng() % n), b = static_cast<int>(rng() % n);
        if (rng() % 3 == 0) b = std::min(n - 1, a + static_cast<int>(rng() % 5));  // many small ones
        return std::pair{std::min(a, b), std::max(a, b)};
    };
    const auto [x0, x1] = pick(W);
    const auto [y0, y1] = pick(H);
    return {x0, y0, x1, y1};
}

}  // namespace

// The chosen level is the finest at which the rectangle meets <= 2 texels per axis, its corner texels
// hold every pixel of the rectangle, and hiz_rect_max >= every depth pixel in the rectangle.
TEST(HiZLevel, FinestLevelCoveringTheRectangleWithAtMost2x2Texels) {
    std::mt19937 rng(5);
    for (int iter = 0; iter < 40; ++iter) {
        const int W = 1 + static_cast<int>(rng() % 400), H = 1 + static_cast<int>(rng() % 400);
        const std::vector<float> depth = random_depth(rng, W, H);
        HiZPyramid hiz;
        hiz.build(depth.data(), W, H);
        for (int k = 0; k < 200; ++k) {
            const PixelRect r = random_rect(rng, W, H);
            const int l = hiz_select_level(r, hiz.levels());
            ASSERT_LE(texels_spanned(r.x0, r.x1, l), 2);
            ASSERT_LE(texels_spanned(r.y0, r.y1, l), 2);
            int brute = 0;
            while (texels_spanned(r.x0, r.x1, brute) > 2 || texels_spanned(r.y0, r.y1, brute) > 2) ++brute;
            ASSERT_EQ(l, brute) << W << "x" << H << " rect " << r.x0 << "," << r.y0 << " - " << r.x1 << "," << r.y1;
            float pix_max = 0;
            for (int y = r.y0; y <= r.y1; ++y)
                for (int x = r.x0; x <= r.x1; ++x)
                    pix_max = std::max(pix_max, depth[static_cast<std::size_t>(y) * W + x]);
            const float h = hiz_rect_max(hiz, r);
            ASSERT_GE(h, pix_max);
            ASSERT_EQ(h, corner_max(hiz, r, l));
        }
    }
}

// The level formula by itself: worst-case alignment of a span never needs more than 2 texels.
TEST(HiZLevel, CeilFormulaCoversEverySpanAtEveryAlignment) {
    for (int span = 0; span <= 600; ++span)
        for (int x0 = 0; x0 < 70; ++x0) {
            const PixelRect r{x0, 0, x0 + span, 0};
            const int l = hiz_select_level(r, 32);
            ASSERT_LE(texels_spanned(r.x0, r.x1, l), 2) << "span " << span << " at " << x0;
            if (l > 0) {
                ASSERT_GT(texels_spanned(r.x0, r.x1, l - 1), 2) << "not the finest level: span " << span;
            }
        }
}

// A `floor` level under-covers: the rectangle meets 3 texels per axis and only the outer two are
// read, so a far pixel in the middle is missed and max(read texels) < max(pixels): false occlusion.
TEST(HiZLevel, FloorLevelUnderCoversAndCeilDoesNot) {
    // Hand case: pixels 1..4 in one row; at level 0 (2-pixel texels) that is texels 0, 1, 2.
    {
        const int W = 8, H = 2;
        std::vector<float> depth(W * H, 0.1f);
        depth[2] = depth[3] = 0.9f;  // far pixels inside the rectangle, in the middle texel
        HiZPyramid hiz;
        hiz.build(depth.data(), W, H);
        const PixelRect r{1, 0, 4, 0};
        EXPECT_EQ(floor_level(r, hiz.levels()), 0);
        EXPECT_EQ(corner_max(hiz, r, 0), 0.1f);  // floor: a patch at depth 0.5 would be "occluded"
        EXPECT_EQ(hiz_select_level(r, hiz.levels()), 1);
        EXPECT_EQ(hiz_rect_max(hiz, r), 0.9f);  // ceil: it is not
    }
    // Random rectangles: floor finds under-covered ones, the real selection never does.
    std::mt19937 rng(17);
    std::size_t floor_under = 0, ceil_under = 0, tried = 0;
    for (int iter = 0; iter < 30; ++iter) {
        const int W = 2 + static_cast<int>(rng() % 300), H = 2 + static_cast<int>(rng() % 300);
        std::vector<float> depth = random_depth(rng, W, H);
        for (auto& d : depth)
            if (rng() % 50 == 0) d = 1.0f;  // sparse far holes
        HiZPyramid hiz;
        hiz.build(depth.data(), W, H);
        for (int k = 0; k < 300; ++k) {
            const PixelRect r = random_rect(rng, W, H);
            float pix_max = 0;
            for (int y = r.y0; y <= r.y1; ++y)
                for (int x = r.x0; x <= r.x1; ++x)
                    pix_max = std::max(pix_max, depth[static_cast<std::size_t>(y) * W + x]);
            ++tried;
            floor_under += corner_max(hiz, r, floor_level(r, hiz.levels())) < pix_max;
            ceil_under += hiz_rect_max(hiz, r) < pix_max;
        }
    }
    EXPECT_EQ(ceil_under, 0u);
    EXPECT_GT(floor_under, tried / 200) << "the floor variant should under-cover often";
}

TEST(HiZLevel, RectangleFromWindowBoxTouchesAndClamps) {
    // Touch rule: floor of each edge.
    PixelRect r = hiz_rect_from_window_box(2.0f, 4.5f, 0.99f, 1.0f, 10, 5);
    EXPECT_EQ(r.x0, 2);
    EXPECT_EQ(r.x1, 4);
    EXPECT_EQ(r.y0, 0);
    EXPECT_EQ(r.y1, 1);
    // Off-screen parts and infinities clamp to the screen.
    r = hiz_rect_from_window_box(-1e30f, INFINITY, -INFINITY, 3.5f, 10, 5);
    EXPECT_EQ(r.x0, 0);
    EXPECT_EQ(r.x1, 9);
    EXPECT_EQ(r.y0, 0);
    EXPECT_EQ(r.y1, 3);
    r = hiz_rect_from_window_box(10.0f, 12.0f, 5.0f, 5.0f, 10, 5);  // right/top edge itself
    EXPECT_EQ(r.x0, 9);
    EXPECT_EQ(r.y1, 4);
}

// ---- kernels: helpers --------------------------------------------------------------------------

namespace {

enum class Impl { kScalar, kSimd };

std::vector<std::uint8_t> run_kernel(Impl impl, const PatchBatchView& v, const Mat4& m, const HiZPyramid& hiz) {
    constexpr std::size_t kGuard = 64;
    std::vector<std::uint8_t> out(v.count + kGuard, 0xAB);
    (impl == Impl::kScalar ? cull_occlusion_scalar : cull_occlusion_simd)(v, m, ClipDepth::zero_to_one, hiz,
                                                                          out.data());
    for (std::size_t i = v.count; i < out.size(); ++i) EXPECT_EQ(out[i], 0xAB) << "wrote past count at " << i;
    out.resize(v.count);
    return out;
}

void for_each_simd_target(const std::function<void(bool)>& body) {
    bool best = true;
    for (std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
        hwy::SetSupportedTargetsForTest(target);
        SCOPED_TRACE(std::string("SIMD target ") + hwy::TargetName(target));
        body(best);
        best = false;
    }
    hwy::SetSupportedTargetsForTest(0);
}

// A flat 4x4 patch: corners c, c + a, c + b, c + a + b.
BezierPatch flat_patch(Vec3 c, Vec3 a, Vec3 b, float w = 1.0f) {
    BezierPatch p;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) p.cp[4 * j + i] = homogeneous(c + a * (i / 3.0f) + b * (j / 3.0f), w);
    return p;
}

// Camera at the origin looking down -z: view = identity.
Mat4 simple_projection(int W, int H) { return perspective(60.0f * kPi / 180, float(W) / float(H), 0.1f, 100.0f); }

// Depth z/w of the view-space point at distance d (camera looks down -z).
float depth_at_distance(const Mat4& proj, float d) {
    const Vec4 c = proj * Vec4{0, 0, -d, 1};
    return c.z / c.w;
}

}  // namespace

// Hand-built cases against a full-screen wall at distance 5 (constant depth buffer).
TEST(HiZKernels, HandBuiltDecisions) {
    const int W = 257, H = 131;
    const Mat4 proj = simple_projection(W, H);
    const float wall = depth_at_distance(proj, 5.0f);
    std::vector<float> depth(static_cast<std::size_t>(W) * H, wall);
    HiZPyramid hiz;
    hiz.build(depth.data(), W, H);

    std::vector<BezierPatch> patches = {
        flat_patch({-1, -1, -10}, {2, 0, 0}, {0, 2, 0}),    // 0: behind the wall: occluded
        flat_patch({-1, -1, -3}, {2, 0, 0}, {0, 2, 0}),     // 1: in front: visible
        flat_patch({50, 0, -10}, {1, 0, 0}, {0, 1, 0}),     // 2: far right, outside: frustum
        flat_patch({-1, -1, -5.5f}, {2, 0, 0}, {0, 0, 2}),  // 3: crosses the wall plane: visible
        flat_patch({-2, -1, 4}, {4, 0, 0},
                   {0, 0, -30}),  // 4: from behind the eye to far behind the wall: not projectable
        flat_patch({6, -1, -10}, {10, 0, 0}, {0, 2, 0}),          // 5: partly off-screen, behind: occluded
        flat_patch({0, 0, -20}, {0.001f, 0, 0}, {0, 0.001f, 0}),  // 6: tiny (sub-pixel), behind: occluded
        flat_patch({-1, -1, -10}, {2, 0, 0}, {0, 2, 0}, 2.0f),    // 7: rational weights (same points)
        flat_patch({-1, -1, -200}, {2, 0, 0}, {0, 2, 0}),         // 8: beyond the far plane: frustum
    };
    const PatchBatch batch = make_batch(patches);
    const std::vector<std::uint8_t> want = {kHiZOccluded, kHiZVisible,  kHiZFrustumCulled,
                                            kHiZVisible,  kHiZVisible,  kHiZOccluded,
                                            kHiZOccluded, kHiZOccluded, kHiZFrustumCulled};
    EXPECT_EQ(run_kernel(Impl::kScalar, batch.view(), proj, hiz), want);
    for_each_simd_target([&](bool) { EXPECT_EQ(run_kernel(Impl::kSimd, batch.view(), proj, hiz), want); });

    // Patch 4 is not projectable; its bounds say so.
    PatchScreenBounds b;
    EXPECT_FALSE(patch_screen_bounds(batch.view(), 4, proj, ClipDepth::zero_to_one, W, H, b));
    ASSERT_TRUE(patch_screen_bounds(batch.view(), 0, proj, ClipDepth::zero_to_one, W, H, b));
    EXPECT_GT(b.zmin, wall);

    // Patch 6 (tiny) seen through a one-pixel hole in the wall is visible; the frustum result is the
    // frustum kernel's.
    ASSERT_TRUE(patch_screen_bounds(batch.view(), 6, proj, ClipDepth::zero_to_one, W, H, b));
    EXPECT_EQ(b.rect.x0, b.rect.x1);
    depth[static_cast<std::size_t>(b.rect.y0) * W + b.rect.x0] = 1.0f;
    hiz.build(depth.data(), W, H);
    EXPECT_EQ(run_kernel(Impl::kScalar, batch.view(), proj, hiz)[6], kHiZVisible);
    EXPECT_EQ(run_kernel(Impl::kSimd, batch.view(), proj, hiz)[6], kHiZVisible);
    std::vector<std::uint8_t> frustum(patches.size());
    cull_frustum_scalar(batch.view(), nullptr, make_frustum_planes(proj, ClipDepth::zero_to_one), frustum.data());
    const auto got = run_kernel(Impl::kScalar, batch.view(), proj, hiz);
    for (std::size_t i = 0; i < patches.size(); ++i) EXPECT_EQ(got[i] == kHiZFrustumCulled, frustum[i] == 1) << i;
}

// A patch that straddles the eye plane is never occluded, even when every projectable part of it is
// behind a wall (its screen rectangle is not defined).
TEST(HiZKernels, PatchStraddlingTheEyePlaneIsNeverOccluded) {
    const int W = 64, H = 64;
    const Mat4 proj = simple_projection(W, H);
    std::vector<float> depth(static_cast<std::size_t>(W) * H, 0.0f);  // everything at the near plane
    HiZPyramid hiz;
    hiz.build(depth.data(), W, H);
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(-1, 1);
    std::vector<BezierPatch> patches;
    for (int i = 0; i < 200; ++i) {
        // Control points on both sides of z = 0 (view space): w = -z changes sign.
        BezierPatch p =
            flat_patch({3 * u(rng), 3 * u(rng), 1 + u(rng) * 0.9f}, {4 * u(rng), 4 * u(rng), -5 - 5 * std::abs(u(rng))},
                       {4 * u(rng), 4 * u(rng), 2 * u(rng)});
        patches.push_back(p);
    }
    const PatchBatch batch = make_batch(patches);
    for (Impl impl : {Impl::kScalar, Impl::kSimd}) {
        const auto d = run_kernel(impl, batch.view(), proj, hiz);
        for (std::size_t i = 0; i < d.size(); ++i) {
            ASSERT_NE(d[i], kHiZOccluded) << i;
            PatchScreenBounds b;
            ASSERT_FALSE(patch_screen_bounds(batch.view(), i, proj, ClipDepth::zero_to_one, W, H, b)) << i;
        }
    }
}

// ---- ground truth -------------------------------------------------------------------------------

namespace {

struct Scene {
    int W = 0, H = 0;
    Mat4 object_to_clip;
    std::vector<float> depth;  // rasterized occluders, cleared to 1
    std::vector<BezierPatch> patches;
};

Vec4 to_clip(const Mat4& m, Vec3 p) { return m * Vec4{p.x, p.y, p.z, 1}; }

// Rasterizes a triangle with all w > 0 and 0 <= z <= w at its vertices (no clipping needed):
// pixel centres inside (edge functions in double, either orientation), depth z/w interpolated
// linearly in screen space (exact for a planar triangle), less-test.
void raster_triangle(Scene& s, Vec4 a, Vec4 b, Vec4 c) {
    double X[3], Y[3], Z[3];
    const Vec4 v[3] = {a, b, c};
    for (int i = 0; i < 3; ++i) {
        X[i] = (double(v[i].x) / v[i].w + 1) * 0.5 * s.W;
        Y[i] = (double(v[i].y) / v[i].w + 1) * 0.5 * s.H;
        Z[i] = double(v[i].z) / v[i].w;
    }
    const double area = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]);
    if (area == 0) return;
    const int x0 = std::max(0, int(std::floor(std::min({X[0], X[1], X[2]})))),
              x1 = std::min(s.W - 1, int(std::ceil(std::max({X[0], X[1], X[2]}))));
    const int y0 = std::max(0, int(std::floor(std::min({Y[0], Y[1], Y[2]})))),
              y1 = std::min(s.H - 1, int(std::ceil(std::max({Y[0], Y[1], Y[2]}))));
    for (int py = y0; py <= y1; ++py)
        for (int px = x0; px <= x1; ++px) {
            const double x = px + 0.5, y = py + 0.5;
            double e[3];
            for (int i = 0; i < 3; ++i) {
                const int j = (i + 1) % 3, k = (i + 2) % 3;
                e[i] = ((X[k] - X[j]) * (y - Y[j]) - (Y[k] - Y[j]) * (x - X[j])) / area;  // barycentric of vertex i
            }
            if (e[0] < 0 || e[1] < 0 || e[2] < 0) continue;
            const double z = e[0] * Z[0] + e[1] * Z[1] + e[2] * Z[2];
            float& d = s.depth[static_cast<std::size_t>(py) * s.W + px];
            if (z < d) d = static_cast<float>(z);
        }
}

bool quad_drawable(const Vec4 c[4]) {
    for (int i = 0; i < 4; ++i)
        if (!(c[i].w > 0 && c[i].z >= 0 && c[i].z <= c[i].w)) return false;
    return true;
}

void raster_quad(Scene& s, Vec3 p, Vec3 a, Vec3 b) {
    const Vec4 c[4] = {to_clip(s.object_to_clip, p), to_clip(s.object_to_clip, p + a),
                       to_clip(s.object_to_clip, p + a + b), to_clip(s.object_to_clip, p + b)};
    if (!quad_drawable(c)) return;
    raster_triangle(s, c[0], c[1], c[2]);
    raster_triangle(s, c[0], c[2], c[3]);
}

// Random scene in view space (camera at the origin looking down -z, then a random rigid view so
// that object_to_clip is general). Occluders: random quads and "picket fences" (bars with gaps a
// few pixels wide: high-frequency depth, where a wrong level shows). Patches: behind / in front of
// occluders, partly off-screen, tiny, rational, and some straddling the eye plane.
Scene random_scene(std::mt19937& rng, int W, int H) {
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    Scene s;
    s.W = W;
    s.H = H;
    const float aspect = float(W) / float(H), fovy = (40 + 40 * unit(rng)) * kPi / 180;
    const float ty = std::tan(fovy / 2), tx = ty * aspect;
    const Vec3 eye{10 * u(rng), 10 * u(rng), 10 * u(rng)};
    const Vec3 target = eye + Vec3{u(rng), u(rng), u(rng)};
    const Mat4 view = look_at(eye, target, {0, 1, 0});
    Mat4 inv;
    invert(view, inv);
    s.object_to_clip = perspective(fovy, aspect, 0.1f, 100.0f) * view;
    auto world = [&](Vec3 v) { return cartesian(inv * Vec4{v.x, v.y, v.z, 1}); };
    auto world_dir = [&](Vec3 v) { return xyz(inv * Vec4{v.x, v.y, v.z, 0}); };
    s.depth.assign(static_cast<std::size_t>(W) * H, 1.0f);

    // Occluders between distance 3 and 15.
    const int quads = 3 + static_cast<int>(rng() % 6);
    for (int q = 0; q < quads; ++q) {
        const float d = 3 + 12 * unit(rng);
        const Vec3 c{tx * d * u(rng), ty * d * u(rng), -d};
        const float size = d * (0.3f + 0.9f * unit(rng));
        const Vec3 a = Vec3{1, 0.2f * u(rng), 0.3f * u(rng)} * size, b = Vec3{0.2f * u(rng), 1, 0.3f * u(rng)} * size;
        raster_quad(s, world(c - a * 0.5f - b * 0.5f), world_dir(a), world_dir(b));
    }
    const int fences = 1 + static_cast<int>(rng() % 2);
    for (int f = 0; f < fences; ++f) {
        const float d = 4 + 8 * unit(rng);
        const float px = 2 * tx * d / W;  // one pixel at distance d
        const bool vertical = rng() % 2;
        const float extent = (vertical ? tx : ty) * d;
        for (float t = -extent; t < extent;) {
            const float bar = px * (2 + 12 * unit(rng)), gap = px * (1 + 6 * unit(rng));
            const float len = 2 * (vertical ? ty : tx) * d;
            const Vec3 p = vertical ? Vec3{t, -len / 2, -d} : Vec3{-len / 2, t, -d};
            const Vec3 a = vertical ? Vec3{bar, 0, 0} : Vec3{len, 0, 0};
            const Vec3 b = vertical ? Vec3{0, len, 0} : Vec3{0, bar, 0};
            raster_quad(s, world(p), world_dir(a), world_dir(b));
            t += bar + gap;
        }
    }

    // Patches.
    const int count = 600;
    for (int i = 0; i < count; ++i) {
        const int kind = static_cast<int>(rng() % 10);
        float d = 5 + 40 * unit(rng);  // mostly behind the occluders
        float size = d * (0.01f + 0.15f * unit(rng));
        float lateral = 1.0f;
        if (kind == 0) d = 0.5f + 4 * unit(rng);                   // in front of most occluders
        if (kind == 1) size = d * (0.0005f + 0.004f * unit(rng));  // tiny: a pixel or less
        if (kind == 2) lateral = 1.0f + 2.0f * unit(rng);          // often partly or wholly off-screen
        if (kind == 3) size = d * (0.3f + 0.7f * unit(rng));       // large
        Vec3 c{tx * d * u(rng) * lateral, ty * d * u(rng) * lateral, -d};
        Vec3 a = Vec3{u(rng), u(rng), 0.5f * u(rng)} * size, b = Vec3{u(rng), u(rng), 0.5f * u(rng)} * size;
        Vec3 n = Vec3{0.3f * u(rng), 0.3f * u(rng), 1} * (0.3f * size);
        if (kind == 4) {  // straddles the eye plane: from behind the camera to far in front
            c = {tx * u(rng), ty * u(rng), 0.5f * u(rng)};
            a = Vec3{u(rng), u(rng), -20 * unit(rng) - 2};
            b = Vec3{u(rng), u(rng), u(rng)} * 2.0f;
        }
        BezierPatch p;
        for (int j = 0; j < 4; ++j)
            for (int k = 0; k < 4; ++k) {
                const Vec3 pt = c + a * (k / 3.0f - 0.5f) + b * (j / 3.0f - 0.5f) + n * u(rng);
                const float w = kind == 5 ? 0.25f + 3.75f * unit(rng) : 1.0f;
                p.cp[4 * j + k] = homogeneous(world(pt), w);
            }
        s.patches.push_back(p);
    }
    return s;
}

struct TruthReport {
    std::size_t occluded = 0, violations = 0, samples_checked = 0;
    std::string first;
};

// For every patch decided occluded: each sample of the 17x17 grid (double precision) must have
// w > 0, and if it projects inside the screen its depth must be strictly greater than the depth
// buffer at its pixel. Frustum-culled patches: no sample inside the clip volume.
TruthReport check_against_truth(const Scene& s, const std::vector<std::uint8_t>& decision) {
    TruthReport rep;
    double M[4][4];
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) M[r][c] = s.object_to_clip.at(r, c);
    constexpr int kGrid = 17;
    for (std::size_t i = 0; i < s.patches.size(); ++i) {
        if (decision[i] == kHiZVisible) continue;
        rep.occluded += decision[i] == kHiZOccluded;
        bool bad = false;
        for (int iv = 0; iv < kGrid && !bad; ++iv)
            for (int iu = 0; iu < kGrid && !bad; ++iu) {
                auto bern = [](double t, double b[4]) {
                    const double q = 1 - t;
                    b[0] = q * q * q;
                    b[1] = 3 * t * q * q;
                    b[2] = 3 * t * t * q;
                    b[3] = t * t * t;
                };
                double bu[4], bv[4];
                bern(iu / double(kGrid - 1), bu);
                bern(iv / double(kGrid - 1), bv);
                double h[4] = {0, 0, 0, 0};
                for (int j = 0; j < 4; ++j)
                    for (int k = 0; k < 4; ++k) {
                        const Vec4& cp = s.patches[i].cp[4 * j + k];
                        const double wgt = bu[k] * bv[j];
                        h[0] += wgt * cp.x;
                        h[1] += wgt * cp.y;
                        h[2] += wgt * cp.z;
                        h[3] += wgt * cp.w;
                    }
                double c[4];
                for (int r = 0; r < 4; ++r) c[r] = M[r][0] * h[0] + M[r][1] * h[1] + M[r][2] * h[2] + M[r][3] * h[3];
                if (decision[i] == kHiZFrustumCulled) {
                    bad = c[3] + c[0] >= 0 && c[3] - c[0] >= 0 && c[3] + c[1] >= 0 && c[3] - c[1] >= 0 && c[2] >= 0 &&
                          c[3] - c[2] >= 0 && c[3] > 0;
                    if (bad && rep.first.empty())
                        rep.first = "patch " + std::to_string(i) + " frustum-culled with a sample inside";
                    continue;
                }
                ++rep.samples_checked;
                if (!(c[3] > 0)) {
                    bad = true;
                    if (rep.first.empty())
                        rep.first = "patch " + std::to_string(i) + " occluded with a sample at w <= 0";
                    continue;
                }
                const double x = (c[0] / c[3] + 1) * 0.5 * s.W, y = (c[1] / c[3] + 1) * 0.5 * s.H, z = c[2] / c[3];
                if (!(x >= 0 && x < s.W && y >= 0 && y < s.H)) continue;
                const int px = static_cast<int>(x), py = static_cast<int>(y);
                const float dbuf = s.depth[static_cast<std::size_t>(py) * s.W + px];
                if (!(z > dbuf)) {
                    bad = true;
                    if (rep.first.empty())
                        rep.first = "patch " + std::to_string(i) + " occluded but sample (" + std::to_string(iu) + "," +
                                    std::to_string(iv) + ") at pixel " + std::to_string(px) + "," + std::to_string(py) +
                                    " has depth " + std::to_string(z) + " <= buffer " + std::to_string(dbuf);
                }
            }
        rep.violations += bad;
    }
    return rep;
}

// Deliberately broken deciders (frustum part taken from the real kernel), for the mutation checks.
enum class Broken { kFloorLevel, kMaxZ };
std::vector<std::uint8_t> broken_decisions(const Scene& s, const HiZPyramid& hiz, Broken how) {
    std::vector<std::uint8_t> d(s.patches.size());
    const PatchBatch batch = make_batch(s.patches);
    cull_frustum_scalar(batch.view(), nullptr, make_frustum_planes(s.object_to_clip, ClipDepth::zero_to_one), d.data());
    for (std::size_t i = 0; i < d.size(); ++i) {
        if (d[i]) continue;
        PatchScreenBounds b;
        if (!patch_screen_bounds(batch.view(), i, s.object_to_clip, ClipDepth::zero_to_one, s.W, s.H, b)) continue;
        if (how == Broken::kFloorLevel) {
            d[i] = corner_max(hiz, b.rect, floor_level(b.rect, hiz.levels())) < b.zmin ? kHiZOccluded : kHiZVisible;
        } else {
            float zmax = -INFINITY;
            for (const Vec4& cp : s.patches[i].cp) {
                const Vec4 c = s.object_to_clip * cp;
                zmax = std::max(zmax, c.z / c.w);
            }
            d[i] = hiz_rect_max(hiz, b.rect) < zmax ? kHiZOccluded : kHiZVisible;
        }
    }
    return d;
}

}  // namespace

// The kernels never occlude a patch with a visible sample; scalar and SIMD agree exactly; the
// deliberately broken deciders are caught by the same check.
TEST(HiZKernels, OccludedPatchesHaveNoSampleInFrontOfTheDepthBuffer) {
    const std::pair<int, int> screens[] = {{257, 131}, {128, 128}, {100, 37}, {640, 360}, {31, 200}, {1, 1}, {3, 2}};
    std::mt19937 rng(4242);
    std::size_t occluded = 0, total = 0, samples = 0, floor_caught = 0, maxz_caught = 0, frustum = 0, visible = 0;
    for (int rep = 0; rep < 3; ++rep)
        for (const auto& [W, H] : screens) {
            SCOPED_TRACE(std::to_string(W) + "x" + std::to_string(H) + " scene " + std::to_string(rep));
            const Scene s = random_scene(rng, W, H);
            HiZPyramid hiz;
            hiz.build(s.depth.data(), W, H);
            const PatchBatch batch = make_batch(s.patches);
            const auto ref = run_kernel(Impl::kScalar, batch.view(), s.object_to_clip, hiz);
            for_each_simd_target([&](bool) {
                const auto simd = run_kernel(Impl::kSimd, batch.view(), s.object_to_clip, hiz);
                EXPECT_TRUE(simd == ref) << "SIMD decisions differ from the scalar reference";
            });
            const TruthReport r = check_against_truth(s, ref);
            EXPECT_EQ(r.violations, 0u) << r.first;
            occluded += r.occluded;
            samples += r.samples_checked;
            total += s.patches.size();
            frustum += static_cast<std::size_t>(std::count(ref.begin(), ref.end(), kHiZFrustumCulled));
            visible += static_cast<std::size_t>(std::count(ref.begin(), ref.end(), kHiZVisible));
            floor_caught += check_against_truth(s, broken_decisions(s, hiz, Broken::kFloorLevel)).violations;
            maxz_caught += check_against_truth(s, broken_decisions(s, hiz, Broken::kMaxZ)).violations;
        }
    // The scenes exercise every outcome, and the check has teeth.
    EXPECT_GT(occluded, total / 10) << "too few occluded patches for a meaningful check";
    EXPECT_GT(frustum, total / 20);
    EXPECT_GT(visible, total / 10);
    EXPECT_GT(samples, 100000u);
    EXPECT_GT(floor_caught, 0u) << "a floor level selection must produce false occlusion here";
    EXPECT_GT(maxz_caught, 0u) << "testing max z instead of min z must produce false occlusion here";
    std::printf(
        "[ HiZ truth ] patches %zu, occluded %zu, frustum %zu, samples %zu; broken deciders caught: "
        "floor level %zu, max z %zu\n",
        total, occluded, frustum, samples, floor_caught, maxz_caught);
}

// Subranges at unaligned offsets and lengths: same decisions as the whole batch, no write past count.
TEST(HiZKernels, SubrangesMatchTheWholeBatch) {
    std::mt19937 rng(8);
    const Scene s = random_scene(rng, 200, 120);
    HiZPyramid hiz;
    hiz.build(s.depth.data(), s.W, s.H);
    const PatchBatch batch = make_batch(s.patches);
    const auto full = run_kernel(Impl::kScalar, batch.view(), s.object_to_clip, hiz);
    const std::size_t n = batch.size();
    const std::pair<std::size_t, std::size_t> ranges[] = {{0, 1},       {1, 1},     {3, 5},       {5, 17}, {7, 300},
                                                          {n - 21, 21}, {n - 1, 1}, {13, n - 13}, {100, 0}};
    for (const auto& [first, len] : ranges) {
        SCOPED_TRACE("subrange " + std::to_string(first) + " + " + std::to_string(len));
        const PatchBatchView sub = batch.view().subrange(first, len);
        const auto want = std::vector<std::uint8_t>(full.begin() + first, full.begin() + first + len);
        EXPECT_EQ(run_kernel(Impl::kScalar, sub, s.object_to_clip, hiz), want);
        for_each_simd_target([&](bool) { EXPECT_EQ(run_kernel(Impl::kSimd, sub, s.object_to_clip, hiz), want); });
    }
}
