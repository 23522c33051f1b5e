// The Vulkan displaced pass (patchcull/vk/vk_passes.h's DisplacedPass) on lavapipe with the
// validation layers on: for caf and oobb bounds and the three cones, forward and reversed depth,
// frustum alone and with a pyramid of the Vulkan HiZBuildPass, the flag words equal
// cull_displaced_frustum's and cull_displaced_occlusion's decisions on the same view, ranges and
// pyramid depths (only_displaced off: every patch tested, as the CPU kernels do).
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/displacement.h"
#include "vk/vk_cases.h"
#include "vk/vk_images.h"

using namespace patchcull;
using namespace patchcull::vk;
using namespace patchcull::vk::test;

namespace {

class VkDisplaced : public VkTest {};

}  // namespace

TEST_F(VkDisplaced, FlagWordsEqualCpuKernels) {
    const int w = 96, h = 64;
    struct Run {
        ClipDepth depth;
        DisplacedBoundKind bound;
        NormalConeKind cone;
    };
    // Each convention once, each bound and cone at least once; con only once (its pipeline and its
    // runs cost seconds on lavapipe).
    const Run runs[] = {{ClipDepth::zero_to_one, DisplacedBoundKind::caf, NormalConeKind::acon},
                        {ClipDepth::reversed, DisplacedBoundKind::oobb, NormalConeKind::con},
                        {ClipDepth::minus_one_to_one, DisplacedBoundKind::caf, NormalConeKind::full},
                        {ClipDepth::reversed_infinite, DisplacedBoundKind::oobb, NormalConeKind::acon}};
    std::size_t frustum = 0, occluded = 0, total = 0;
    for (const Run& run : runs) {
        const RandomCase c = random_case(81 + static_cast<std::uint32_t>(run.depth), 1200, run.depth, false);
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> u(0.0f, 0.2f);
        std::vector<DisplacementRange> ranges(c.patches.size());
        for (DisplacementRange& r : ranges) r = {-u(rng), u(rng)};
        const Mat4 m = c.camera.view_projection();
        const DisplacedCullView view = make_displaced_cull_view(c.camera.view(), c.camera.projection(), run.depth);
        const std::vector<float> depths = wall_depths(c, m, run.depth, w, h);
        CaseBuffers frustum_buffers(c), occlusion_buffers(c);
        HostBuffer range_buffer(ranges.size() * sizeof(DisplacementRange));
        range_buffer.write(ranges.data(), ranges.size() * sizeof(DisplacementRange));
        CullStatusPass status(vk().passes());
        DisplacedPass pass(vk().passes());
        bool reversed = false;
        vk_pyramid(vk(), depths, w, h, run.depth, &reversed, [&](VkCommandBuffer cmd, const HiZImage& hiz) {
            status.begin(cmd, frustum_buffers.patch_buffers());
            pass.run(cmd, frustum_buffers.patch_buffers(), range_buffer.range(), run.bound, run.cone, view, hiz, false,
                     false);
            status.begin(cmd, occlusion_buffers.patch_buffers());
            pass.run(cmd, occlusion_buffers.patch_buffers(), range_buffer.range(), run.bound, run.cone, view, hiz, true,
                     false);
        });
        const PatchBatch batch = patch_batch(c.patches);
        std::vector<std::uint8_t> cpu_frustum(c.patches.size()), cpu_occlusion(c.patches.size());
        cull_displaced_frustum(batch.view(), ranges.data(), run.bound, run.cone, view, cpu_frustum.data());
        HiZPyramid pyramid;
        pyramid.build(depths.data(), w, h, run.depth);
        cull_displaced_occlusion(batch.view(), ranges.data(), run.bound, run.cone, view, pyramid, cpu_occlusion.data());
        const std::vector<std::uint32_t> got_frustum = frustum_buffers.flags.read<std::uint32_t>(c.patches.size());
        const std::vector<std::uint32_t> got_occlusion = occlusion_buffers.flags.read<std::uint32_t>(c.patches.size());
        const std::string where = std::string(clip_depth_name(run.depth)) + " " + displaced_bound_name(run.bound) +
                                  " " + normal_cone_name(run.cone);
        for (std::size_t p = 0; p < c.patches.size(); ++p) {
            ASSERT_EQ(got_frustum[p], cpu_frustum[p] ? kCullFrustum : 0u) << where << " frustum, patch " << p;
            const std::uint32_t expected = cpu_occlusion[p] == kHiZFrustumCulled ? kCullFrustum
                                           : cpu_occlusion[p] == kHiZOccluded    ? kCullOcclusion
                                                                                 : 0u;
            ASSERT_EQ(got_occlusion[p], expected) << where << " occlusion, patch " << p;
            frustum += cpu_occlusion[p] == kHiZFrustumCulled;
            occluded += cpu_occlusion[p] == kHiZOccluded;
        }
        total += c.patches.size();
    }
    EXPECT_GT(frustum, total / 10);
    EXPECT_GT(occluded, total / 50);
}
