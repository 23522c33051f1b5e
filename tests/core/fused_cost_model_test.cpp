// The fused kernel's cost model (patchcull/core/fused_cost_model.h): the plan it chooses follows the
// expected time sum_i c(s_i) (1 - P(S_{i-1})) from measured stage costs and decided fractions
// (profiles built by hand here: speed itself is measured by `patchcull eval fused`, never in a
// test), its profiling schedule, and the refresh of prefix rates from ordinary runs; then, on
// real kernel runs, that whatever it chooses decides exactly as the fixed plans do.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "patchcull/core/fused_cost_model.h"
#include "patchcull/core/fused_cull.h"

using namespace patchcull;

namespace {

constexpr unsigned F = 1u << static_cast<unsigned>(FusedStage::frustum);
constexpr unsigned B = 1u << static_cast<unsigned>(FusedStage::backpatch);
constexpr unsigned H = 1u << static_cast<unsigned>(FusedStage::occlusion);

// A profile of `groups` groups (16 patches each) in which stage costs are cost[F,B,H] seconds per
// group and subset S decides decided(S) * groups of them (and culls the same fraction of patches).
FusedProfile make_profile(double cf, double cb, double ch, double pf, double pb, double ph,
                          std::uint64_t groups = 1000) {
    FusedProfile p;
    p.groups = groups;
    const double cost[3] = {cf, cb, ch};
    double total = 0;
    for (int s = 0; s < 3; ++s) {
        p.ticks[s] = static_cast<std::uint64_t>(cost[s] * 1e12) * groups;
        total += cost[s];
    }
    p.seconds = total * static_cast<double>(groups);
    p.call_ticks = static_cast<std::uint64_t>(total * 1e12) * groups;
    const double alone[3] = {pf, pb, ph};
    for (unsigned s = 1; s < 8; ++s) {
        // Independent stages: a group survives S when it survives each stage of S.
        double survive = 1;
        for (int st = 0; st < 3; ++st)
            if (s & (1u << st)) survive *= 1 - alone[st];
        p.decided[s] = static_cast<std::uint64_t>(std::llround((1 - survive) * static_cast<double>(groups)));
        p.patches_culled_by[s] = p.decided[s] * 16;
    }
    return p;
}

std::string chosen(const FusedCostModel& m, std::size_t object, unsigned available = kAllFusedStages) {
    return fused_plan_name(m.choose(object, available));
}

}  // namespace

TEST(FusedCostModel, ChoosesTheOrderOfLeastExpectedTime) {
    FusedCostModel m(3);
    // Costs per group: frustum 1, cone 3, Hi-Z 2 (microseconds, any unit).
    // Object 0: behind a wall (Hi-Z decides 95% of groups, the cone 30%): F, then H, then B.
    m.observe_profile(0, kAllFusedStages, make_profile(1e-6, 3e-6, 2e-6, 0.0, 0.3, 0.95), 16000);
    EXPECT_EQ(chosen(m, 0), "FHB");
    // Object 1: in plain view, facing away (the cone decides 90%, Hi-Z nothing): B first.
    m.observe_profile(1, kAllFusedStages, make_profile(1e-6, 3e-6, 2e-6, 0.0, 0.9, 0.0), 16000);
    EXPECT_EQ(chosen(m, 1), "BFH");
    // Object 2: mostly outside the frustum, the rest facing the eye in view: F, B is useless, H last
    // is cheaper than B... both FBH and FHB start with F; with the cone deciding nothing and Hi-Z
    // a little, H before B.
    m.observe_profile(2, kAllFusedStages, make_profile(1e-6, 3e-6, 2e-6, 0.8, 0.0, 0.1), 16000);
    EXPECT_EQ(chosen(m, 2), "FHB");
    // The choice is the minimum of expected_seconds over every plan with all the stages.
    for (std::size_t o = 0; o < 3; ++o) {
        FusedPlan plans[6];
        const int n = fused_plans_of(kAllFusedStages, plans);
        const FusedPlan c = m.choose(o, kAllFusedStages);
        for (int i = 0; i < n; ++i)
            EXPECT_LE(m.expected_seconds(o, c, 1, 16), m.expected_seconds(o, plans[i], 1, 16) + 1e-18);
    }
    // Expected time by hand for object 0, FHB: 1 + (1 - 0)*2 + (1 - P(FH))*3 with P(FH) = 0.95.
    FusedPlan fhb = m.choose(0, kAllFusedStages);
    EXPECT_NEAR(m.expected_seconds(0, fhb, 1, 16), 1e-6 + 2e-6 + 0.05 * 3e-6, 1e-9);
}

TEST(FusedCostModel, OnlyAvailableStagesAndAllOfThemWithoutADrawCost) {
    FusedCostModel m(1);
    m.observe_profile(0, F | H, make_profile(1e-6, 3e-6, 2e-6, 0.5, 0.0, 0.0), 1600);
    EXPECT_EQ(chosen(m, 0, F | H), "FH");  // Hi-Z decides nothing, but leaving it out would draw more
    EXPECT_EQ(chosen(m, 0, F), "F");
    EXPECT_EQ(chosen(m, 0, B), "B");
    EXPECT_EQ(chosen(m, 0, H), "FH");  // occlusion needs the frustum stage's clip coordinates
}

TEST(FusedCostModel, AFiniteDrawCostDropsTestsThatDoNotPay) {
    FusedCostModel::Config config;
    config.draw_seconds_per_patch = 1e-9;  // drawing is cheap: a test must cull a lot to pay
    FusedCostModel cheap(1, config);
    // The cone culls 1% of the patches at 3 us per group of 16: culls 0.16 patches per group,
    // saving 0.16 ns: not worth it. Hi-Z culls 60%: 9.6 patches, 9.6 ns < its 2 us: not worth it
    // either; frustum alone is cheapest... and even it is dropped only if its cost exceeds its
    // saving; the model compares totals, so here the best plan is the one stage of least cost.
    cheap.observe_profile(0, kAllFusedStages, make_profile(1e-6, 3e-6, 2e-6, 0.0, 0.01, 0.6), 16000);
    EXPECT_EQ(chosen(cheap, 0), "F");
    config.draw_seconds_per_patch = 1e-3;  // drawing is dear: every test that culls anything pays
    FusedCostModel dear(1, config);
    dear.observe_profile(0, kAllFusedStages, make_profile(1e-6, 3e-6, 2e-6, 0.0, 0.01, 0.6), 16000);
    EXPECT_EQ(chosen(dear, 0).size(), 3u);
}

TEST(FusedCostModel, ProfilesFirstThenEveryIntervalStaggered) {
    FusedCostModel::Config config;
    config.profile_interval = 4;
    FusedCostModel m(3, config);
    for (std::size_t o = 0; o < 3; ++o) EXPECT_TRUE(m.should_profile(o, kAllFusedStages)) << "never profiled";
    for (std::size_t o = 0; o < 3; ++o)
        m.observe_profile(o, kAllFusedStages, make_profile(1e-6, 1e-6, 1e-6, 0, 0, 0), 16);
    std::vector<std::vector<int>> due(3);
    for (int frame = 1; frame <= 12; ++frame) {
        m.next_frame();
        for (std::size_t o = 0; o < 3; ++o)
            if (m.should_profile(o, kAllFusedStages)) {
                due[o].push_back(frame);
                m.observe_profile(o, kAllFusedStages, make_profile(1e-6, 1e-6, 1e-6, 0, 0, 0), 16);
            }
    }
    EXPECT_EQ(due[0], (std::vector<int>{4, 8, 12}));
    EXPECT_EQ(due[1], (std::vector<int>{7, 11}));  // (frame + 1) % 4 == 0, at least 4 after frame 0
    EXPECT_EQ(due[2], (std::vector<int>{6, 10}));
    EXPECT_TRUE(m.should_profile(0, F | B)) << "its stages changed";
}

TEST(FusedCostModel, OrdinaryRunsRefreshThePrefixRates) {
    FusedCostModel::Config config;
    config.rate_weight = 1.0;  // take the newest observation
    FusedCostModel m(1, config);
    m.observe_profile(0, kAllFusedStages, make_profile(1e-6, 3e-6, 2e-6, 0.0, 0.3, 0.95), 16000);
    EXPECT_EQ(chosen(m, 0), "FHB");
    // The object comes out from behind the wall: the FHB run sees Hi-Z decide nothing.
    FusedPlan plan = m.choose(0, kAllFusedStages);
    FusedCullStats stats;
    stats.groups = 100;
    stats.groups_entered[0] = 100;
    stats.groups_entered[1] = 100;  // frustum decided nothing
    stats.groups_entered[2] = 100;  // frustum + Hi-Z decided nothing
    m.observe(0, plan, stats);
    EXPECT_DOUBLE_EQ(m.decided_fraction(0, F | H), 0.0);
    // Now F, B first (the cone's 30% still pays before the dearer Hi-Z? 1 + 3 + 0.7*2 = 5.4 against
    // FHB 1 + 2 + 3 = 6, BFH 3 + 0.7 + 0.7*2 = 5.1): BFH.
    EXPECT_EQ(chosen(m, 0), "BFH");
}

TEST(FusedCostModel, WhateverItChoosesTheDecisionsAreTheFixedPlans) {
    // A batch of random patches and a random pyramid; the model, fed real profiles, picks some
    // plan; every plan with all three stages culls the same patches (reasons may differ).
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1, 1);
    std::vector<BezierPatch> patches(300);
    for (BezierPatch& p : patches) {
        const Vec3 c{4 * u(rng), 4 * u(rng), -6 + 4 * u(rng)};
        for (int k = 0; k < 16; ++k) {
            const int col = k % 4, row = k / 4;
            p.cp[k] = homogeneous(c + Vec3{col * 0.2f, row * 0.2f, 0.1f * u(rng)});
        }
    }
    const PatchBatch batch = make_batch(patches);
    std::vector<float> depth(64 * 48);
    for (float& d : depth) d = 0.5f + 0.5f * (u(rng) > 0);
    HiZPyramid hiz;
    hiz.build(depth.data(), 64, 48);
    const Mat4 m4 = perspective(1.2f, 64.0f / 48, 0.1f, 50.0f);
    const FusedCullSetup setup = make_fused_setup(m4, ClipDepth::zero_to_one, {0, 0, 0}, BackPatchCone::tcone, &hiz);
    FusedCostModel model(1);
    std::vector<std::uint8_t> reference(patches.size()), out(patches.size());
    FusedPlan fbh;
    cull_fused_simd(batch.view(), setup, fbh, reference.data());
    for (int frame = 0; frame < 20; ++frame) {
        const FusedPlan plan = model.choose(0, kAllFusedStages);
        ASSERT_TRUE(valid_fused_plan(plan));
        ASSERT_EQ(plan.count, 3);
        if (model.should_profile(0, kAllFusedStages)) {
            FusedProfile profile;
            cull_fused_profile_simd(batch.view(), setup, plan, out.data(), profile);
            model.observe_profile(0, kAllFusedStages, profile, patches.size());
        } else {
            FusedCullStats stats;
            cull_fused_simd(batch.view(), setup, plan, out.data(), &stats);
            model.observe(0, plan, stats);
        }
        for (std::size_t p = 0; p < patches.size(); ++p) ASSERT_EQ(out[p] != 0, reference[p] != 0) << p;
        model.next_frame();
    }
    for (FusedStage s : {FusedStage::frustum, FusedStage::backpatch, FusedStage::occlusion})
        EXPECT_GT(model.stage_seconds(s), 0.0);
}
