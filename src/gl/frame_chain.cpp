// FrameChain (frame_chain.h): one frame's flag chain over its dispatch spans.
#include "frame_chain.h"

namespace patchcull::gl {

PatchBuffers FrameChain::buffers_of(const PatchSpan& s) const {
    PatchBuffers b = f_.chain;
    b.first = s.first;
    b.count = s.count;
    return b;
}

void FrameChain::end_span(const PatchSpan& s, std::size_t slot) {
    if (append_pass_ < 0) {
        m_.status.end(buffers_of(s), m_.counters, slot * m_.counter_stride);
        return;
    }
    const DrawListBuffers out = m_.reserve_draw_list(append_pass_, s, plan_);
    m_.status.end(buffers_of(s), m_.counters, slot * m_.counter_stride, out, append_mask_, append_value_);
}

void FrameChain::mark_culled(std::size_t first, std::size_t end) {
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    const std::uint32_t object_word = sh::kCullObject;
    for (const PatchSpan& s : plan_.culled) {
        const std::size_t a = std::max(s.first, first), b = std::min(s.first + s.count, end);
        if (a < b)
            glClearNamedBufferSubData(m_.renderer.flag_buffer(), GL_R32UI,
                                      static_cast<GLintptr>(a * sizeof(std::uint32_t)),
                                      static_cast<GLsizeiptr>((b - a) * sizeof(std::uint32_t)), GL_RED_INTEGER,
                                      GL_UNSIGNED_INT, &object_word);
    }
}

void FrameChain::begin_gaps() {
    for (const std::vector<PatchSpan>& spans : plan_.gap_spans)
        for (const PatchSpan& s : spans) m_.status.begin(buffers_of(s));
}

void FrameChain::end_gaps() {
    for (const std::vector<PatchSpan>& spans : plan_.gap_spans)
        for (const PatchSpan& s : spans) end_span(s, plan_.objects.size());
}

void FrameChain::run(const HiZTexture* hiz, const std::vector<std::size_t>* only, bool timed) {
    std::vector<std::size_t> all_objects;
    if (!only) {
        for (std::size_t i = 0; i < plan_.objects.size(); ++i) all_objects.push_back(i);
        only = &all_objects;
    }
    const bool with_gaps = only == &all_objects;
    for (std::size_t i : *only)
        for (const PatchSpan& s : plan_.object_spans[i]) m_.status.begin(buffers_of(s));
    if (with_gaps) begin_gaps();
    if (with_gaps) {
        if (!plan_.culled.empty()) mark_culled(0, plan_.patch_count);
    } else {
        for (std::size_t i : *only)
            mark_culled(plan_.objects[i].first, plan_.objects[i].first + plan_.objects[i].count);
    }
    run_tests(hiz, *only, timed);
    for (std::size_t i : *only)
        for (const PatchSpan& s : plan_.object_spans[i]) end_span(s, i);
    if (with_gaps) end_gaps();
    append_pass_ = -1;  // append_to holds for one run
    if (timed) clock_.mark();
}

void FrameChain::run_tests(const HiZTexture* hiz, const std::vector<std::size_t>& only, bool timed) {
    const std::uint32_t tests = f_.tests;
    // The tested objects' spans, ascending, adjacent ones joined: the tests are per patch, so a
    // dispatch may cross objects (CullStatusPass::end still counts each object apart).
    std::vector<PatchSpan> spans;
    for (std::size_t i : only)
        if (plan_.objects[i].cull)  // ObjectRange::cull
            spans.insert(spans.end(), plan_.object_spans[i].begin(), plan_.object_spans[i].end());
    join_adjacent(spans);
    if (f_.fused) {
        // One dispatch per span for all three tests; its time counts as the first part.
        const std::uint32_t fused_tests =
            (tests & (sh::kCullFrustum | sh::kCullBackPatch)) | (hiz ? (tests & sh::kCullOcclusion) : 0u);
        for (const PatchSpan& s : spans) m_.fused.run(buffers_of(s), fused_tests, f_.view, params_.backpatch, hiz);
    }
    if (!f_.fused && (tests & sh::kCullFrustum))
        for (const PatchSpan& s : spans) {
            if (f_.aabb)
                m_.frustum_disp.run(buffers_of(s), f_.view);
            else
                m_.frustum.run(buffers_of(s), f_.view);
        }
    if (timed) clock_.mark();
    // The back-patch, Hi-Z and displaced-bound passes skip some patches (displaced or not): they
    // run on the parts of a span that hold the others (PatchRenderer::undisplaced_runs), since
    // llvmpipe spends as long on a patch a pass returns from at once as on one it tests.
    std::vector<PatchSpan> pieces;
    auto for_each_piece = [&](const PatchSpan& s, const std::vector<PatchSpan>* runs, auto&& run) {
        if (!runs) return run(s);
        pieces.clear();
        clip_to_runs(s, *runs, pieces);
        for (const PatchSpan& piece : pieces) run(piece);
    };
    // Without margins (drawn undisplaced) every patch is tested as undisplaced.
    const std::vector<PatchSpan>* undisplaced = f_.chain.margins ? &m_.renderer.undisplaced_runs() : nullptr;
    if (!f_.fused && (tests & sh::kCullBackPatch))
        for (const PatchSpan& s : spans)
            for_each_piece(s, undisplaced, [&](const PatchSpan& piece) {
                m_.backpatch_pass(params_.backpatch).run(buffers_of(piece), f_.view, f_.backpatch_options);
            });
    if (timed) clock_.mark();
    // The frustum pass ran first when the mode has it: the occlusion pass only tests Hi-Z.
    const HiZTexture* occluding = (tests & sh::kCullOcclusion) ? hiz : nullptr;
    // The displaced pass runs when either test is asked for, with the bound's frustum test too (a
    // bound outside the frustum is invisible), against the pyramid when occluding. With the aabb
    // frustum test the box (grown by max |D|) already tested the displaced patches against the
    // frustum: the bound is built only for the Hi-Z test.
    const bool bounds =
        f_.ranges && (f_.aabb ? occluding != nullptr : (tests & (sh::kCullFrustum | sh::kCullOcclusion)) != 0);
    const DisplacedCullView displaced_view = bounds ? make_displaced_cull_view(f_.view) : DisplacedCullView{};
    for (const PatchSpan& s : spans) {
        if (occluding && !f_.fused)
            for_each_piece(s, undisplaced, [&](const PatchSpan& piece) {
                m_.occlusion.run(buffers_of(piece), f_.view, *occluding, false);
            });
        if (bounds)
            for_each_piece(s, &m_.renderer.displaced_runs(), [&](const PatchSpan& piece) {
                m_.displaced.run(buffers_of(piece), f_.ranges, params_.bound, params_.cone, displaced_view, occluding,
                                 true);
            });
    }
}

}  // namespace patchcull::gl
