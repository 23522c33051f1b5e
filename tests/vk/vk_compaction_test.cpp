// The Vulkan compaction pass (patchcull/vk/vk_passes.h's CompactPass) on lavapipe with the
// validation layers on: for every draw selection of shared.h, both methods and several command
// limits K, the list holds exactly the patches the selection keeps (ascending for the scan), the
// commands and the draw count are the header's formulas, entries past the survivors are left as
// they were, and a range of 0 patches writes one empty command.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "shared.h"
#include "vk/vk_test_util.h"

using namespace patchcull;
using namespace patchcull::vk;
using namespace patchcull::vk::test;
namespace shared = patchcull::gl::shared;

namespace {

struct Compacted {
    std::vector<std::uint32_t> list;      // the whole list buffer
    std::vector<std::uint32_t> commands;  // 4 words per command
    std::uint32_t draw_count = 0;
};

Compacted vk_compact(Context& vk, const std::vector<std::uint32_t>& words, std::size_t first, std::size_t count,
                     std::uint32_t mask, std::uint32_t value, std::size_t list_first, std::size_t k,
                     CompactMethod method) {
    HostBuffer flags(std::max<std::size_t>(words.size() * 4, 4));
    flags.write(words.data(), words.size() * 4);
    const std::size_t list_entries = list_first + count + 3;
    HostBuffer list(list_entries * 4);
    const std::vector<std::uint32_t> marker(list_entries, 0xDEADBEEFu);
    list.write(marker.data(), marker.size() * 4);
    const std::size_t commands = compact_command_count(count, k);
    HostBuffer command(commands * 16);
    HostBuffer draw_count(4);
    HostBuffer scratch(compact_scratch_bytes(count, method));
    PatchBuffers patches;
    patches.flags = flags.range();
    patches.first = first;
    patches.count = count;
    DrawListRanges out;
    out.list = list.range();
    out.list_first = list_first;
    out.command = command.range();
    out.draw_count = draw_count.range();
    out.scratch = scratch.range();
    out.patches_per_command = k;
    CompactPass pass(vk.passes());
    vk.submit([&](VkCommandBuffer cmd) { pass.run(cmd, patches, mask, value, out, method); });
    return {list.read<std::uint32_t>(list_entries), command.read<std::uint32_t>(commands * 4),
            draw_count.read<std::uint32_t>(1)[0]};
}

class VkCompaction : public VkTest {};

}  // namespace

TEST_F(VkCompaction, ListCommandsAndCountFollowTheContract) {
    std::mt19937 rng(17);
    // Ranges of 4700 (the scan in one work group: at most kCompactSingleGroupPatches) and 20000
    // patches (its dispatches: 10 work groups of 2048).
    const std::size_t n = 20100;
    std::vector<std::uint32_t> words(n);
    const std::uint32_t kinds[] = {0u,
                                   kCullFrustum,
                                   kCullOcclusion,
                                   kStatusVisible,
                                   kStatusVisible | kStatusNewlyVisible,
                                   kCullBackPatch | kStatusVisible};
    for (std::uint32_t& w : words) w = kinds[rng() % 6];
    struct Selection {
        std::uint32_t mask, value;
    };
    const Selection selections[] = {{shared::kDrawMaskUnculled, shared::kDrawValueUnculled},
                                    {shared::kDrawMaskFirstPass, shared::kDrawValueFirstPass},
                                    {shared::kDrawMaskSecondPass, shared::kDrawValueSecondPass},
                                    {0u, 0u}};
    const std::size_t first = 37, list_first = 11;
    static_assert(shared::kCompactSingleGroupPatches >= 4700 && shared::kCompactSingleGroupPatches < 20000);
    for (const std::size_t count : {std::size_t{4700}, std::size_t{20000}})
        for (const CompactMethod method : {CompactMethod::prefix_scan, CompactMethod::atomic_append})
            for (const Selection& s : selections)
                for (const std::size_t k : {std::size_t{0}, std::size_t{1}, std::size_t{7}, count + 5}) {
                    const Compacted got = vk_compact(vk(), words, first, count, s.mask, s.value, list_first, k, method);
                    std::vector<std::uint32_t> kept;
                    for (std::size_t p = first; p < first + count; ++p)
                        if ((words[p] & s.mask) == s.value) kept.push_back(static_cast<std::uint32_t>(p));
                    const std::size_t survivors = kept.size();
                    std::vector<std::uint32_t> listed(
                        got.list.begin() + static_cast<std::ptrdiff_t>(list_first),
                        got.list.begin() + static_cast<std::ptrdiff_t>(list_first + survivors));
                    if (method == CompactMethod::atomic_append) std::sort(listed.begin(), listed.end());
                    const std::string where = std::string(method == CompactMethod::prefix_scan ? "scan" : "append") +
                                              " count " + std::to_string(count) + " mask " + std::to_string(s.mask) +
                                              " K " + std::to_string(k);
                    ASSERT_EQ(listed, kept) << where;
                    for (std::size_t e = 0; e < got.list.size(); ++e) {
                        if (e < list_first || e >= list_first + survivors) {
                            ASSERT_EQ(got.list[e], 0xDEADBEEFu) << where;
                        }
                    }
                    const std::size_t kk = k == 0 ? count : std::min(k, count);
                    const std::size_t commands = compact_command_count(count, k);
                    for (std::size_t c = 0; c < commands; ++c) {
                        const std::size_t m = survivors > c * kk ? std::min(kk, survivors - c * kk) : 0;
                        EXPECT_EQ(got.commands[4 * c + 0], 16 * m) << where << " command " << c;
                        EXPECT_EQ(got.commands[4 * c + 1], 1u) << where << " command " << c;
                        EXPECT_EQ(got.commands[4 * c + 2], 16 * (list_first + c * kk)) << where << " command " << c;
                        EXPECT_EQ(got.commands[4 * c + 3], 0u) << where << " command " << c;
                    }
                    EXPECT_EQ(got.draw_count, (survivors + kk - 1) / kk) << where;
                }
}

TEST_F(VkCompaction, EmptyRangeWritesOneEmptyCommand) {
    const std::vector<std::uint32_t> words(10, 0u);
    for (const CompactMethod method : {CompactMethod::prefix_scan, CompactMethod::atomic_append}) {
        const Compacted got = vk_compact(vk(), words, 4, 0, 0u, 0u, 5, 0, method);
        EXPECT_EQ(got.commands, (std::vector<std::uint32_t>{0u, 1u, 80u, 0u}));
        EXPECT_EQ(got.draw_count, 0u);
    }
}
