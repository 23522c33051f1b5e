// The Vulkan frustum pass and the ends of the flag chain (patchcull/vk/vk_passes.h) on lavapipe,
// with the validation layers on (VkTest fails a test on any message): the flag words equal the
// CPU scalar kernel's word for word in every ClipDepth convention, the six plane maxima equal its
// arithmetic bit for bit, a Vulkan y-down projection changes nothing, and the chain's rules
// (begin keeps statuses, a culled patch is skipped, end makes statuses and counts) hold.
#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <string>

#include "patchcull/core/clip_space.h"
#include "patchcull/core/error.h"
#include "shared.h"
#include "vk/vk_cases.h"

using namespace patchcull;
using namespace patchcull::vk;
using namespace patchcull::vk::test;
namespace shared = patchcull::gl::shared;

namespace {

constexpr ClipDepth kConventions[] = {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one, ClipDepth::reversed,
                                      ClipDepth::reversed_infinite};

std::uint32_t bits(float f) {
    std::uint32_t b;
    std::memcpy(&b, &f, 4);
    return b;
}

// cull_frustum_scalar's per-plane maxima (frustum_plane_values / add_frustum_margins).
std::vector<float> cpu_plane_values(const RandomCase& c, const FrustumPlanes& planes) {
    std::vector<float> out(6 * c.patches.size(), -std::numeric_limits<float>::infinity());
    for (std::size_t p = 0; p < c.patches.size(); ++p)
        for (const Vec4& P : c.patches[p].cp) {
            float v[6];
            frustum_plane_values(planes, P.x, P.y, P.z, P.w, v);
            if (!c.margins.empty()) add_frustum_margins(planes, c.margins[p], P.w, v);
            for (int q = 0; q < 6; ++q) out[6 * p + q] = out[6 * p + q] > v[q] ? out[6 * p + q] : v[q];
        }
    return out;
}

// begin -> FrustumPass on the case's buffers; the flag words and the plane maxima.
std::vector<std::uint32_t> vk_frustum_words(Context& vk, const RandomCase& c, const FrustumPlanes& planes,
                                            std::vector<float>* plane_values = nullptr) {
    CaseBuffers b(c);
    HostBuffer values(c.patches.size() * 6 * sizeof(float));
    CullStatusPass status(vk.passes());
    FrustumPass frustum(vk.passes());
    vk.submit([&](VkCommandBuffer cmd) {
        status.begin(cmd, b.patch_buffers());
        frustum.run(cmd, b.patch_buffers(), planes, plane_values ? values.range() : BufferRange{});
    });
    if (plane_values) *plane_values = values.read<float>(c.patches.size() * 6);
    return b.flags.read<std::uint32_t>(c.patches.size());
}

class VkFrustum : public VkTest {};

}  // namespace

TEST_F(VkFrustum, FlagWordsEqualCpuScalarKernelInEveryConvention) {
    std::size_t culled = 0, total = 0;
    for (const ClipDepth depth : kConventions)
        for (std::uint32_t seed = 1; seed <= 4; ++seed) {
            const RandomCase c = random_case(seed, 1500, depth, seed % 2 == 0);
            const FrustumPlanes planes = make_frustum_planes(c.camera.view_projection(), depth);
            std::vector<float> values;
            const std::vector<std::uint32_t> gpu = vk_frustum_words(vk(), c, planes, &values);
            const std::vector<std::uint32_t> cpu = cpu_frustum_words(c, planes);
            ASSERT_EQ(gpu.size(), cpu.size());
            for (std::size_t p = 0; p < cpu.size(); ++p) {
                ASSERT_EQ(gpu[p], cpu[p]) << clip_depth_name(depth) << " seed " << seed << " patch " << p;
                culled += cpu[p] != 0;
            }
            total += cpu.size();
            const std::vector<float> expected = cpu_plane_values(c, planes);
            for (std::size_t i = 0; i < expected.size(); ++i)
                ASSERT_EQ(bits(values[i]), bits(expected[i]))
                    << clip_depth_name(depth) << " seed " << seed << " patch " << i / 6 << " plane " << i % 6
                    << ": Vulkan " << values[i] << ", CPU " << expected[i];
        }
    // Both outcomes are well represented.
    EXPECT_GT(culled, total / 10);
    EXPECT_LT(culled, total * 9 / 10);
}

TEST_F(VkFrustum, YDownProjectionMakesTheSameDecisions) {
    // Vulkan's clip space has y pointing down: an engine negates the projection's y row (or draws
    // with a negative viewport height). The same camera gives the same words either way.
    for (const ClipDepth depth : {ClipDepth::zero_to_one, ClipDepth::reversed}) {
        const RandomCase c = random_case(11, 2000, depth, true);
        Mat4 flip;
        flip.at(1, 1) = -1.0f;
        const Mat4 projection = c.camera.projection();
        const FrustumPlanes up = make_frustum_planes(projection * c.camera.view(), depth);
        const FrustumPlanes down = make_frustum_planes((flip * projection) * c.camera.view(), depth);
        const std::vector<std::uint32_t> gpu_up = vk_frustum_words(vk(), c, up);
        const std::vector<std::uint32_t> gpu_down = vk_frustum_words(vk(), c, down);
        EXPECT_EQ(gpu_down, cpu_frustum_words(c, down)) << clip_depth_name(depth);
        EXPECT_EQ(gpu_down, gpu_up) << clip_depth_name(depth);
    }
}

TEST_F(VkFrustum, ChainSkipsCulledPatchesAndEndMakesStatusesAndCounts) {
    const RandomCase c = random_case(5, 3000, ClipDepth::zero_to_one, true);
    const FrustumPlanes planes = make_frustum_planes(c.camera.view_projection(), ClipDepth::zero_to_one);
    const std::vector<std::uint32_t> frustum_words = cpu_frustum_words(c, planes);
    // Last frame's words: statuses of every kind, and reasons an earlier pass of this frame set
    // on a third (the pass runs without begin, so they stand as culled by that pass).
    std::vector<std::uint32_t> words(c.patches.size());
    for (std::size_t p = 0; p < words.size(); ++p) {
        const std::uint32_t status = p % 4 == 0   ? 0u
                                     : p % 4 == 1 ? kStatusVisible
                                                  : kStatusVisible | kStatusNewlyVisible;
        words[p] = status | (p % 3 == 0 ? kCullOcclusion : 0u);
    }
    CaseBuffers b(c);
    b.flags.write(words.data(), words.size() * 4);
    HostBuffer counters(shared::kCounterCount * 4);
    const std::uint32_t preset[shared::kCounterCount] = {7, 0, 0, 0, 0, 0, 0, 0};
    counters.write(preset, sizeof preset);
    CullStatusPass status(vk().passes());
    FrustumPass frustum(vk().passes());
    vk().submit([&](VkCommandBuffer cmd) {
        frustum.run(cmd, b.patch_buffers(), planes);
        status.end(cmd, b.patch_buffers(), counters.range());
    });
    const std::vector<std::uint32_t> gpu = b.flags.read<std::uint32_t>(words.size());
    std::uint32_t expected_counts[shared::kCounterCount] = {7, 0, 0, 0, 0, 0, 0, 0};
    for (std::size_t p = 0; p < words.size(); ++p) {
        std::uint32_t reason = words[p] & kCullReasonMask;
        if (reason == 0) reason = frustum_words[p];
        const bool was_visible = (words[p] & kStatusVisible) != 0;
        const std::uint32_t expected = reason != 0 ? reason : kStatusVisible | (was_visible ? 0u : kStatusNewlyVisible);
        ASSERT_EQ(gpu[p], expected) << "patch " << p;
        expected_counts[shared::kCounterWasVisible] += was_visible;
        expected_counts[shared::kCounterFrustum] += reason == kCullFrustum;
        expected_counts[shared::kCounterOcclusion] += reason == kCullOcclusion;
        expected_counts[shared::kCounterDisplacedOcclusion] += reason == kCullOcclusion && c.margins[p] > 0.0f;
        expected_counts[shared::kCounterVisible] += reason == 0;
        expected_counts[shared::kCounterNewlyVisible] += reason == 0 && !was_visible;
    }
    const std::vector<std::uint32_t> got = counters.read<std::uint32_t>(shared::kCounterCount);
    for (std::uint32_t i = 0; i < shared::kCounterCount; ++i) EXPECT_EQ(got[i], expected_counts[i]) << "counter " << i;
    EXPECT_GT(expected_counts[shared::kCounterFrustum], 100u);

    // begin clears the reasons and keeps the statuses.
    vk().submit([&](VkCommandBuffer cmd) { status.begin(cmd, b.patch_buffers()); });
    const std::vector<std::uint32_t> begun = b.flags.read<std::uint32_t>(words.size());
    for (std::size_t p = 0; p < words.size(); ++p) ASSERT_EQ(begun[p], gpu[p] & ~kCullReasonMask) << "patch " << p;
}

TEST_F(VkFrustum, SubRangeLeavesTheRestAlone) {
    const RandomCase c = random_case(3, 1000, ClipDepth::reversed, false);
    const FrustumPlanes planes = make_frustum_planes(c.camera.view_projection(), ClipDepth::reversed);
    const std::vector<std::uint32_t> cpu = cpu_frustum_words(c, planes);
    CaseBuffers b(c);
    const std::vector<std::uint32_t> marker(c.patches.size(), kStatusNewlyVisible);
    b.flags.write(marker.data(), marker.size() * 4);
    PatchBuffers range = b.patch_buffers();
    range.first = 123;
    range.count = 700;
    FrustumPass frustum(vk().passes());
    vk().submit([&](VkCommandBuffer cmd) { frustum.run(cmd, range, planes); });
    const std::vector<std::uint32_t> gpu = b.flags.read<std::uint32_t>(c.patches.size());
    for (std::size_t p = 0; p < gpu.size(); ++p) {
        const bool inside = p >= range.first && p < range.first + range.count;
        ASSERT_EQ(gpu[p], kStatusNewlyVisible | (inside ? cpu[p] : 0u)) << "patch " << p;
    }
}

TEST_F(VkFrustum, RefusesRangesThatAreTooSmallOrMissing) {
    const RandomCase c = random_case(1, 10, ClipDepth::zero_to_one, false);
    CaseBuffers b(c);
    const FrustumPlanes planes = make_frustum_planes(c.camera.view_projection(), ClipDepth::zero_to_one);
    FrustumPass frustum(vk().passes());
    CullStatusPass status(vk().passes());
    PatchBuffers too_many = b.patch_buffers();
    too_many.count = 11;
    std::string message;
    vk().submit([&](VkCommandBuffer cmd) {
        try {
            frustum.run(cmd, too_many, planes);
        } catch (const Error& e) {
            message = e.what();
        }
    });
    EXPECT_EQ(message, "Vulkan: FrustumPass: the control-point range holds 2560 bytes, 2816 needed");
    PatchBuffers no_flags = b.patch_buffers();
    no_flags.flags = {};
    message.clear();
    vk().submit([&](VkCommandBuffer cmd) {
        try {
            status.begin(cmd, no_flags);
        } catch (const Error& e) {
            message = e.what();
        }
    });
    EXPECT_EQ(message, "Vulkan: CullStatusPass: the flag range has no buffer");
}

TEST_F(VkFrustum, LargeRangesAreSplitIntoDispatchesOfAtMost65535Groups) {
    // 65535 work groups of 64 patches cover 4,194,240 patches: CullStatusPass::end over 4.3M
    // (flags only, 17 MB) runs two dispatches, the second from first_patch 4,194,240 + first.
    const std::size_t n = 4300000, first = 3;
    std::vector<std::uint32_t> words(n);
    for (std::size_t p = 0; p < n; ++p)
        words[p] = (p % 3 == 0 ? kStatusVisible : 0u) | (p % 7 == 0 ? kCullFrustum : 0u);
    HostBuffer flags(n * 4), counters(shared::kCounterCount * 4);
    flags.write(words.data(), n * 4);
    PatchBuffers b;
    b.flags = flags.range();
    b.first = first;
    b.count = n - first;
    CullStatusPass status(vk().passes());
    vk().submit([&](VkCommandBuffer cmd) { status.end(cmd, b, counters.range()); });
    const std::vector<std::uint32_t> got = flags.read<std::uint32_t>(n);
    std::uint32_t visible = 0;
    for (std::size_t p = 0; p < n; ++p) {
        std::uint32_t expected = words[p];
        if (p >= first) {
            const std::uint32_t reason = words[p] & kCullReasonMask;
            const bool was_visible = (words[p] & kStatusVisible) != 0;
            expected = reason != 0 ? reason : kStatusVisible | (was_visible ? 0u : kStatusNewlyVisible);
            visible += reason == 0;
        }
        ASSERT_EQ(got[p], expected) << "patch " << p;
    }
    EXPECT_EQ(counters.read<std::uint32_t>(shared::kCounterCount)[shared::kCounterVisible], visible);
}
