// The fused kernel (patchcull/core/fused_cull.h): for every valid plan, on random batches with a real
// depth pyramid, its decisions equal the separate kernels' (frustum, tcone or ncone, Hi-Z), the
// reason being the first culling stage of the plan; scalar and SIMD (every Highway target) agree,
// in both layouts, whole and in subranges; the profiling variant decides the same and its counts
// are consistent; statistics add up.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/fused_cull.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"

using namespace patchcull;

namespace {

// Debug + sanitizer builds (the ASan + UBSan run of scripts/test.sh) are ~30x slower: there the
// SIMD kernel runs on the dispatched target only and on fewer seeds (the Release run does all).
#if defined(__SANITIZE_ADDRESS__) || !defined(NDEBUG)
constexpr bool kSlowBuild = true;
#else
constexpr bool kSlowBuild = false;
#endif

void for_each_simd_target(const std::function<void()>& body) {
    if (kSlowBuild) {
        body();
        return;
    }
    for (std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
        hwy::SetSupportedTargetsForTest(target);
        SCOPED_TRACE(std::string("SIMD target ") + hwy::TargetName(target));
        body();
    }
    hwy::SetSupportedTargetsForTest(0);
}

struct Case {
    Mat4 object_to_clip;
    Vec3 eye;
    HiZPyramid hiz;
    std::vector<BezierPatch> patches;
};

// A random camera looking into a cloud of curved patches: some outside the frustum, some behind
// a depth layer of random screen rectangles, about half facing away, some straddling the eye
// plane, some rational (never culled by the cones). offset moves everything far from the origin
// (the kernels work in the caller's frame; the patches and the eye move together).
Case random_case(std::uint32_t seed, int W, int H, Vec3 offset) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    Case c;
    const Vec3 eye = offset + Vec3{4 * u(rng), 4 * u(rng), 4 * u(rng)};
    const Vec3 target = eye + Vec3{u(rng), u(rng), u(rng) - 1.5f};
    const Mat4 view = look_at(eye, target, {0, 1, 0});
    c.object_to_clip = perspective(1.0f + 0.4f * unit(rng), float(W) / float(H), 0.1f, 100.0f) * view;
    c.eye = eye;
    Mat4 inv;
    invert(view, inv);
    // Depth layer: far, with random rectangles at view distances 4..12.
    std::vector<float> depth(static_cast<std::size_t>(W) * H, 1.0f);
    const float n = 0.1f, f = 100.0f;
    for (int r = 0; r < 12; ++r) {
        const int x0 = static_cast<int>(unit(rng) * W), y0 = static_cast<int>(unit(rng) * H);
        const int w = 1 + static_cast<int>(unit(rng) * W * 0.6f), h = 1 + static_cast<int>(unit(rng) * H * 0.6f);
        const float dist = 4 + 8 * unit(rng);
        const float z = (f / (f - n)) * (1 - n / dist);
        for (int y = y0; y < std::min(H, y0 + h); ++y)
            for (int x = x0; x < std::min(W, x0 + w); ++x) {
                float& d = depth[static_cast<std::size_t>(y) * W + x];
                d = std::min(d, z);
            }
    }
    c.hiz.build(depth.data(), W, H);
    // Patches in view space, then to world.
    const int count = 700;
    for (int i = 0; i < count; ++i) {
        const int kind = static_cast<int>(rng() % 8);
        const float dist = kind == 0 ? 0.5f + 3 * unit(rng) : 2 + 30 * unit(rng);
        const float spread = kind == 1 ? 3.0f : 1.0f;  // often outside the frustum
        Vec3 centre{dist * 0.6f * u(rng) * spread, dist * 0.5f * u(rng) * spread, -dist};
        const float size = dist * (kind == 2 ? 0.002f : 0.03f + 0.2f * unit(rng));
        Vec3 a{u(rng), u(rng), u(rng)}, b{u(rng), u(rng), u(rng)};
        if (kind == 3) {  // straddles the eye plane
            centre = {u(rng), u(rng), 0.3f * u(rng)};
            a = {u(rng), u(rng), -8};
        }
        const float bulge = kind == 4 ? 1.5f : 0.3f;
        BezierPatch p;
        for (int j = 0; j < 4; ++j)
            for (int k = 0; k < 4; ++k) {
                const float s = k / 3.0f - 0.5f, t = j / 3.0f - 0.5f;
                const Vec3 pv =
                    centre + (a * s + b * t) * size + cross(a, b) * (bulge * size * (s * s + t * t) * u(rng));
                const Vec4 w4 = inv * Vec4{pv.x, pv.y, pv.z, 1};
                const float w = kind == 5 ? 0.5f + 1.5f * unit(rng) : 1.0f;
                p.cp[4 * j + k] = homogeneous(Vec3{w4.x, w4.y, w4.z}, w);
            }
        c.patches.push_back(p);
    }
    return c;
}

// The separate kernels' verdicts, per patch.
struct Verdicts {
    std::vector<std::uint8_t> frustum, backpatch, occlusion;  // occlusion: cull_occlusion_scalar == occluded
};

Verdicts separate_verdicts(const Case& c, const PatchBatchView& v, BackPatchCone cone) {
    Verdicts out;
    out.frustum.resize(v.count);
    out.backpatch.resize(v.count);
    out.occlusion.resize(v.count);
    cull_frustum_scalar(v, nullptr, make_frustum_planes(c.object_to_clip, ClipDepth::zero_to_one), out.frustum.data());
    (cone == BackPatchCone::tcone ? cull_tcone_scalar : cull_ncone_scalar)(v, c.eye, out.backpatch.data());
    cull_occlusion_scalar(v, c.object_to_clip, ClipDepth::zero_to_one, c.hiz, out.occlusion.data());
    for (auto& o : out.occlusion) o = o == kHiZOccluded ? 1 : 0;
    return out;
}

std::vector<std::uint8_t> expected_decisions(const Verdicts& s, const FusedPlan& plan) {
    std::vector<std::uint8_t> out(s.frustum.size(), kFusedVisible);
    for (std::size_t p = 0; p < out.size(); ++p)
        for (int i = 0; i < plan.count && out[p] == kFusedVisible; ++i) {
            switch (plan.stages[i]) {
                case FusedStage::frustum:
                    if (s.frustum[p]) out[p] = kFusedFrustumCulled;
                    break;
                case FusedStage::backpatch:
                    if (s.backpatch[p]) out[p] = kFusedBackPatchCulled;
                    break;
                case FusedStage::occlusion:
                    if (s.occlusion[p]) out[p] = kFusedOccluded;
                    break;
            }
        }
    return out;
}

std::vector<FusedPlan> all_plans() {
    std::vector<FusedPlan> plans;
    for (unsigned stages = 1; stages < 8; ++stages) {
        FusedPlan out[6];
        const int n = fused_plans_of(stages, out);
        plans.insert(plans.end(), out, out + n);
    }
    return plans;
}

using Kernel = void (*)(const PatchBatchView&, const FusedCullSetup&, const FusedPlan&, std::uint8_t*, FusedCullStats*);

std::vector<std::uint8_t> run(Kernel kernel, const PatchBatchView& v, const FusedCullSetup& setup,
                              const FusedPlan& plan, FusedCullStats* stats = nullptr) {
    constexpr std::size_t kGuard = 32;
    std::vector<std::uint8_t> out(v.count + kGuard, 0xAB);
    kernel(v, setup, plan, out.data(), stats);
    for (std::size_t i = v.count; i < out.size(); ++i) EXPECT_EQ(out[i], 0xAB) << "wrote past count at " << i;
    out.resize(v.count);
    return out;
}

}  // namespace

TEST(FusedCullPlans, ValidPlansAndNames) {
    const std::vector<FusedPlan> plans = all_plans();
    std::vector<std::string> names;
    for (const FusedPlan& p : plans) {
        EXPECT_TRUE(valid_fused_plan(p));
        names.push_back(fused_plan_name(p));
    }
    std::sort(names.begin(), names.end());
    // F, B alone; FB and BF; FH; FBH, FHB and BFH (H never before F, never alone).
    EXPECT_EQ(names, (std::vector<std::string>{"B", "BF", "BFH", "F", "FB", "FBH", "FH", "FHB"}));
    FusedPlan bad;
    bad.stages[0] = FusedStage::occlusion;
    bad.stages[1] = FusedStage::frustum;
    bad.count = 2;
    EXPECT_FALSE(valid_fused_plan(bad));
    bad.count = 1;
    EXPECT_FALSE(valid_fused_plan(bad));
    bad.stages[0] = FusedStage::frustum;
    bad.stages[1] = FusedStage::frustum;
    bad.count = 2;
    EXPECT_FALSE(valid_fused_plan(bad));
    bad.count = 0;
    EXPECT_FALSE(valid_fused_plan(bad));
}

constexpr std::uint32_t kSeeds = kSlowBuild ? 2 : 6;

TEST(FusedCull, EveryPlanEqualsTheSeparateKernelsScalarAndSimdBothLayouts) {
    std::size_t totals[4] = {};
    for (std::uint32_t seed = 1; seed <= kSeeds; ++seed) {
        const Vec3 offset = seed % 3 == 0 ? Vec3{3000, -2000, 1500} : Vec3{0, 0, 0};
        const Case c = random_case(seed, seed % 2 ? 320 : 97, seed % 2 ? 180 : 61, offset);
        const PatchBatch batch = make_batch(c.patches);
        const PatchBlocks blocks(batch.view());
        for (BackPatchCone cone : {BackPatchCone::tcone, BackPatchCone::ncone}) {
            const Verdicts verdicts = separate_verdicts(c, batch.view(), cone);
            const FusedCullSetup setup =
                make_fused_setup(c.object_to_clip, ClipDepth::zero_to_one, c.eye, cone, &c.hiz);
            for (const FusedPlan& plan : all_plans()) {
                SCOPED_TRACE("seed " + std::to_string(seed) + " plan " + fused_plan_name(plan));
                const std::vector<std::uint8_t> expected = expected_decisions(verdicts, plan);
                ASSERT_EQ(run(cull_fused_scalar, batch.view(), setup, plan), expected);
                ASSERT_EQ(run(cull_fused_scalar, blocks.view(), setup, plan), expected);
                for_each_simd_target([&] {
                    ASSERT_EQ(run(cull_fused_simd, batch.view(), setup, plan), expected);
                    ASSERT_EQ(run(cull_fused_simd, blocks.view(), setup, plan), expected);
                    // Subranges: plain at any offset, blocked at block starts.
                    for (std::size_t first : {std::size_t{0}, std::size_t{16}, std::size_t{48}}) {
                        const std::size_t n = std::min<std::size_t>(37, c.patches.size() - first);
                        const std::vector<std::uint8_t> part(expected.begin() + first, expected.begin() + first + n);
                        ASSERT_EQ(run(cull_fused_simd, batch.view().subrange(first + 3, n - 3), setup, plan),
                                  std::vector<std::uint8_t>(part.begin() + 3, part.end()));
                        ASSERT_EQ(run(cull_fused_simd, blocks.view().subrange(first, n), setup, plan), part);
                    }
                });
                if (plan.count == 3)
                    for (std::uint8_t d : expected) ++totals[d];
            }
        }
    }
    // Every outcome is well represented, so the equalities above say something.
    for (int d = 0; d < 4; ++d) EXPECT_GT(totals[d], 60u * kSeeds) << "decision " << d;
}

TEST(FusedCull, FrustumThenOcclusionIsTheHiZKernel) {
    for (std::uint32_t seed = 11; seed <= 14; ++seed) {
        const Case c = random_case(seed, 200, 150, {0, 0, 0});
        const PatchBatch batch = make_batch(c.patches);
        std::vector<std::uint8_t> hiz_scalar(c.patches.size()), hiz_simd(c.patches.size());
        cull_occlusion_scalar(batch.view(), c.object_to_clip, ClipDepth::zero_to_one, c.hiz, hiz_scalar.data());
        FusedPlan plan;
        plan.stages[0] = FusedStage::frustum;
        plan.stages[1] = FusedStage::occlusion;
        plan.count = 2;
        const FusedCullSetup setup =
            make_fused_setup(c.object_to_clip, ClipDepth::zero_to_one, c.eye, BackPatchCone::tcone, &c.hiz);
        EXPECT_EQ(run(cull_fused_scalar, batch.view(), setup, plan), hiz_scalar);
        for_each_simd_target([&] {
            cull_occlusion_simd(batch.view(), c.object_to_clip, ClipDepth::zero_to_one, c.hiz, hiz_simd.data());
            EXPECT_EQ(hiz_simd, hiz_scalar);
        });
    }
}

TEST(FusedCull, StatisticsAndProfileAreConsistent) {
    const Case c = random_case(21, 320, 180, {0, 0, 0});
    const PatchBatch batch = make_batch(c.patches);
    const FusedCullSetup setup =
        make_fused_setup(c.object_to_clip, ClipDepth::zero_to_one, c.eye, BackPatchCone::tcone, &c.hiz);
    for (const FusedPlan& plan : all_plans()) {
        SCOPED_TRACE(fused_plan_name(plan));
        FusedCullStats stats;
        const std::vector<std::uint8_t> d = run(cull_fused_simd, batch.view(), setup, plan, &stats);
        std::size_t by_reason[4] = {};
        for (std::uint8_t x : d) ++by_reason[x];
        EXPECT_EQ(stats.patches_culled[0], by_reason[kFusedFrustumCulled]);
        EXPECT_EQ(stats.patches_culled[1], by_reason[kFusedBackPatchCulled]);
        EXPECT_EQ(stats.patches_culled[2], by_reason[kFusedOccluded]);
        EXPECT_EQ(stats.groups_entered[0], stats.groups);
        for (int i = 1; i < plan.count; ++i) EXPECT_LE(stats.groups_entered[i], stats.groups_entered[i - 1]);
        // The early exit only ever skips work: the scalar reference (1-patch groups) enters later
        // stages exactly as often as there are patches still visible before them.
        FusedCullStats scalar;
        run(cull_fused_scalar, batch.view(), setup, plan, &scalar);
        EXPECT_EQ(scalar.groups, c.patches.size());

        FusedProfile profile;
        std::vector<std::uint8_t> pd(c.patches.size());
        cull_fused_profile_simd(batch.view(), setup, plan, pd.data(), profile, 0);
        EXPECT_EQ(pd, d);
        EXPECT_EQ(profile.groups, stats.groups);
        EXPECT_EQ(profile.decided[0], 0u);
        unsigned in_plan = 0;
        for (int i = 0; i < plan.count; ++i) in_plan |= 1u << static_cast<unsigned>(plan.stages[i]);
        for (unsigned s = 1; s < 8; ++s) {
            if (s & ~in_plan) {
                EXPECT_EQ(profile.decided[s], 0u);
                continue;
            }
            EXPECT_LE(profile.decided[s], profile.groups);
            for (unsigned sub = 1; sub < 8; ++sub) {
                if ((sub & s) == sub) {
                    EXPECT_LE(profile.decided[sub], profile.decided[s]);  // more stages decide more
                }
            }
        }
        // The groups that leave after stage i of the real run are those the prefix decides.
        unsigned prefix = 0;
        for (int i = 0; i + 1 < plan.count; ++i) {
            prefix |= 1u << static_cast<unsigned>(plan.stages[i]);
            EXPECT_EQ(stats.groups_entered[i + 1], profile.groups - profile.decided[prefix]);
        }
        for (int i = 0; i < plan.count; ++i) EXPECT_GT(profile.seconds_per_group(plan.stages[i]), 0.0);
    }
}

TEST(FusedCull, ProfilingASampleOfGroupsDecidesTheSame) {
    Case c = random_case(31, 320, 180, {0, 0, 0});
    const Case more = random_case(32, 320, 180, {0, 0, 0});
    for (int i = 0; i < 6; ++i) c.patches.insert(c.patches.end(), more.patches.begin(), more.patches.end());
    const PatchBatch batch = make_batch(c.patches);
    const FusedCullSetup setup =
        make_fused_setup(c.object_to_clip, ClipDepth::zero_to_one, c.eye, BackPatchCone::tcone, &c.hiz);
    const FusedPlan plan;  // FBH
    const std::vector<std::uint8_t> d = run(cull_fused_simd, batch.view(), setup, plan);
    for (std::size_t max_groups : {std::size_t{1}, std::size_t{8}, std::size_t{32}}) {
        FusedProfile profile;
        std::vector<std::uint8_t> pd(c.patches.size());
        cull_fused_profile_simd(batch.view(), setup, plan, pd.data(), profile, max_groups);
        EXPECT_EQ(pd, d);
        FusedProfile all;
        cull_fused_profile_simd(batch.view(), setup, plan, pd.data(), all, 0);
        // About max_groups groups profiled (every k-th, k = groups / max_groups), never all of them.
        EXPECT_GE(profile.groups, max_groups);
        EXPECT_LT(profile.groups, 2 * max_groups + 1);
        EXPECT_LT(profile.groups, all.groups);
        EXPECT_GT(profile.seconds_per_group(FusedStage::frustum), 0.0);
    }
}
