// DisplacementMap::patch_range (the min/max pyramid) against patch_range_exact (the texel scan)
// and dense bilinear samples (patchcull/core/displacement.h): always containing, equal on small
// footprints, local on large ones, and constant-time on footprints that span a large map.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <random>

#include "patchcull/core/displacement.h"

using namespace patchcull;

namespace {

DisplacementMap random_map(std::mt19937& rng, int w, int h, float scale) {
    DisplacementMap m;
    m.width = w;
    m.height = h;
    m.scale = scale;
    std::uniform_real_distribution<float> unit(0, 1);
    m.texels.resize(static_cast<std::size_t>(w) * h);
    for (float& t : m.texels) t = unit(rng);
    return m;
}

// A skewed quad in texture space of about `size` map widths, anywhere in [-3, 4]^2 (wrapping).
void random_footprint(std::mt19937& rng, float size, Vec2 uv[4]) {
    std::uniform_real_distribution<float> coord(-3.0f, 4.0f), unit(0, 1);
    const Vec2 base{coord(rng), coord(rng)};
    for (int k = 0; k < 4; ++k)
        uv[k] = base + Vec2{(k & 1) * size * (0.5f + unit(rng)) + size * 0.3f * unit(rng),
                            (k >> 1) * size * (0.5f + unit(rng))};
}

}  // namespace

TEST(DisplacementPyramid, ContainsTheExactRangeAndEveryBilinearSample) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> unit(0, 1);
    const float sizes[] = {0.001f, 0.01f, 0.05f, 0.2f, 0.6f, 1.5f};  // up to footprints larger than the map
    for (int trial = 0; trial < 600; ++trial) {
        const float scale = (trial % 3 == 0 ? -1.0f : 1.0f) * (0.1f + unit(rng));
        DisplacementMap m =
            random_map(rng, 1 + trial % 97 + (trial % 5) * 40, 1 + trial % 61 + (trial % 7) * 30, scale);
        m.midlevel = unit(rng);
        Vec2 uv[4];
        random_footprint(rng, sizes[trial % 6], uv);
        const DisplacementRange r = m.patch_range(uv), e = m.patch_range_exact(uv);
        ASSERT_LE(r.d_min, e.d_min) << "trial " << trial;
        ASSERT_GE(r.d_max, e.d_max) << "trial " << trial;
        for (int j = 0; j <= 24; ++j)
            for (int i = 0; i <= 24; ++i) {
                const float d = m.sample(patch_texcoord(uv, i / 24.0f, j / 24.0f));
                ASSERT_GE(d, r.d_min - 1e-6f) << "trial " << trial;
                ASSERT_LE(d, r.d_max + 1e-6f) << "trial " << trial;
            }
    }
}

TEST(DisplacementPyramid, EqualsTheExactRangeOnFootprintsWithinATexelCell) {
    std::mt19937 rng(12);
    std::uniform_real_distribution<float> unit(0, 1), cell(-40, 300);
    for (int trial = 0; trial < 2000; ++trial) {
        DisplacementMap m = random_map(rng, 64 + trial % 200, 32 + trial % 150, 1.0f);
        // Inside one cell between four texel centres (wrapping when negative or past the edge).
        const float x = std::floor(cell(rng)) + 0.5f, y = std::floor(cell(rng)) + 0.5f;
        Vec2 uv[4];
        for (int k = 0; k < 4; ++k)
            uv[k] = {(x + 0.999f * unit(rng)) / static_cast<float>(m.width),
                     (y + 0.999f * unit(rng)) / static_cast<float>(m.height)};
        const DisplacementRange r = m.patch_range(uv), e = m.patch_range_exact(uv);
        ASSERT_EQ(r.d_min, e.d_min) << "trial " << trial;
        ASSERT_EQ(r.d_max, e.d_max) << "trial " << trial;
    }
}

TEST(DisplacementPyramid, LargeFootprintsStayLocal) {
    // A flat map with one spike: a footprint of 40x40 texels far from the spike must not see it
    // (a level too coarse, or a global range, would), the same footprint over it must.
    DisplacementMap m;
    m.width = m.height = 1024;
    m.scale = 1.0f;
    m.midlevel = 0.0f;
    m.texels.assign(1024 * 1024, 0.0f);
    m.texels[600 * 1024 + 600] = 1.0f;
    const auto square = [](float x0, float y0, float side, Vec2 uv[4]) {
        for (int k = 0; k < 4; ++k) uv[k] = {(x0 + (k & 1) * side) / 1024.0f, (y0 + (k >> 1) * side) / 1024.0f};
    };
    Vec2 uv[4];
    square(100, 100, 40, uv);
    EXPECT_EQ(m.patch_range(uv).d_max, 0.0f);
    square(580, 580, 40, uv);
    EXPECT_EQ(m.patch_range(uv).d_max, 1.0f);
    // Larger than the map: the whole map's range.
    square(-2000, 10, 5000, uv);
    EXPECT_EQ(m.patch_range(uv).d_max, 1.0f);
    // Wrapping across the seam onto the spike's column and row from below 0.
    square(600.5f - 1024 - 20, 600.5f - 20, 40, uv);
    EXPECT_EQ(m.patch_range(uv).d_max, 1.0f);
}

TEST(DisplacementPyramid, NonFiniteTexcoordsGiveTheWholeMap) {
    std::mt19937 rng(13);
    const DisplacementMap m = random_map(rng, 50, 30, 1.0f);
    const Vec2 all[4] = {{0, 0}, {2, 0}, {0, 2}, {2, 2}};
    const DisplacementRange whole = m.patch_range_exact(all);
    for (const float bad : {NAN, INFINITY, -INFINITY}) {
        const Vec2 uv[4] = {{0.1f, 0.1f}, {bad, 0.1f}, {0.1f, 0.2f}, {0.2f, 0.2f}};
        EXPECT_EQ(m.patch_range(uv).d_min, whole.d_min);
        EXPECT_EQ(m.patch_range(uv).d_max, whole.d_max);
        EXPECT_EQ(m.patch_range_exact(uv).d_max, whole.d_max);
    }
    // A huge coordinate takes the whole map along its axis only (here: rows 0.1-0.2 in t).
    const Vec2 huge[4] = {{0.1f, 0.1f}, {1e30f, 0.1f}, {0.1f, 0.2f}, {0.2f, 0.2f}};
    const Vec2 band[4] = {{0, 0.1f}, {1, 0.1f}, {0, 0.2f}, {1, 0.2f}};
    EXPECT_EQ(m.patch_range(huge).d_max, m.patch_range_exact(band).d_max);
    EXPECT_EQ(m.patch_range(huge).d_min, m.patch_range_exact(band).d_min);
}

TEST(DisplacementPyramid, FollowsChangedTexelsAndCopies) {
    DisplacementMap m;
    m.width = m.height = 256;
    m.scale = 1.0f;
    m.midlevel = 0.0f;
    m.texels.assign(256 * 256, 0.25f);
    const Vec2 all[4] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
    EXPECT_EQ(m.patch_range(all).d_max, 0.25f);  // builds the pyramid
    // A copy builds its own pyramid from its own texels.
    DisplacementMap copy = m;
    copy.texels[1000] = 0.75f;
    EXPECT_EQ(copy.patch_range(all).d_max, 0.75f);
    EXPECT_EQ(m.patch_range(all).d_max, 0.25f);
    // In-place changes need texels_changed() (the documented contract) ...
    m.texels[77] = 0.5f;
    m.texels_changed();
    EXPECT_EQ(m.patch_range(all).d_max, 0.5f);
    // ... a new size or buffer is detected.
    m.width = m.height = 128;
    m.texels.assign(128 * 128, 0.125f);
    m.texels.shrink_to_fit();
    EXPECT_EQ(m.patch_range(all).d_max, 0.125f);
}

TEST(DisplacementPyramid, FootprintsSpanningALargeMapCostConstantTime) {
    // The old range scanned every texel of the footprint: 4000 patches spanning a 2048^2 map
    // read 16G texels (minutes). The pyramid reads at most 36 blocks per patch after one build.
    std::mt19937 rng(14);
    const DisplacementMap m = random_map(rng, 2048, 2048, 1.0f);
    const auto t0 = std::chrono::steady_clock::now();
    float sum = 0;
    for (int p = 0; p < 4000; ++p) {
        const float o = static_cast<float>(p) * 1e-4f;
        const Vec2 uv[4] = {{o, 0}, {1 + o, 0}, {o, 1}, {1 + o, 1}};
        sum += m.patch_range(uv).d_max;
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_GT(sum, 0.0f);
    EXPECT_LT(s, 3.0);
}
