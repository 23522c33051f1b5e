// plan_spans (gl/gl_span_plan.h) on the CPU, no GL context: the dispatch and draw spans of a
// frame with objects, gaps and object-culled spans, and the refusals.
#include <gtest/gtest.h>

#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/gl/gl_span_plan.h"

namespace patchcull::gl {
namespace {

TEST(SpanPlan, NoObjectsIsOneObjectOfEveryPatch) {
    const SpanPlan plan = plan_spans(10, {}, {});
    ASSERT_EQ(plan.objects.size(), 1u);
    EXPECT_EQ(plan.objects[0].count, 10u);
    EXPECT_TRUE(plan.gaps.empty());
    EXPECT_EQ(plan.object_spans[0], (std::vector<PatchSpan>{{0, 10}}));
    EXPECT_EQ(plan.drawn, (std::vector<PatchSpan>{{0, 10}}));
}

TEST(SpanPlan, GapsAreDrawnAndObjectCulledSpansAreNot) {
    // Objects [2, 6) and [8, 10) of 12 patches (given out of order); patches 3-4 and all of the
    // second object culled at the object level.
    const SpanPlan plan = plan_spans(12, {{8, 2, true}, {2, 4, true}}, {{8, 2}, {3, 2}});
    ASSERT_EQ(plan.gaps.size(), 3u);  // [0, 2), [6, 8), [10, 12)
    EXPECT_EQ(plan.gaps[1].first, 6u);
    EXPECT_EQ(plan.object_spans[0], (std::vector<PatchSpan>{}));        // culled whole: no dispatch
    EXPECT_EQ(plan.object_spans[1], (std::vector<PatchSpan>{{2, 4}}));  // dispatched whole, 3-4 pre-marked
    EXPECT_EQ(plan.active_spans(plan.objects[1]), (std::vector<PatchSpan>{{2, 1}, {5, 1}}));
    EXPECT_EQ(plan.gaps_drawn, (std::vector<PatchSpan>{{0, 2}, {6, 2}, {10, 2}}));
    EXPECT_EQ(plan.drawn, (std::vector<PatchSpan>{{2, 1}, {5, 1}, {0, 2}, {6, 2}, {10, 2}}));
}

TEST(SpanPlan, AddCulledPlansAgain) {
    SpanPlan plan = plan_spans(8, {{0, 4, true}, {4, 4, true}}, {});
    plan.add_culled({{4, 4}});
    EXPECT_EQ(plan.object_spans[1], (std::vector<PatchSpan>{}));
    EXPECT_EQ(plan.drawn, (std::vector<PatchSpan>{{0, 4}}));
}

TEST(SpanPlan, RefusesRangesOutsideTheSetAndOverlaps) {
    EXPECT_THROW(plan_spans(4, {{2, 3, true}}, {}), Error);
    EXPECT_THROW(plan_spans(4, {{0, 2, true}, {1, 2, true}}, {}), Error);
    EXPECT_THROW(plan_spans(4, {}, {{3, 2}}), Error);
    EXPECT_THROW(plan_spans(4, {}, {{0, 2}, {1, 1}}), Error);
}

}  // namespace
}  // namespace patchcull::gl
