// CullPipeline (patchcull/gl/gl_pipeline.h): Niessner & Loop §3's two-pass frame, the passes of
// gl_passes.h chained through the renderer's flag buffer. The frame's spans come from plan_spans
// (gl_span_plan.h), its flag chain from FrameChain (frame_chain.h).
#include <algorithm>
#include <functional>
#include <string>
#include <vector>

#include "cull_pipeline_impl.h"
#include "frame_chain.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/error.h"
#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/gl/gl_span_plan.h"

namespace patchcull::gl {

CullPipeline::CullPipeline(const GlContext& ctx) : impl_((ctx.make_current(), std::make_unique<Impl>(ctx))) {}
CullPipeline::CullPipeline(CullPipeline&&) noexcept = default;
CullPipeline& CullPipeline::operator=(CullPipeline&&) noexcept = default;
CullPipeline::~CullPipeline() = default;

void CullPipeline::set_patches(const std::vector<BezierPatch>& patches, const PatchAttributes& attributes) {
    impl_->renderer.set_patches(patches, attributes);
}

void CullPipeline::update_patches(const std::vector<BezierPatch>& patches, const PatchAttributes& attributes) {
    impl_->renderer.update_patches(patches, attributes);
}

std::size_t CullPipeline::patch_count() const { return impl_->renderer.patch_count(); }
void CullPipeline::reset_visibility() { impl_->primed_generation = ~std::uint64_t{0}; }
void CullPipeline::forget_visibility() { impl_->forget_visibility = true; }

const char* frustum_test_name(FrustumTest test) { return test == FrustumTest::aabb ? "aabb" : "hull"; }
const char* draw_mode_name(DrawMode mode) { return mode == DrawMode::indirect ? "indirect" : "flags"; }

Vec3 eye_of_view(const Mat4& view) {
    Mat4 inverse;
    if (!invert(view, inverse)) throw Error("render: the view matrix is singular (no eye position)");
    return cartesian(inverse * Vec4{0, 0, 0, 1});
}

namespace {

// The object pass's drawer (ObjectDrawer): draws an object's first-pass patches (two-pass) or
// runs the chain on it and draws what passed (one pass).
struct Drawer final : ObjectDrawer {
    std::function<void(std::size_t)> draw_object;
    PatchRenderer* target = nullptr;
    std::vector<std::uint8_t> done;
    void draw(std::size_t object) override {
        if (object >= done.size())
            throw Error("ObjectDrawer::draw: object " + std::to_string(object) + " out of range");
        if (done[object]) return;
        done[object] = 1;
        draw_object(object);
    }
    PatchRenderer& renderer() override { return *target; }
};

// The frame's tests from the parameters and what the draw displaces.
FrameTests frame_tests(const PipelineParams& params, const PatchRenderer& r) {
    const RenderParams& rp = params.frame.render;
    FrameTests f;
    f.tests = static_cast<std::uint32_t>(params.frame.cull) & sh::kCullReasonMask;
    f.two_pass = (f.tests & sh::kCullOcclusion) != 0;
    // What the draw displaces decides what the tests may assume (gl_renderer.h): with a map and
    // without margins every patch is displaced by an unknown amount, so nothing may be culled.
    const bool displacing = rp.displace && r.displaces();
    f.chain = r.patch_buffers();
    if (!displacing) f.chain.margins = 0;  // drawn undisplaced: every patch is its base patch
    if (displacing && !f.chain.margins) f.tests = 0;
    f.ranges = displacing ? r.range_buffer() : 0;
    f.view = make_cull_view(rp.view, rp.projection, rp.depth);
    eye_of_view(rp.view);  // refuses a singular view, as before the CullView
    f.backpatch_options = BackpatchOptions{params.ptp_rule};
    f.aabb = params.frustum == FrustumTest::aabb;
    // The fused pass replaces frustum, back-patch and Hi-Z where it can run them (gl_pipeline.h).
    f.fused = params.fused_pass && !f.aabb &&
              !((f.tests & sh::kCullBackPatch) && !backpatch_method_info(params.backpatch).fusable);
    return f;
}

}  // namespace

FrameStats CullPipeline::render_frame(const PipelineParams& params) {
    Impl& m = *impl_;
    PatchRenderer& r = m.renderer;
    const FrameParams& frame = params.frame;
    const RenderParams& rp = frame.render;
    const FrameTests f = frame_tests(params, r);
    const bool two_pass = f.two_pass;
    TimingMethod method = frame.timing;
    if (method == TimingMethod::automatic)
        method = m.passes.is_software() ? TimingMethod::wall_clock : TimingMethod::timer_query;

    FrameStats stats;
    stats.patches = r.patch_count();
    stats.two_pass = two_pass;
    stats.timing = method;
    stats.fused_pass = f.fused;
    stats.draw = params.draw;

    SpanPlan plan = plan_spans(r.patch_count(), params.objects, params.object_culled);
    if (params.object_pass && params.objects.empty())
        throw Error("render_frame: an object pass needs PipelineParams::objects");

    if (m.primed_generation != r.flag_generation()) m.prime_statuses();
    if (m.forget_visibility && r.patch_count() > 0) {
        // No status, no reason: as a patch no frame has drawn yet (after the last frame's writes).
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glClearNamedBufferData(r.flag_buffer(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
    }
    m.forget_visibility = false;
    r.set_culled_occluders(params.culled_occluders);
    m.ensure_counter_slots(plan.objects.size() + 1);
    m.begin_draws();
    PassClock clock(method, m.timer_queries);
    clock.mark();
    FrameChain chain(m, params, f, plan, clock);
    // CompactMethod::fused_append: the chain's end lists the draw that follows it where its
    // dispatch spans are that draw's spans (no object-culled spans); else CompactPass does.
    auto fusable = [&] {
        return params.draw == DrawMode::indirect && params.compact == CompactMethod::fused_append &&
               plan.culled.empty() && r.patch_count() > 0;
    };
    const bool fused_list = !two_pass && !params.object_pass && fusable();
    // The object pass (PipelineParams::object_pass): the objects it leaves out become object-culled
    // spans.
    auto run_object_pass = [&](bool chain_per_object) {
        Drawer drawer;
        drawer.target = &r;
        drawer.done.assign(plan.objects.size(), 0);
        drawer.draw_object = [&](std::size_t i) {
            if (chain_per_object) {
                const std::vector<std::size_t> one{i};
                chain.run(nullptr, &one, false);
            }
            const std::vector<PatchSpan> active = plan.active_spans(plan.objects[i]);
            if (!active.empty()) m.draw(0, sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass, active, params, plan);
        };
        params.object_pass->run(drawer);
        std::vector<PatchSpan> left_out;
        for (std::size_t i = 0; i < plan.objects.size(); ++i) {
            if (drawer.done[i]) continue;
            ++stats.objects_left_out;
            for (const PatchSpan& s : plan.active_spans(plan.objects[i])) left_out.push_back(s);
        }
        plan.add_culled(left_out);
    };
    if (two_pass) {
        // 1. occluders + patches tagged visible: with an object pass, the pass draws each object
        // it finds visible (its patches tagged visible), then the patches outside every object.
        r.begin_frame(rp);
        if (params.object_pass) {
            run_object_pass(false);
            m.draw(0, sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass, plan.gaps_drawn, params, plan);
        } else {
            m.draw(0, sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass, plan.drawn, params, plan);
        }
        clock.mark();
        // 2. Hi-Z from that depth.
        m.ensure_hiz();
        m.hiz_build.run(r.depth_texture(), m.hiz, rp.depth);
        clock.mark();
        // 3. test every patch (of the objects drawn), update statuses (and list pass 2's patches
        // when fused).
        if (!frame.aggressive && fusable()) chain.append_to(1, sh::kDrawMaskSecondPass, sh::kDrawValueSecondPass);
        chain.run(&m.hiz);
        // 4. newly visible patches (Niessner & Loop §3.1: skipped when aggressive).
        if (!frame.aggressive) m.draw(1, sh::kDrawMaskSecondPass, sh::kDrawValueSecondPass, plan.drawn, params, plan);
        clock.mark();
    } else if (params.object_pass) {
        // One pass: the object pass runs the chain on each object it draws; the objects it left
        // out get their culled words; then the gaps. Every part counts as pass 1.
        clock.mark();
        clock.mark();
        clock.mark();
        r.begin_frame(rp);
        run_object_pass(true);
        for (std::size_t i = 0; i < plan.objects.size(); ++i)
            if (plan.object_spans[i].empty())
                chain.mark_culled(plan.objects[i].first, plan.objects[i].first + plan.objects[i].count);
        chain.begin_gaps();
        chain.end_gaps();
        m.draw(0, sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass, plan.gaps_drawn, params, plan);
        clock.mark();
    } else if (fused_list) {
        // The chain lists the draw's patches: the commands' K needs begin_frame's tessellation
        // level, so the occluders are drawn before the chain (their time counts in cull_ms).
        r.begin_frame(rp);
        chain.append_to(0, sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass);
        chain.run(nullptr);
        m.draw(0, sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass, plan.drawn, params, plan);
        clock.mark();
    } else {
        chain.run(nullptr);
        r.begin_frame(rp);
        m.draw(0, sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass, plan.drawn, params, plan);
        clock.mark();
    }
    check_gl("render_frame");
    m.read_stats(plan, f, two_pass, frame.aggressive, clock, stats);
    stats.pass1_submitted = m.submitted(0, params.draw);
    stats.pass2_submitted = m.submitted(1, params.draw);
    return stats;
}

void CullPipeline::Impl::draw(int pass, std::uint32_t mask, std::uint32_t value, const std::vector<PatchSpan>& spans,
                              const PipelineParams& params, const SpanPlan& plan) {
    PassDrawList& l = draw_lists[pass];
    if (params.draw == DrawMode::flags) {
        renderer.draw_selected(mask, value, spans);
        for (const PatchSpan& s : spans) l.issued += s.count;
        return;
    }
    if (spans.empty() || renderer.patch_count() == 0) return;
    const std::size_t k = patches_per_command();
    start_draw_list(pass, plan);
    std::size_t first_command = l.used_commands;
    if (!l.appended.empty()) {
        // CompactMethod::fused_append: the chain's end listed these spans already.
        const bool same =
            l.appended.size() == spans.size() &&
            std::equal(spans.begin(), spans.end(), l.appended.begin(),
                       [](const PatchSpan& a, const PatchSpan& b) { return a.first == b.first && a.count == b.count; });
        if (!same || l.used_counts != l.appended.size())
            throw Error("render_frame: a draw pass's spans differ from those its chain listed (internal)");
        first_command = l.appended_first_command;
        l.appended.clear();
    } else {
        for (const PatchSpan& s : spans) {
            const std::size_t commands = compact_command_count(s.count, k);
            if (l.used_commands + commands > l.command_capacity || l.used_counts + 1 > l.count_capacity)
                throw Error("render_frame: a draw pass's spans outgrew its command buffer (internal)");
            PatchBuffers range = renderer.patch_buffers();
            range.first = s.first;
            range.count = s.count;
            compact.run(range, mask, value,
                        {l.list, s.first, l.commands, l.used_commands * sizeof(DrawArraysIndirectCommand), l.counts,
                         l.used_counts * 4, k},
                        params.compact);
            l.used_commands += commands;
            ++l.used_counts;
        }
    }
    // With glMultiDrawArraysIndirectCount: one per span, each with its own range's draw count
    // (a span's commands past its survivors are never read). Without it: one
    // glMultiDrawArraysIndirect over every command of the spans (the empty ones draw nothing).
    IndirectDraw d;
    d.list = l.list;
    d.commands = l.commands;
    d.first_command = first_command;
    if (!renderer.has_indirect_count()) {
        d.command_count = l.used_commands - first_command;
        renderer.draw_indirect(d);
        return;
    }
    d.draw_count = l.counts;
    d.draw_count_offset = (l.used_counts - spans.size()) * 4;
    for (const PatchSpan& s : spans) {
        d.command_count = compact_command_count(s.count, k);
        renderer.draw_indirect(d);
        d.first_command += d.command_count;
        d.draw_count_offset += 4;
    }
}

std::size_t CullPipeline::Impl::patches_per_command() const {
    // At most patches_per_draw() patches a command (llvmpipe's limit), a sixteenth of that on a
    // software rasterizer (core/render_params.h).
    return patches_per_indirect_command(renderer.patches_per_draw(), passes.is_software());
}

void CullPipeline::Impl::start_draw_list(int pass, const SpanPlan& plan) {
    PassDrawList& l = draw_lists[pass];
    if (l.started) return;
    // Every span a pass draws lies in one span of the plan at its first draw (an object's
    // active spans, the gaps), so the plan's commands bound the pass's.
    const std::size_t k = patches_per_command();
    std::size_t commands = 0;
    for (const PatchSpan& s : plan.drawn) commands += compact_command_count(s.count, k);
    const std::size_t counts = plan.drawn.size();
    auto grow = [](GLuint& buffer, std::size_t& capacity, std::size_t need, std::size_t bytes_each) {
        if (buffer && need <= capacity) return;
        capacity = std::max(need, 2 * capacity);
        if (!buffer) glCreateBuffers(1, &buffer);
        glNamedBufferData(buffer, static_cast<GLsizeiptr>(capacity * bytes_each), nullptr, GL_DYNAMIC_DRAW);
    };
    grow(l.list, l.list_capacity, std::max<std::size_t>(renderer.patch_count(), 1), 4);
    grow(l.commands, l.command_capacity, std::max<std::size_t>(commands, 1), sizeof(DrawArraysIndirectCommand));
    grow(l.counts, l.count_capacity, std::max<std::size_t>(counts, 1), 4);
    l.started = true;
}

DrawListBuffers CullPipeline::Impl::reserve_draw_list(int pass, const PatchSpan& s, const SpanPlan& plan) {
    start_draw_list(pass, plan);
    PassDrawList& l = draw_lists[pass];
    const std::size_t k = patches_per_command();
    const std::size_t commands = compact_command_count(s.count, k);
    if (l.used_commands + commands > l.command_capacity || l.used_counts + 1 > l.count_capacity)
        throw Error("render_frame: a draw pass's spans outgrew its command buffer (internal)");
    if (l.appended.empty()) l.appended_first_command = l.used_commands;
    l.appended.push_back(s);
    const DrawListBuffers out{
        l.list,   s.first,           l.commands, l.used_commands * sizeof(DrawArraysIndirectCommand),
        l.counts, l.used_counts * 4, k};
    l.used_commands += commands;
    ++l.used_counts;
    return out;
}

std::size_t CullPipeline::Impl::submitted(int pass, DrawMode mode) const {
    const PassDrawList& l = draw_lists[pass];
    if (mode == DrawMode::flags) return l.issued;
    if (l.used_commands == 0) return 0;
    std::vector<DrawArraysIndirectCommand> commands(l.used_commands);

    glGetNamedBufferSubData(l.commands, 0, static_cast<GLsizeiptr>(commands.size() * sizeof(DrawArraysIndirectCommand)),
                            commands.data());
    check_gl("render_frame draw commands");
    std::size_t n = 0;
    for (const DrawArraysIndirectCommand& c : commands) n += c.count / sh::kDrawListPatchVertices;
    return n;
}

void CullPipeline::Impl::read_stats(const SpanPlan& plan, const FrameTests& f, bool two_pass, bool aggressive,
                                    PassClock& clock, FrameStats& stats) {
    const std::vector<ObjectRange>& objects = plan.objects;
    std::vector<std::uint32_t> slots((objects.size() + 1) * counter_stride / sizeof(std::uint32_t));
    glGetNamedBufferSubData(counters, 0, static_cast<GLsizeiptr>(slots.size() * sizeof(std::uint32_t)), slots.data());
    check_gl("render_frame counters");
    std::uint32_t c[sh::kCounterCount] = {};
    for (std::size_t i = 0; i <= objects.size(); ++i) {
        const std::uint32_t* slot = slots.data() + i * counter_stride / sizeof(std::uint32_t);
        for (std::uint32_t k = 0; k < sh::kCounterCount; ++k) c[k] += slot[k];
        if (i == objects.size()) break;
        ObjectStats o;
        o.patches = objects[i].count;
        o.object_culled = objects[i].count;
        for (const PatchSpan& s : plan.active_spans(objects[i])) o.object_culled -= s.count;
        o.frustum_culled = slot[sh::kCounterFrustum];
        o.backpatch_culled = slot[sh::kCounterBackPatch];
        o.occlusion_culled = slot[sh::kCounterOcclusion];
        o.visible = slot[sh::kCounterVisible];
        stats.objects.push_back(o);
    }
    for (const PatchSpan& s : plan.culled) stats.object_culled += s.count;
    stats.frustum_culled = c[sh::kCounterFrustum];
    stats.backpatch_culled = c[sh::kCounterBackPatch];
    stats.occlusion_culled = c[sh::kCounterOcclusion];
    stats.displaced_occlusion_culled = c[sh::kCounterDisplacedOcclusion];
    stats.visible = c[sh::kCounterVisible];
    stats.newly_visible = c[sh::kCounterNewlyVisible];
    if (two_pass) {
        stats.pass1_drawn = c[sh::kCounterWasVisible];
        stats.pass2_drawn = aggressive ? 0 : stats.newly_visible;
    } else {
        stats.pass1_drawn = stats.visible;
    }
    const std::vector<double> ms = clock.intervals();
    if (!ms.empty()) {
        // Two-pass marks: pass1 | hiz | chain A | back-patch | chain B | pass2; one pass: chain A |
        // back-patch | chain B | pass1.
        const std::size_t chain_first = two_pass ? 2 : 0;
        stats.cull_ms = ms[chain_first] + ms[chain_first + 1] + ms[chain_first + 2];
        if ((f.tests & sh::kCullBackPatch) && !f.fused) stats.backpatch_ms = ms[chain_first + 1];
        if (two_pass) {
            stats.pass1_ms = ms[0];
            stats.hiz_ms = ms[1];
            stats.pass2_ms = ms[5];
        } else {
            stats.pass1_ms = ms[3];
        }
        for (double t : ms) stats.total_ms += t;
    }
}

std::vector<float> CullPipeline::read_hiz() const {
    if (!impl_->hiz.texture) throw Error("GL: read_hiz: no two-pass frame yet");
    return read_hiz_texture(impl_->hiz);
}
int CullPipeline::hiz_levels() const {
    return impl_->hiz.texture ? HiZPyramid::level_count(impl_->hiz.width, impl_->hiz.height) : 0;
}

PatchRenderer& CullPipeline::renderer() { return impl_->renderer; }
const PatchRenderer& CullPipeline::renderer() const { return impl_->renderer; }
PassContext& CullPipeline::passes() { return impl_->passes; }

}  // namespace patchcull::gl
