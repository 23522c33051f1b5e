// kept_runs, clip_to_runs, join_adjacent and displacement_runs (patchcull/core/patch_runs.h): the
// runs a pass that skips displaced or undisplaced patches is dispatched on.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "patchcull/core/patch_runs.h"

namespace patchcull {
namespace {

TEST(KeptRuns, RunsOfKeptPatchesJoinedAcrossShortGaps) {
    //                                     0  1  2  3  4  5  6  7  8  9
    const std::vector<std::uint8_t> keep = {1, 1, 0, 1, 0, 0, 0, 1, 1, 0};
    EXPECT_EQ(kept_runs(keep, 0), (std::vector<PatchSpan>{{0, 2}, {3, 1}, {7, 2}}));
    EXPECT_EQ(kept_runs(keep, 1), (std::vector<PatchSpan>{{0, 2}, {3, 1}, {7, 2}}));
    EXPECT_EQ(kept_runs(keep, 2), (std::vector<PatchSpan>{{0, 4}, {7, 2}}));  // the gap of 1 joined, of 3 not
    EXPECT_EQ(kept_runs(keep, 4), (std::vector<PatchSpan>{{0, 9}}));
    EXPECT_EQ(kept_runs({0, 0, 0}, 8), (std::vector<PatchSpan>{}));
    EXPECT_EQ(kept_runs({}, 8), (std::vector<PatchSpan>{}));
    EXPECT_EQ(kept_runs({1, 1, 1}, 8), (std::vector<PatchSpan>{{0, 3}}));
    // Every kept patch is covered, whatever the pattern and gap.
    std::vector<std::uint8_t> pattern(1000);
    for (std::size_t p = 0; p < pattern.size(); ++p) pattern[p] = (p * 7919 % 13) < 4 || (p / 100) % 3 == 0;
    for (const std::size_t gap : {0u, 3u, 256u}) {
        const std::vector<PatchSpan> runs = kept_runs(pattern, gap);
        std::vector<std::uint8_t> covered(pattern.size(), 0);
        std::size_t end = 0;
        for (const PatchSpan& r : runs) {
            EXPECT_GE(r.first, end);  // ascending, disjoint
            EXPECT_GT(r.count, 0u);
            for (std::size_t p = r.first; p < r.first + r.count; ++p) covered[p] = 1;
            end = r.first + r.count;
        }
        for (std::size_t p = 0; p < pattern.size(); ++p)
            if (pattern[p]) {
                EXPECT_TRUE(covered[p]) << p << " gap " << gap;
            }
        if (gap <= 1) {
            EXPECT_EQ(covered, pattern);
        }
    }
}

TEST(KeptRuns, ClipToRunsKeepsTheSpansPartsInsideTheRuns) {
    const std::vector<PatchSpan> runs = {{2, 3}, {8, 2}, {12, 4}};  // [2, 5), [8, 10), [12, 16)
    auto clipped = [&](PatchSpan s) {
        std::vector<PatchSpan> out = {{99, 1}};  // appended to
        clip_to_runs(s, runs, out);
        out.erase(out.begin());
        return out;
    };
    EXPECT_EQ(clipped({0, 20}), (std::vector<PatchSpan>{{2, 3}, {8, 2}, {12, 4}}));
    EXPECT_EQ(clipped({3, 10}), (std::vector<PatchSpan>{{3, 2}, {8, 2}, {12, 1}}));
    EXPECT_EQ(clipped({5, 3}), (std::vector<PatchSpan>{}));  // between two runs
    EXPECT_EQ(clipped({9, 1}), (std::vector<PatchSpan>{{9, 1}}));
    EXPECT_EQ(clipped({16, 4}), (std::vector<PatchSpan>{}));
    EXPECT_EQ(clipped({4, 0}), (std::vector<PatchSpan>{}));
    std::vector<PatchSpan> none;
    clip_to_runs({0, 10}, {}, none);
    EXPECT_TRUE(none.empty());
}

TEST(KeptRuns, JoinAdjacentSortsAndJoinsTouchingSpans) {
    std::vector<PatchSpan> spans = {{10, 5}, {0, 4}, {4, 2}, {20, 1}, {15, 3}};
    join_adjacent(spans);
    EXPECT_EQ(spans, (std::vector<PatchSpan>{{0, 6}, {10, 8}, {20, 1}}));
    std::vector<PatchSpan> none;
    join_adjacent(none);
    EXPECT_TRUE(none.empty());
}

TEST(KeptRuns, DisplacementRunsFromMarginsAndRanges) {
    const std::size_t n = 1000;
    // No margins, no ranges: every patch undisplaced, none displaced.
    DisplacementRuns none = displacement_runs(n, {}, {});
    EXPECT_EQ(none.undisplaced, (std::vector<PatchSpan>{{0, n}}));
    EXPECT_TRUE(none.displaced.empty());
    EXPECT_TRUE(displacement_runs(0, {}, {}).undisplaced.empty());
    // Displaced (margin > 0, range not (0, 0)) in [300, 600) and at 800: the gaps of 1 and 200
    // are too short to dispatch around.
    std::vector<float> margins(n, 0.0f);
    std::vector<DisplacementRange> ranges(n);
    for (std::size_t p = 300; p < 600; ++p) {
        margins[p] = 0.5f;
        ranges[p] = {-0.25f, 0.5f};
    }
    margins[800] = 0.1f;
    ranges[800] = {0.0f, 0.1f};
    const DisplacementRuns runs = displacement_runs(n, margins, ranges);
    EXPECT_EQ(runs.undisplaced, (std::vector<PatchSpan>{{0, 300}, {600, n - 600}}));
    EXPECT_EQ(runs.displaced, (std::vector<PatchSpan>{{300, 501}}));
    // A NaN margin is not > 0: the pass tests it (and decides for itself).
    margins[100] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(displacement_runs(n, margins, {}).undisplaced, (std::vector<PatchSpan>{{0, 300}, {600, n - 600}}));
    // A range with only d_min is displaced.
    std::vector<DisplacementRange> low(n);
    low[5] = {-0.1f, 0.0f};
    EXPECT_EQ(displacement_runs(n, {}, low).displaced, (std::vector<PatchSpan>{{5, 1}}));
}

}  // namespace
}  // namespace patchcull
