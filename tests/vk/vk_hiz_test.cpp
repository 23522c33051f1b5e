// The Vulkan Hi-Z build pass (patchcull/vk/vk_passes.h's HiZBuildPass) on lavapipe with the
// validation layers on: from a D32_SFLOAT depth image holding the same depths as an array, every
// level's texels equal HiZPyramid::build's bit for bit, for odd and even sizes, in the forward and
// reversed conventions (keys -depth), and the pass sets HiZImage::reversed.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <stdexcept>

#include "patchcull/core/hiz.h"
#include "vk/vk_images.h"

using namespace patchcull;
using namespace patchcull::vk;
using namespace patchcull::vk::test;

namespace {

// Depths with structure (planes at several depths, a gradient) and noise; exact 0 and 1 too.
std::vector<float> test_depths(int w, int h, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<float> d(static_cast<std::size_t>(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float v = (x / 7 + y / 5) % 3 == 0 ? 0.25f + 0.5f * u(rng) : static_cast<float>(x + y) / (w + h);
            if ((x * 31 + y * 17) % 23 == 0) v = 1.0f;
            if ((x * 13 + y * 29) % 19 == 0) v = 0.0f;
            d[static_cast<std::size_t>(y) * w + x] = v;
        }
    return d;
}

class VkHiZ : public VkTest {};

}  // namespace

TEST_F(VkHiZ, PyramidEqualsCpuBuildBitForBit) {
    struct Size {
        int w, h;
    };
    for (const Size s : {Size{37, 23}, Size{64, 48}, Size{1, 5}, Size{200, 3}})
        for (const ClipDepth convention : {ClipDepth::zero_to_one, ClipDepth::reversed}) {
            const std::vector<float> depths = test_depths(s.w, s.h, static_cast<std::uint32_t>(s.w * 100 + s.h));
            bool reversed = false;
            const std::vector<float> gpu = vk_pyramid(vk(), depths, s.w, s.h, convention, &reversed);
            HiZPyramid cpu;
            cpu.build(depths.data(), s.w, s.h, convention);
            EXPECT_EQ(reversed, is_reversed(convention));
            ASSERT_EQ(gpu.size(), cpu.size());
            for (std::size_t i = 0; i < gpu.size(); ++i) {
                std::uint32_t a, b;
                std::memcpy(&a, &gpu[i], 4);
                std::memcpy(&b, &cpu.data()[i], 4);
                ASSERT_EQ(a, b) << s.w << "x" << s.h << " " << clip_depth_name(convention) << " texel " << i
                                << ": Vulkan " << gpu[i] << ", CPU " << cpu.data()[i];
            }
        }
}
