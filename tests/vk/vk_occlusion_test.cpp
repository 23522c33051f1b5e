// The Vulkan occlusion pass (patchcull/vk/vk_passes.h's OcclusionPass) against a pyramid of the
// Vulkan HiZBuildPass, on lavapipe with the validation layers on: the flag words equal
// cull_occlusion_scalar's decisions on the same matrix and the CPU pyramid of the same depths
// (kHiZFrustumCulled -> kCullFrustum, kHiZOccluded -> kCullOcclusion), in every ClipDepth, with
// many patches of each outcome; a pyramid of the other direction is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "patchcull/core/clip_space.h"
#include "patchcull/core/error.h"
#include "vk/vk_cases.h"
#include "vk/vk_images.h"

using namespace patchcull;
using namespace patchcull::vk;
using namespace patchcull::vk::test;

namespace {

class VkOcclusion : public VkTest {};

}  // namespace

TEST_F(VkOcclusion, FlagWordsEqualCpuScalarKernelInEveryConvention) {
    const int w = 96, h = 64;
    std::size_t frustum = 0, occluded = 0, total = 0;
    for (const ClipDepth depth :
         {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one, ClipDepth::reversed, ClipDepth::reversed_infinite})
        for (std::uint32_t seed = 51; seed <= 52; ++seed) {
            const RandomCase c = random_case(seed, 2000, depth, false);
            const Mat4 m = c.camera.view_projection();
            const std::vector<float> depths = wall_depths(c, m, depth, w, h);
            CaseBuffers b(c);
            CullStatusPass status(vk().passes());
            OcclusionPass pass(vk().passes());
            bool reversed = false;
            vk_pyramid(vk(), depths, w, h, depth, &reversed, [&](VkCommandBuffer cmd, const HiZImage& hiz) {
                status.begin(cmd, b.patch_buffers());
                pass.run(cmd, b.patch_buffers(), m, depth, hiz);
            });
            const std::vector<std::uint32_t> gpu = b.flags.read<std::uint32_t>(c.patches.size());
            HiZPyramid pyramid;
            pyramid.build(depths.data(), w, h, depth);
            std::vector<std::uint8_t> cpu(c.patches.size());
            cull_occlusion_scalar(patch_batch(c.patches).view(), m, depth, pyramid, cpu.data());
            for (std::size_t p = 0; p < cpu.size(); ++p) {
                const std::uint32_t expected = cpu[p] == kHiZFrustumCulled ? kCullFrustum
                                               : cpu[p] == kHiZOccluded    ? kCullOcclusion
                                                                           : 0u;
                ASSERT_EQ(gpu[p], expected) << clip_depth_name(depth) << " seed " << seed << " patch " << p;
                frustum += cpu[p] == kHiZFrustumCulled;
                occluded += cpu[p] == kHiZOccluded;
            }
            total += cpu.size();
        }
    EXPECT_GT(occluded, total / 20);
    EXPECT_GT(frustum, total / 10);
    EXPECT_LT(frustum + occluded, total * 9 / 10);
}

TEST_F(VkOcclusion, RefusesAPyramidOfTheOtherDirection) {
    const RandomCase c = random_case(3, 10, ClipDepth::zero_to_one, false);
    CaseBuffers b(c);
    OcclusionPass pass(vk().passes());
    HiZImage hiz;
    // NOLINTNEXTLINE(performance-no-int-to-ptr): a dummy non-null handle, never bound (refused first)
    hiz.all_levels = reinterpret_cast<VkImageView>(std::uintptr_t{1});
    hiz.width = 8;
    hiz.height = 8;
    hiz.reversed = true;
    std::string message;
    try {
        pass.run(VK_NULL_HANDLE, b.patch_buffers(), c.camera.view_projection(), ClipDepth::zero_to_one, hiz);
    } catch (const Error& e) {
        message = e.what();
    }
    EXPECT_EQ(
        message,
        "Vulkan: OcclusionPass: the matrix is declared zero-to-one but the Hi-Z pyramid was built from a reversed "
        "depth buffer (HiZBuildPass::run's convention)");
}
