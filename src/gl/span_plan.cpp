// plan_spans (patchcull/gl/gl_span_plan.h): a frame's dispatch and draw spans.
#include <algorithm>
#include <string>

#include "patchcull/core/error.h"
#include "patchcull/gl/gl_span_plan.h"

namespace patchcull::gl {
namespace {

bool by_first(const PatchSpan& a, const PatchSpan& b) { return a.first < b.first; }

void plan_dispatch_and_draws(SpanPlan& plan) {
    plan.object_spans.clear();
    plan.gap_spans.clear();
    plan.drawn.clear();
    plan.gaps_drawn.clear();
    auto dispatch_spans = [&plan](const ObjectRange& o, std::vector<PatchSpan>* also_drawn) {
        const std::vector<PatchSpan> active = plan.active_spans(o);
        plan.drawn.insert(plan.drawn.end(), active.begin(), active.end());
        if (also_drawn) also_drawn->insert(also_drawn->end(), active.begin(), active.end());
        if (active.empty()) return std::vector<PatchSpan>{};
        return std::vector<PatchSpan>{{o.first, o.count}};
    };
    for (const ObjectRange& o : plan.objects) plan.object_spans.push_back(dispatch_spans(o, nullptr));
    for (const ObjectRange& g : plan.gaps) plan.gap_spans.push_back(dispatch_spans(g, &plan.gaps_drawn));
}

}  // namespace

std::vector<PatchSpan> SpanPlan::active_spans(const ObjectRange& o) const {
    std::vector<PatchSpan> out;
    std::size_t at = o.first;
    const std::size_t end = o.first + o.count;
    for (const PatchSpan& s : culled) {
        if (s.first + s.count <= at) continue;
        if (s.first >= end) break;
        if (s.first > at) out.push_back({at, s.first - at});
        at = std::max(at, s.first + s.count);
    }
    if (at < end) out.push_back({at, end - at});
    return out;
}

void SpanPlan::add_culled(const std::vector<PatchSpan>& spans) {
    culled.insert(culled.end(), spans.begin(), spans.end());
    std::sort(culled.begin(), culled.end(), by_first);
    plan_dispatch_and_draws(*this);
}

SpanPlan plan_spans(std::size_t count, const std::vector<ObjectRange>& objects,
                    const std::vector<PatchSpan>& object_culled) {
    SpanPlan plan;
    plan.patch_count = count;
    plan.objects = objects;
    if (plan.objects.empty()) plan.objects.push_back({0, count, true});
    std::vector<ObjectRange> sorted = plan.objects;
    std::sort(sorted.begin(), sorted.end(),
              [](const ObjectRange& a, const ObjectRange& b) { return a.first < b.first; });
    std::size_t covered = 0;
    for (const ObjectRange& o : sorted) {
        if (o.first > count || o.count > count - o.first)
            throw Error("render_frame: object [" + std::to_string(o.first) + ", +" + std::to_string(o.count) +
                        ") leaves the set of " + std::to_string(count) + " patches");
        if (o.first < covered) throw Error("render_frame: objects overlap at patch " + std::to_string(o.first));
        if (o.first > covered) plan.gaps.push_back({covered, o.first - covered, false});
        covered = o.first + o.count;
    }
    if (covered < count) plan.gaps.push_back({covered, count - covered, false});
    plan.culled = object_culled;
    std::sort(plan.culled.begin(), plan.culled.end(), by_first);
    std::size_t culled_end = 0;
    for (const PatchSpan& s : plan.culled) {
        if (s.first > count || s.count > count - s.first)
            throw Error("render_frame: object-culled span [" + std::to_string(s.first) + ", +" +
                        std::to_string(s.count) + ") leaves the set of " + std::to_string(count) + " patches");
        if (s.first < culled_end)
            throw Error("render_frame: object-culled spans overlap at patch " + std::to_string(s.first));
        culled_end = s.first + s.count;
    }
    plan_dispatch_and_draws(plan);
    return plan;
}

}  // namespace patchcull::gl
