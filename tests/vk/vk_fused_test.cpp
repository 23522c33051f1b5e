// The Vulkan fused pass (patchcull/vk/vk_passes.h's FusedCullPass) on lavapipe with the validation
// layers on: for every mask of tests, tcone and ncone, every ClipDepth, each flag word equals the
// one the Vulkan chain begin -> FrustumPass -> BackpatchConePass -> OcclusionPass (no frustum)
// leaves with the same tests, and, where the mask has the frustum test or no Hi-Z test, the CPU
// scalar kernels' decisions in that order (cull_frustum_scalar, cull_tcone/ncone_scalar,
// cull_occlusion_scalar's kHiZOccluded).
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>

#include "core/test_patches.h"
#include "patchcull/core/backpatch.h"
#include "patchcull/core/clip_space.h"
#include "vk/vk_cases.h"
#include "vk/vk_images.h"

using namespace patchcull;
using namespace patchcull::vk;
using namespace patchcull::vk::test;

namespace {

class VkFused : public VkTest {};

}  // namespace

TEST_F(VkFused, WordsEqualTheChainAndTheCpuKernels) {
    const int w = 96, h = 64;
    std::size_t culled[3] = {0, 0, 0};
    for (const ClipDepth depth :
         {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one, ClipDepth::reversed, ClipDepth::reversed_infinite})
        for (const BackpatchMethod method : {BackpatchMethod::tcone, BackpatchMethod::ncone}) {
            // Random patches and, for the cones, flat ones facing every way.
            RandomCase c = random_case(depth == ClipDepth::reversed ? 61 : 62, 1500, depth, false);
            c.patches.reserve(c.patches.size() + 300);
            for (int i = 0; i < 300; ++i) {
                const int column = i % 20, row = i / 20;  // a 20 x 15 grid of flat patches
                c.patches.push_back(test_patches::flat_patch(static_cast<float>(column) - 10.0f,
                                                             static_cast<float>(row) - 7.0f,
                                                             static_cast<float>(i % 7) - 3.0f, i % 2 == 0));
            }
            const Mat4 m = c.camera.view_projection();
            const Vec3 eye = c.camera.eye;
            const std::vector<float> depths = wall_depths(c, m, depth, w, h);
            const FrustumPlanes planes = make_frustum_planes(m, depth);
            std::vector<std::unique_ptr<CaseBuffers>> fused_buffers, chain_buffers;
            for (std::uint32_t tests = 1; tests < 8; ++tests) {
                fused_buffers.push_back(std::make_unique<CaseBuffers>(c));
                chain_buffers.push_back(std::make_unique<CaseBuffers>(c));
            }
            CullStatusPass status(vk().passes());
            FusedCullPass fused(vk().passes());
            FrustumPass frustum(vk().passes());
            BackpatchConePass cones(vk().passes());
            OcclusionPass occlusion(vk().passes());
            bool reversed = false;
            vk_pyramid(vk(), depths, w, h, depth, &reversed, [&](VkCommandBuffer cmd, const HiZImage& hiz) {
                for (std::uint32_t tests = 1; tests < 8; ++tests) {
                    const PatchBuffers f = fused_buffers[tests - 1]->patch_buffers();
                    const PatchBuffers ch = chain_buffers[tests - 1]->patch_buffers();
                    status.begin(cmd, f);
                    fused.run(cmd, f, tests, m, depth, method, eye, hiz);
                    status.begin(cmd, ch);
                    if (tests & kCullFrustum) frustum.run(cmd, ch, planes);
                    if (tests & kCullBackPatch) cones.run(cmd, ch, method, eye);
                    if (tests & kCullOcclusion) occlusion.run(cmd, ch, m, depth, hiz, false);
                }
            });
            // The CPU kernels, in the chain's order.
            const PatchBatch batch = patch_batch(c.patches);
            std::vector<std::uint8_t> f(c.patches.size()), b(c.patches.size()), o(c.patches.size());
            cull_frustum_scalar(batch.view(), nullptr, planes, f.data());
            if (method == BackpatchMethod::tcone)
                cull_tcone_scalar(batch.view(), eye, b.data());
            else
                cull_ncone_scalar(batch.view(), eye, b.data());
            HiZPyramid pyramid;
            pyramid.build(depths.data(), w, h, depth);
            cull_occlusion_scalar(batch.view(), m, depth, pyramid, o.data());
            for (std::uint32_t tests = 1; tests < 8; ++tests) {
                const std::vector<std::uint32_t> got =
                    fused_buffers[tests - 1]->flags.read<std::uint32_t>(c.patches.size());
                const std::vector<std::uint32_t> chain =
                    chain_buffers[tests - 1]->flags.read<std::uint32_t>(c.patches.size());
                const std::string where = std::string(clip_depth_name(depth)) + " " + backpatch_method_name(method) +
                                          " tests " + std::to_string(tests);
                ASSERT_EQ(got, chain) << where;
                if ((tests & kCullOcclusion) && !(tests & kCullFrustum)) continue;
                for (std::size_t p = 0; p < got.size(); ++p) {
                    std::uint32_t expected = 0;
                    if ((tests & kCullFrustum) && f[p])
                        expected = kCullFrustum;
                    else if ((tests & kCullBackPatch) && b[p])
                        expected = kCullBackPatch;
                    else if ((tests & kCullOcclusion) && o[p] == kHiZOccluded)
                        expected = kCullOcclusion;
                    ASSERT_EQ(got[p], expected) << where << " patch " << p;
                    if (tests == 7 && expected)
                        ++culled[expected == kCullFrustum ? 0 : expected == kCullBackPatch ? 1 : 2];
                }
            }
        }
    EXPECT_GT(culled[0], 1000u);
    EXPECT_GT(culled[1], 100u);
    EXPECT_GT(culled[2], 100u);
}
