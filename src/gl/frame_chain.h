// The flag chain of one frame (gl_passes.h) run over a SpanPlan's dispatch spans: begin, the
// frame's tests in the chain's order (fused, or frustum, back-patch, occlusion and displaced
// bounds), end with the counts per object. CullPipeline::render_frame's runner; not a public header.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "cull_pipeline_impl.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/gl/gl_span_plan.h"

namespace patchcull::gl {

/// What a frame's tests are, decided once per frame.
struct FrameTests {
    std::uint32_t tests = 0;  ///< kCullFrustum | kCullBackPatch | kCullOcclusion bits to run
    /// The mode has occlusion: the frame is drawn in two passes around a Hi-Z pyramid (even when
    /// no test may run, e.g. displaced without margins).
    bool two_pass = false;
    bool fused = false;        ///< FusedCullPass runs frustum, cone and Hi-Z together
    bool aabb = false;         ///< FrustumDispPass instead of FrustumPass
    PatchBuffers chain;        ///< the renderer's buffers (margins 0 when drawn undisplaced)
    std::uint32_t ranges = 0;  ///< displacement ranges buffer when displacing, else 0
    CullView view;             ///< the frame's view (its eye checked: a singular view is refused)
    BackpatchOptions backpatch_options;
};

class FrameChain {
public:
    FrameChain(CullPipeline::Impl& pipeline, const PipelineParams& params, const FrameTests& frame,
               const SpanPlan& plan, PassClock& clock)
        : m_(pipeline), params_(params), f_(frame), plan_(plan), clock_(clock) {}

    /// The chain on the objects `only` names (every object and every gap when null), against hiz
    /// (null: no Hi-Z test), marking the clock between its three parts (begin + frustum,
    /// back-patch, the rest) when timed.
    void run(const HiZTexture* hiz, const std::vector<std::size_t>* only = nullptr, bool timed = true);
    /// Writes kCullObject (status cleared) into the culled spans' words within [first, end): a
    /// buffer clear after begin's shader writes, no pass.
    void mark_culled(std::size_t first, std::size_t end);
    /// begin / end on the gaps alone (counted in the last counter slot).
    void begin_gaps();
    void end_gaps();
    /// CompactMethod::fused_append: the ends of the next run() append each dispatch span's patches
    /// that (flag & mask) == value keeps to draw pass `pass`'s list (CullPipeline::Impl::
    /// reserve_draw_list), in the order of the plan's drawn spans when the plan has no culled
    /// spans (every dispatch span is then a drawn span). For that one run: run() clears it, and
    /// without it (the default) nothing is appended.
    void append_to(int pass, std::uint32_t mask, std::uint32_t value) {
        append_pass_ = pass;
        append_mask_ = mask;
        append_value_ = value;
    }

private:
    PatchBuffers buffers_of(const PatchSpan& s) const;
    /// CullStatusPass::end on span s, counted in slot `slot`, with the append when asked for.
    void end_span(const PatchSpan& s, std::size_t slot);
    void run_tests(const HiZTexture* hiz, const std::vector<std::size_t>& only, bool timed);

    CullPipeline::Impl& m_;
    const PipelineParams& params_;
    const FrameTests& f_;
    const SpanPlan& plan_;
    PassClock& clock_;
    int append_pass_ = -1;
    std::uint32_t append_mask_ = 0, append_value_ = 0;
};

}  // namespace patchcull::gl
