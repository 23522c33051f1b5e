// Internals of CullPipeline (patchcull/gl/gl_pipeline.h) shared by its sources: the passes and
// buffers a pipeline owns (cull_pipeline.cpp) and the clock that times a frame's parts, used by
// the flag chain's runner (frame_chain.cpp). Not a public header.
#pragma once

#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <memory>
#include <vector>

#include "patchcull/gl/gl_backpatch_passes.h"
#include "patchcull/gl/gl_compaction.h"
#include "patchcull/gl/gl_pipeline.h"
#include "renderer_internal.h"

namespace patchcull::gl {

struct SpanPlan;
struct FrameTests;

// Marks pass boundaries: GL_TIMESTAMP queries, or steady_clock after glFinish().
class PassClock {
public:
    static constexpr int kMaxMarks = 8;
    PassClock(TimingMethod method, GLuint* queries) : method_(method), queries_(queries) {
        if (method_ == TimingMethod::timer_query && !queries_[0]) glCreateQueries(GL_TIMESTAMP, kMaxMarks, queries_);
    }
    void mark() {
        if (method_ == TimingMethod::wall_clock) {
            glFinish();
            wall_[marks_] = std::chrono::steady_clock::now();
        } else if (method_ == TimingMethod::timer_query) {
            glQueryCounter(queries_[marks_], GL_TIMESTAMP);
        }
        ++marks_;
    }
    // Milliseconds between mark i and mark i + 1 (waits for query results); 0 when not timed.
    std::vector<double> intervals() {
        std::vector<double> ms(static_cast<std::size_t>(std::max(marks_ - 1, 0)), 0.0);
        if (method_ == TimingMethod::wall_clock) {
            for (int i = 0; i + 1 < marks_; ++i)
                ms[static_cast<std::size_t>(i)] =
                    std::chrono::duration<double, std::milli>(wall_[i + 1] - wall_[i]).count();
        } else if (method_ == TimingMethod::timer_query) {
            GLuint64 t[kMaxMarks] = {};
            for (int i = 0; i < marks_; ++i) glGetQueryObjectui64v(queries_[i], GL_QUERY_RESULT, &t[i]);
            for (int i = 0; i + 1 < marks_; ++i)
                ms[static_cast<std::size_t>(i)] = static_cast<double>(t[i + 1] - t[i]) * 1e-6;
        }
        return ms;
    }

private:
    TimingMethod method_;
    GLuint* queries_;
    std::chrono::steady_clock::time_point wall_[kMaxMarks];
    int marks_ = 0;
};

struct CullPipeline::Impl {
    explicit Impl(const GlContext& ctx)
        : renderer(ctx),
          frustum(passes),
          frustum_disp(passes),
          hiz_build(passes),
          occlusion(passes),
          displaced(passes),
          status(passes),
          fused(passes),
          compact(passes) {
        glCreateBuffers(1, &counters);
        GLint alignment = 16;
        glGetIntegerv(GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, &alignment);
        const std::size_t bytes = sh::kCounterCount * sizeof(std::uint32_t);
        const std::size_t a = static_cast<std::size_t>(std::max(alignment, 1));
        counter_stride = (bytes + a - 1) / a * a;
        check_gl("CullPipeline setup");
    }
    ~Impl() {
        glDeleteBuffers(1, &counters);
        glDeleteTextures(1, &hiz.texture);
        for (PassDrawList& l : draw_lists) {
            const GLuint buffers[] = {l.list, l.commands, l.counts};
            glDeleteBuffers(3, buffers);
        }
        if (timer_queries[0]) glDeleteQueries(PassClock::kMaxMarks, timer_queries);
    }
    PatchRenderer renderer;  // first: makes the context current before the passes bind to it
    PassContext passes;
    FrustumPass frustum;
    FrustumDispPass frustum_disp;
    HiZBuildPass hiz_build;
    OcclusionPass occlusion;
    DisplacedPass displaced;
    CullStatusPass status;
    FusedCullPass fused;
    CompactPass compact;
    // DrawMode::indirect: one draw pass's list, commands and draw counts (pass 1, pass 2). A frame
    // appends one CompactPass range per span drawn: commands [0, used_commands), counts
    // [0, used_counts); a list entry per patch of the set (a span's entries at its patches).
    struct PassDrawList {
        GLuint list = 0, commands = 0, counts = 0;
        std::size_t list_capacity = 0, command_capacity = 0, count_capacity = 0;  // entries
        std::size_t used_commands = 0, used_counts = 0;
        bool started = false;    // sized for this frame
        std::size_t issued = 0;  // DrawMode::flags: the patches of the spans drawn
        // CompactMethod::fused_append: the chain's end appended the lists of `appended` spans
        // (reserve_draw_list), commands from appended_first_command on, for the pass's next draw.
        std::vector<PatchSpan> appended;
        std::size_t appended_first_command = 0;
    };
    PassDrawList draw_lists[2];
    std::map<BackpatchMethod, std::unique_ptr<BackpatchPass>> backpatch_passes;  // made on first use
    HiZTexture hiz;                  // of the framebuffer's size; recreated when it changes
    GLuint counters = 0;             // kCounterCount uints per object (+ one slot for the rest)
    std::size_t counter_stride = 0;  // bytes between slots (the SSBO offset alignment)
    std::size_t counter_slots = 0;   // slots allocated
    GLuint timer_queries[PassClock::kMaxMarks] = {};
    // The renderer's flag_generation when the statuses were primed; another value (the flags were
    // replaced, or reset_visibility) makes the next frame a first frame.
    std::uint64_t primed_generation = ~std::uint64_t{0};
    bool forget_visibility = false;  // CullPipeline::forget_visibility: clear the statuses first

    // Tags the even-indexed patches visible, the others not (Niessner & Loop §3's first frame).
    void prime_statuses() {
        std::vector<std::uint32_t> words(renderer.patch_count());
        for (std::size_t p = 0; p < words.size(); p += 2) words[p] = sh::kStatusVisible;
        renderer.set_flag_words(words);
        primed_generation = renderer.flag_generation();
    }

    void ensure_counter_slots(std::size_t slots) {
        if (slots > counter_slots) {
            glNamedBufferData(counters, static_cast<GLsizeiptr>(slots * counter_stride), nullptr, GL_DYNAMIC_READ);
            counter_slots = slots;
        }
        glClearNamedBufferData(counters, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
    }

    BackpatchPass& backpatch_pass(BackpatchMethod method) {
        std::unique_ptr<BackpatchPass>& pass = backpatch_passes[method];
        if (!pass) pass = make_backpatch_pass(passes, method);
        return *pass;
    }

    /// Reads the frame's counters back (waits) into stats: per object and in all, and the
    /// clock's intervals as the pass times.
    void read_stats(const SpanPlan& plan, const FrameTests& frame, bool two_pass, bool aggressive, PassClock& clock,
                    FrameStats& stats);

    /// A draw pass's draw (pass 0 or 1) of the patches of spans that (flag & mask) == value
    /// keeps, in the frame's DrawMode (gl_pipeline.h's PipelineParams::draw); plan sizes the
    /// pass's buffers on its first draw of the frame.
    void draw(int pass, std::uint32_t mask, std::uint32_t value, const std::vector<PatchSpan>& spans,
              const PipelineParams& params, const SpanPlan& plan);
    /// Starts a frame's draws (nothing drawn or compacted yet).
    void begin_draws() {
        for (PassDrawList& l : draw_lists) {
            l.used_commands = l.used_counts = l.issued = 0;
            l.appended.clear();
            l.started = false;
        }
    }
    /// DrawMode::indirect's K: at most patches_per_draw() patches a command, a sixteenth of that
    /// on a software rasterizer.
    std::size_t patches_per_command() const;
    /// Sizes pass's buffers for the frame on its first use (plan's spans bound its commands).
    void start_draw_list(int pass, const SpanPlan& plan);
    /// CompactMethod::fused_append: the range of pass's buffers for span s (its list entries at its
    /// patches, its commands and draw count next), for CullStatusPass::end to append into; the
    /// pass's next draw draws the spans reserved so far instead of compacting them, in this order.
    DrawListBuffers reserve_draw_list(int pass, const PatchSpan& s, const SpanPlan& plan);
    /// The patches each pass issued (FrameStats::pass*_submitted; reads the commands back).
    std::size_t submitted(int pass, DrawMode mode) const;

    void ensure_hiz() {
        if (hiz.texture && hiz.width == renderer.width() && hiz.height == renderer.height()) return;
        glDeleteTextures(1, &hiz.texture);
        hiz = create_hiz_texture(renderer.width(), renderer.height());
    }
};

}  // namespace patchcull::gl
