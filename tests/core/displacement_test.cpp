// Displacement sampling and the per-patch range of Niessner & Loop, "Analytic Displacement Mapping using
// Hardware Tessellation": every displacement a patch can take lies in its [D_min, D_max].
#include <gtest/gtest.h>

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
    m.texels.resize(w * h);
    for (float& t : m.texels) t = unit(rng);
    return m;
}

}  // namespace

TEST(Displacement, SamplesTexelCentresExactlyAndWraps) {
    DisplacementMap m;
    m.width = 4;
    m.height = 2;
    m.scale = 2.0f;
    m.midlevel = 0.5f;
    m.texels = {0, 0.25f, 0.5f, 1, 1, 0.75f, 0.5f, 0};
    EXPECT_FLOAT_EQ(m.sample({0.125f, 0.25f}), 2.0f * (0 - 0.5f));
    EXPECT_FLOAT_EQ(m.sample({0.875f, 0.75f}), 2.0f * (0 - 0.5f));
    EXPECT_FLOAT_EQ(m.sample({0.375f, 0.75f}), 2.0f * (0.75f - 0.5f));
    EXPECT_FLOAT_EQ(m.sample({1.125f, 0.25f}), m.sample({0.125f, 0.25f}));   // wrap in s
    EXPECT_FLOAT_EQ(m.sample({0.375f, -1.75f}), m.sample({0.375f, 0.25f}));  // wrap in t
    // Halfway between the last and the first texel of a row blends across the seam.
    EXPECT_FLOAT_EQ(m.sample({0.0f, 0.25f}), 2.0f * (0.5f * (1 + 0) - 0.5f));
}

TEST(Displacement, EmptyMapDisplacesNothing) {
    DisplacementMap m;
    EXPECT_TRUE(m.empty());
    EXPECT_EQ(m.sample({0.3f, 0.3f}), 0.0f);
    const Vec2 uv[4] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
    EXPECT_EQ(m.patch_range(uv).max_abs(), 0.0f);
}

TEST(Displacement, PatchRangeHoldsEverySampleOfRandomPatches) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> coord(-1.5f, 2.5f), size(0.0f, 0.2f), unit(0, 1);
    for (int trial = 0; trial < 400; ++trial) {
        const float scale = (trial % 3 == 0 ? -1.0f : 1.0f) * (0.1f + unit(rng));
        DisplacementMap m = random_map(rng, 8 + trial % 57, 5 + trial % 31, scale);
        m.midlevel = unit(rng);
        // A skewed quad in texture space (bilinear texcoords), sometimes wrapping.
        const Vec2 base{coord(rng), coord(rng)};
        Vec2 uv[4];
        for (int k = 0; k < 4; ++k) uv[k] = base + Vec2{(k & 1) * size(rng) + size(rng) * 0.3f, (k >> 1) * size(rng)};
        const DisplacementRange r = m.patch_range(uv);
        EXPECT_LE(r.d_min, 0.0f);
        EXPECT_GE(r.d_max, 0.0f);
        for (int j = 0; j <= 32; ++j)
            for (int i = 0; i <= 32; ++i) {
                const float d = m.sample(patch_texcoord(uv, i / 32.0f, j / 32.0f));
                ASSERT_GE(d, r.d_min - 1e-6f) << "trial " << trial;
                ASSERT_LE(d, r.d_max + 1e-6f) << "trial " << trial;
            }
    }
}

TEST(Displacement, PatchRangeIsLocalNotGlobal) {
    // A map that is flat except for one spike: patches far from the spike get a tight range, the
    // patch over it sees the spike. A "range" that ignored the footprint would fail one of these.
    DisplacementMap m;
    m.width = m.height = 64;
    m.scale = 1.0f;
    m.midlevel = 0.0f;
    m.texels.assign(64 * 64, 0.0f);
    m.texels[40 * 64 + 40] = 1.0f;  // texel centre (40.5/64, 40.5/64)
    const Vec2 far_uv[4] = {{0.05f, 0.05f}, {0.2f, 0.05f}, {0.05f, 0.2f}, {0.2f, 0.2f}};
    EXPECT_EQ(m.patch_range(far_uv).d_max, 0.0f);
    const Vec2 near_uv[4] = {{0.6f, 0.6f}, {0.66f, 0.6f}, {0.6f, 0.66f}, {0.66f, 0.66f}};
    EXPECT_EQ(m.patch_range(near_uv).d_max, 1.0f);
}

TEST(Displacement, ProceduralMapSpansUnitRangeAndTiles) {
    const DisplacementMap m = make_procedural_displacement(128, 0.5f);
    float lo = 1, hi = 0;
    for (float t : m.texels) {
        lo = std::min(lo, t);
        hi = std::max(hi, t);
    }
    EXPECT_FLOAT_EQ(lo, 0.0f);
    EXPECT_FLOAT_EQ(hi, 1.0f);
    EXPECT_NEAR(m.sample({0.0f, 0.3f}), m.sample({1.0f, 0.3f}), 1e-5f);
    EXPECT_NE(make_procedural_displacement(128, 0.5f, 8).texels, m.texels);
}
