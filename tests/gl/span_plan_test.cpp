// plan_spans (gl/gl_span_plan.h) on the CPU, no GL context: the dispatch and draw spans of a
// frame with objects, gaps and object-culled spans, and the refusals; kept_runs and clip_to_runs.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/gl/gl_span_plan.h"

namespace patchcull::gl {
namespace {

bool same(const std::vector<PatchSpan>& a, const std::vector<PatchSpan>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (a[i].first != b[i].first || a[i].count != b[i].count) return false;
    return true;
}

TEST(SpanPlan, NoObjectsIsOneObjectOfEveryPatch) {
    const SpanPlan plan = plan_spans(10, {}, {});
    ASSERT_EQ(plan.objects.size(), 1u);
    EXPECT_EQ(plan.objects[0].count, 10u);
    EXPECT_TRUE(plan.gaps.empty());
    EXPECT_TRUE(same(plan.object_spans[0], {{0, 10}}));
    EXPECT_TRUE(same(plan.drawn, {{0, 10}}));
}

TEST(SpanPlan, GapsAreDrawnAndObjectCulledSpansAreNot) {
    // Objects [2, 6) and [8, 10) of 12 patches (given out of order); patches 3-4 and all of the
    // second object culled at the object level.
    const SpanPlan plan = plan_spans(12, {{8, 2, true}, {2, 4, true}}, {{8, 2}, {3, 2}});
    ASSERT_EQ(plan.gaps.size(), 3u);  // [0, 2), [6, 8), [10, 12)
    EXPECT_EQ(plan.gaps[1].first, 6u);
    EXPECT_TRUE(same(plan.object_spans[0], {}));        // culled whole: no dispatch
    EXPECT_TRUE(same(plan.object_spans[1], {{2, 4}}));  // dispatched whole, 3-4 pre-marked
    EXPECT_TRUE(same(plan.active_spans(plan.objects[1]), {{2, 1}, {5, 1}}));
    EXPECT_TRUE(same(plan.gaps_drawn, {{0, 2}, {6, 2}, {10, 2}}));
    EXPECT_TRUE(same(plan.drawn, {{2, 1}, {5, 1}, {0, 2}, {6, 2}, {10, 2}}));
}

TEST(SpanPlan, AddCulledPlansAgain) {
    SpanPlan plan = plan_spans(8, {{0, 4, true}, {4, 4, true}}, {});
    plan.add_culled({{4, 4}});
    EXPECT_TRUE(same(plan.object_spans[1], {}));
    EXPECT_TRUE(same(plan.drawn, {{0, 4}}));
}

TEST(SpanPlan, RefusesRangesOutsideTheSetAndOverlaps) {
    EXPECT_THROW(plan_spans(4, {{2, 3, true}}, {}), Error);
    EXPECT_THROW(plan_spans(4, {{0, 2, true}, {1, 2, true}}, {}), Error);
    EXPECT_THROW(plan_spans(4, {}, {{3, 2}}), Error);
    EXPECT_THROW(plan_spans(4, {}, {{0, 2}, {1, 1}}), Error);
}

TEST(KeptRuns, RunsOfKeptPatchesJoinedAcrossShortGaps) {
    //                                     0  1  2  3  4  5  6  7  8  9
    const std::vector<std::uint8_t> keep = {1, 1, 0, 1, 0, 0, 0, 1, 1, 0};
    EXPECT_TRUE(same(kept_runs(keep, 0), {{0, 2}, {3, 1}, {7, 2}}));
    EXPECT_TRUE(same(kept_runs(keep, 1), {{0, 2}, {3, 1}, {7, 2}}));
    EXPECT_TRUE(same(kept_runs(keep, 2), {{0, 4}, {7, 2}}));  // the gap of 1 joined, of 3 not
    EXPECT_TRUE(same(kept_runs(keep, 4), {{0, 9}}));
    EXPECT_TRUE(same(kept_runs({0, 0, 0}, 8), {}));
    EXPECT_TRUE(same(kept_runs({}, 8), {}));
    EXPECT_TRUE(same(kept_runs({1, 1, 1}, 8), {{0, 3}}));
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
    EXPECT_TRUE(same(clipped({0, 20}), {{2, 3}, {8, 2}, {12, 4}}));
    EXPECT_TRUE(same(clipped({3, 10}), {{3, 2}, {8, 2}, {12, 1}}));
    EXPECT_TRUE(same(clipped({5, 3}), {}));  // between two runs
    EXPECT_TRUE(same(clipped({9, 1}), {{9, 1}}));
    EXPECT_TRUE(same(clipped({16, 4}), {}));
    EXPECT_TRUE(same(clipped({4, 0}), {}));
    std::vector<PatchSpan> none;
    clip_to_runs({0, 10}, {}, none);
    EXPECT_TRUE(none.empty());
}

}  // namespace
}  // namespace patchcull::gl
