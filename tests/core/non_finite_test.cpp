// Input no kernel mis-culls: a patch with a NaN or infinite coordinate is never culled by any CPU
// kernel (frustum.h, hiz.h, fused_cull.h, backpatch.h, displaced_bounds.h), whichever component of
// whichever control point it is in; and weights <= 0 are refused where patches enter a batch
// (patch.h). Each base patch is culled by its kernel while finite, so the tests can fail.
#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/camera.h"
#include "patchcull/core/clip_space.h"
#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/fused_cull.h"
#include "patchcull/core/hiz.h"

#include "core/test_patches.h"

using namespace patchcull;

namespace {

using test_patches::flat_patch;

// The base patch and its 192 poisoned copies (test_patches::poisoned_copies) in a batch filled
// through component(): weights of NaN and -Inf must reach the kernels too.
PatchBatch poisoned_copies(const BezierPatch& base) {
    const std::vector<BezierPatch> patches = test_patches::poisoned_copies(base);
    PatchBatch batch(patches.size());
    for (std::size_t n = 0; n < patches.size(); ++n)
        for (int k = 0; k < kPatchPoints; ++k) {
            batch.component(k, 0)[n] = patches[n].cp[k].x;
            batch.component(k, 1)[n] = patches[n].cp[k].y;
            batch.component(k, 2)[n] = patches[n].cp[k].z;
            batch.component(k, 3)[n] = patches[n].cp[k].w;
        }
    return batch;
}

using Kernel = std::function<void(const PatchBatchView&, std::uint8_t*)>;

// Runs kernel on the poisoned batch: the base patch must be culled (decision != 0), no poisoned
// copy may be.
void expect_only_base_culled(const char* name, const BezierPatch& base, const Kernel& kernel) {
    const PatchBatch batch = poisoned_copies(base);
    std::vector<std::uint8_t> decision(batch.size(), 0xEE);
    kernel(batch.view(), decision.data());
    EXPECT_NE(decision[0], 0) << name << ": the finite base patch must be culled (else the test shows nothing)";
    for (std::size_t i = 1; i < batch.size(); ++i) {
        const std::size_t j = i - 1;
        EXPECT_EQ(decision[i], 0) << name << ": point " << j / 12 << " component " << j / 3 % 4 << " value "
                                  << (j % 3 == 0   ? "NaN"
                                      : j % 3 == 1 ? "+Inf"
                                                   : "-Inf");
    }
}

}  // namespace

TEST(NonFinite, NoKernelCullsAPatchWithANonFiniteCoordinate) {
    const Camera camera;  // eye (0, 0, 5) looking down -z
    for (ClipDepth depth : {ClipDepth::zero_to_one, ClipDepth::reversed_infinite}) {
        const Mat4 proj = perspective(camera.fovy_radians, camera.aspect, camera.z_near, camera.z_far, depth);
        const Mat4 m = proj * camera.view();
        const FrustumPlanes planes = make_frustum_planes(m, depth);
        const BezierPatch outside = flat_patch(30.0f, 0.0f, 0.0f, false);              // far right of the view
        const BezierPatch behind_wall = flat_patch(-0.5f, -0.5f, -2.0f, false);        // in view, behind depth 0.1
        const std::vector<float> wall(64 * 64, is_reversed(depth) ? 0.999f : 0.001f);  // just beyond the near plane
        HiZPyramid hiz;
        hiz.build(wall.data(), 64, 64, depth);
        const std::string tag = std::string(" (") + clip_depth_name(depth) + ")";
        const std::vector<float> zero_margin(1 + kPatchPoints * 12, 0.0f), margin(1 + kPatchPoints * 12, 0.25f);

        expect_only_base_culled(
            ("frustum scalar" + tag).c_str(), outside,
            [&](const PatchBatchView& v, std::uint8_t* d) { cull_frustum_scalar(v, nullptr, planes, d); });
        expect_only_base_culled(("frustum simd" + tag).c_str(), outside, [&](const PatchBatchView& v, std::uint8_t* d) {
            cull_frustum_simd(v, nullptr, planes, d);
        });
        expect_only_base_culled(
            ("frustum scalar margins" + tag).c_str(), outside,
            [&](const PatchBatchView& v, std::uint8_t* d) { cull_frustum_scalar(v, margin.data(), planes, d); });
        expect_only_base_culled(
            ("frustum simd margins" + tag).c_str(), outside,
            [&](const PatchBatchView& v, std::uint8_t* d) { cull_frustum_simd(v, margin.data(), planes, d); });
        expect_only_base_culled(("frustum-disp scalar" + tag).c_str(), outside,
                                [&](const PatchBatchView& v, std::uint8_t* d) {
                                    cull_frustum_disp_scalar(v, zero_margin.data(), m, depth, d);
                                });
        expect_only_base_culled(("frustum-disp simd" + tag).c_str(), outside,
                                [&](const PatchBatchView& v, std::uint8_t* d) {
                                    cull_frustum_disp_simd(v, zero_margin.data(), m, depth, d);
                                });
        for (const BezierPatch* base : {&outside, &behind_wall}) {
            const std::string where = (base == &outside ? " outside" : " occluded") + tag;
            expect_only_base_culled(
                ("occlusion scalar" + where).c_str(), *base,
                [&](const PatchBatchView& v, std::uint8_t* d) { cull_occlusion_scalar(v, m, depth, hiz, d); });
            expect_only_base_culled(
                ("occlusion simd" + where).c_str(), *base,
                [&](const PatchBatchView& v, std::uint8_t* d) { cull_occlusion_simd(v, m, depth, hiz, d); });
            const FusedCullSetup setup = make_fused_setup(m, depth, camera.eye, BackPatchCone::tcone, &hiz);
            FusedPlan plans[6];
            const int count = fused_plans_of(7u, plans);
            for (int i = 0; i < count; ++i) {
                std::string plan = " fused " + fused_plan_name(plans[i]);
                plan += where;
                expect_only_base_culled(("scalar" + plan).c_str(), *base,
                                        [&](const PatchBatchView& v, std::uint8_t* d) {
                                            cull_fused_scalar(v, setup, plans[i], d, nullptr);
                                        });
                expect_only_base_culled(("simd" + plan).c_str(), *base, [&](const PatchBatchView& v, std::uint8_t* d) {
                    cull_fused_simd(v, setup, plans[i], d, nullptr);
                });
            }
            const DisplacedCullView dview = make_displaced_cull_view(camera.view(), proj, depth);
            for (DisplacedBoundKind kind : {DisplacedBoundKind::caf, DisplacedBoundKind::oobb}) {
                const bool caf = kind == DisplacedBoundKind::caf;
                const std::string occlusion = (caf ? "displaced occlusion caf" : "displaced occlusion oobb") + where;
                const std::string frustum = (caf ? "displaced frustum caf" : "displaced frustum oobb") + tag;
                expect_only_base_culled(occlusion.c_str(), *base, [&](const PatchBatchView& v, std::uint8_t* d) {
                    cull_displaced_occlusion(v, nullptr, kind, NormalConeKind::full, dview, hiz, d);
                });
                if (base == &outside)
                    expect_only_base_culled(frustum.c_str(), *base, [&](const PatchBatchView& v, std::uint8_t* d) {
                        cull_displaced_frustum(v, nullptr, kind, NormalConeKind::full, dview, d);
                    });
            }
        }
    }
}

TEST(NonFinite, NoBackPatchKernelCullsAPatchWithANonFiniteCoordinate) {
    const Camera camera;
    const Mat4 m = camera.view_projection();
    const float alpha = clip_space_eye_alpha(camera.projection());
    const BezierPatch facing_away = flat_patch(-0.5f, 0.5f, 0.0f, true);  // normal -z, eye at +z
    const std::pair<const char*, Kernel> kernels[] = {
        {"tcone scalar", [&](const PatchBatchView& v, std::uint8_t* d) { cull_tcone_scalar(v, camera.eye, d); }},
        {"tcone simd", [&](const PatchBatchView& v, std::uint8_t* d) { cull_tcone_simd(v, camera.eye, d); }},
        {"ncone scalar", [&](const PatchBatchView& v, std::uint8_t* d) { cull_ncone_scalar(v, camera.eye, d); }},
        {"ncone simd", [&](const PatchBatchView& v, std::uint8_t* d) { cull_ncone_simd(v, camera.eye, d); }},
        {"ptp scalar",
         [&](const PatchBatchView& v, std::uint8_t* d) { cull_ptp_scalar(v, m, alpha, PtpRule::ncnt, d); }},
        {"ptp simd", [&](const PatchBatchView& v, std::uint8_t* d) { cull_ptp_simd(v, m, alpha, PtpRule::ncnt, d); }},
        {"ptp simd pcnt",
         [&](const PatchBatchView& v, std::uint8_t* d) { cull_ptp_simd(v, m, alpha, PtpRule::pcnt, d); }},
    };
    for (const auto& [name, kernel] : kernels) expect_only_base_culled(name, facing_away, kernel);
}

TEST(PatchWeights, BatchesRefuseWeightsThatAreNotPositive) {
    const BezierPatch good = flat_patch(0, 0, 0, false);
    for (float w : {0.0f, -0.0f, -1.0f, -std::numeric_limits<float>::infinity()}) {
        BezierPatch bad = good;
        bad.cp[5].w = w;
        PatchBatch batch(3);
        PatchBlocks blocks(3);
        try {
            batch.set(2, bad);
            ADD_FAILURE() << "PatchBatch::set accepted weight " << w;
        } catch (const Error& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find("patch 2: control point 5 has weight"), std::string::npos) << what;
            EXPECT_NE(what.find("weights must be positive"), std::string::npos) << what;
        }
        EXPECT_THROW(blocks.set(1, bad), Error);
        EXPECT_THROW((void)make_batch({good, bad}), Error);
        // Every weight negative: the same surface, still refused (the message says how to mend it).
        BezierPatch negated = good;
        for (Vec4& c : negated.cp) c = c * -1.0f;
        EXPECT_THROW(batch.set(0, negated), Error);
    }
    // Positive, NaN and +Inf weights pass (the kernels never cull the non-finite ones).
    for (float w : {1e-30f, 2.0f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
        BezierPatch p = good;
        p.cp[0].w = w;
        PatchBatch batch(1);
        EXPECT_NO_THROW(batch.set(0, p)) << w;
    }
}
