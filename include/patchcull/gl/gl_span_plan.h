// patchcull/gl/gl_span_plan.h: which ranges of the patch set a frame dispatches its cull passes on
// and draws (CullPipeline::render_frame's plan). Plain CPU code, no GL: tests call it directly.
#pragma once

#include <cstddef>
#include <vector>

#include "patchcull/gl/gl_cull_flags.h"
#include "patchcull/gl/gl_pipeline.h"

namespace patchcull::gl {

/// A frame's spans over a set of patch_count patches.
struct SpanPlan {
    std::size_t patch_count = 0;
    /// The objects (PipelineParams::objects, or one culled object of every patch when empty) and
    /// the gaps between them (drawn unculled, never tested), both in object order / ascending.
    std::vector<ObjectRange> objects;
    std::vector<ObjectRange> gaps;
    /// Object-culled spans (PipelineParams::object_culled plus any the object pass adds),
    /// ascending, disjoint.
    std::vector<PatchSpan> culled;
    /// Per object (per gap): the spans the passes run on: the whole range, or none when every
    /// patch of it is object-culled. Culled words inside a dispatched range are pre-marked
    /// kCullObject, so every pass skips them.
    std::vector<std::vector<PatchSpan>> object_spans, gap_spans;
    /// The spans the draws issue: every patch outside the culled spans (drawn), and of those the
    /// ones in gaps (gaps_drawn).
    std::vector<PatchSpan> drawn, gaps_drawn;

    /// The parts of object o's range outside every culled span, ascending.
    std::vector<PatchSpan> active_spans(const ObjectRange& o) const;
    /// Adds object-culled spans (disjoint from the culled ones) and plans the spans again.
    void add_culled(const std::vector<PatchSpan>& spans);
};

/// Plans a frame. Throws Error ("render_frame: ...") when an object or a culled span leaves the
/// set, or objects (culled spans) overlap.
SpanPlan plan_spans(std::size_t patch_count, const std::vector<ObjectRange>& objects,
                    const std::vector<PatchSpan>& object_culled);

}  // namespace patchcull::gl
