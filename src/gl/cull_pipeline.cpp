// CullPipeline (patchcull/gl/gl_pipeline.h): Niessner & Loop §3's two-pass frame, the passes of
// gl_passes.h chained through the renderer's flag buffer.
#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/gl/gl_pipeline.h"
#include "renderer_internal.h"

namespace patchcull::gl {

static_assert(kFlagFrustum == sh::kCullFrustum && kFlagBackPatch == sh::kCullBackPatch &&
              kFlagOcclusion == sh::kCullOcclusion && kFlagObject == sh::kCullObject &&
              kFlagReasonMask == sh::kCullReasonMask);
static_assert(kStatusVisible == sh::kStatusVisible && kStatusNewlyVisible == sh::kStatusNewlyVisible);

namespace {

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
                ms[static_cast<std::size_t>(i)] = std::chrono::duration<double, std::milli>(wall_[i + 1] - wall_[i]).count();
        } else if (method_ == TimingMethod::timer_query) {
            GLuint64 t[kMaxMarks] = {};
            for (int i = 0; i < marks_; ++i) glGetQueryObjectui64v(queries_[i], GL_QUERY_RESULT, &t[i]);
            for (int i = 0; i + 1 < marks_; ++i) ms[static_cast<std::size_t>(i)] = static_cast<double>(t[i + 1] - t[i]) * 1e-6;
        }
        return ms;
    }

private:
    TimingMethod method_;
    GLuint* queries_;
    std::chrono::steady_clock::time_point wall_[kMaxMarks];
    int marks_ = 0;
};

}  // namespace

struct CullPipeline::Impl {
    explicit Impl(const GlContext& ctx)
        : renderer(ctx), frustum(passes), frustum_disp(passes), hiz_build(passes), occlusion(passes), cones(passes), ptp(passes),
          displaced(passes), status(passes), fused(passes) {
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
        if (timer_queries[0]) glDeleteQueries(PassClock::kMaxMarks, timer_queries);
    }
    PatchRenderer renderer;  // first: makes the context current before the passes bind to it
    PassContext passes;
    FrustumPass frustum;
    FrustumDispPass frustum_disp;
    HiZBuildPass hiz_build;
    OcclusionPass occlusion;
    BackpatchConePass cones;
    BackpatchPtpPass ptp;
    DisplacedPass displaced;
    CullStatusPass status;
    FusedCullPass fused;
    HiZTexture hiz;  // of the framebuffer's size; recreated when it changes
    GLuint counters = 0;             // kCounterCount uints per object (+ one slot for the rest)
    std::size_t counter_stride = 0;  // bytes between slots (the SSBO offset alignment)
    std::size_t counter_slots = 0;   // slots allocated
    GLuint timer_queries[PassClock::kMaxMarks] = {};
    // The renderer's flag_generation when the statuses were primed; another value (the flags were
    // replaced, or reset_visibility) makes the next frame a first frame.
    std::uint64_t primed_generation = ~std::uint64_t{0};

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

    void ensure_hiz() {
        if (hiz.texture && hiz.width == renderer.width() && hiz.height == renderer.height()) return;
        glDeleteTextures(1, &hiz.texture);
        hiz = create_hiz_texture(renderer.width(), renderer.height());
    }
};

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

const char* frustum_test_name(FrustumTest test) { return test == FrustumTest::aabb ? "aabb" : "hull"; }

Vec3 eye_of_view(const Mat4& view) {
    Mat4 inverse;
    if (!invert(view, inverse)) throw Error("render: the view matrix is singular (no eye position)");
    return cartesian(inverse * Vec4{0, 0, 0, 1});
}

FrameStats CullPipeline::render_frame(const PipelineParams& params) {
    Impl& m = *impl_;
    PatchRenderer& r = m.renderer;
    const FrameParams& frame = params.frame;
    const RenderParams& rp = frame.render;
    std::uint32_t tests = static_cast<std::uint32_t>(frame.cull) & sh::kCullReasonMask;
    const bool two_pass = (tests & sh::kCullOcclusion) != 0;
    TimingMethod method = frame.timing;
    if (method == TimingMethod::automatic) method = m.passes.is_software() ? TimingMethod::wall_clock : TimingMethod::timer_query;

    // What the draw displaces decides what the tests may assume (gl_renderer.h): with a map and
    // without margins every patch is displaced by an unknown amount, so nothing may be culled.
    const bool displacing = rp.displace && r.displaces();
    PatchBuffers chain = r.patch_buffers();
    if (!displacing) chain.margins = 0;  // drawn undisplaced: every patch is its base patch
    if (displacing && !chain.margins) tests = 0;
    const std::uint32_t ranges = displacing ? r.range_buffer() : 0;

    FrameStats stats;
    stats.patches = r.patch_count();
    stats.two_pass = two_pass;
    stats.timing = method;
    const Mat4 object_to_clip = rp.projection * rp.view;
    const Vec3 eye = eye_of_view(rp.view);
    const bool aabb = params.frustum == FrustumTest::aabb;
    // The fused pass replaces frustum, back-patch and Hi-Z where it can run them (gl_pipeline.h).
    const bool fused = params.fused_pass && !aabb &&
                       !((tests & sh::kCullBackPatch) && params.backpatch == BackpatchMethod::ptp);
    stats.fused_pass = fused;

    // The objects, and the ranges between them (drawn unculled, counted in the last slot).
    const std::size_t count = r.patch_count();
    std::vector<ObjectRange> objects = params.objects;
    if (objects.empty()) objects.push_back({0, count, true});
    std::vector<ObjectRange> sorted = objects;
    std::sort(sorted.begin(), sorted.end(), [](const ObjectRange& a, const ObjectRange& b) { return a.first < b.first; });
    std::vector<ObjectRange> gaps;
    std::size_t covered = 0;
    for (const ObjectRange& o : sorted) {
        if (o.first > count || o.count > count - o.first)
            throw Error("render_frame: object [" + std::to_string(o.first) + ", +" + std::to_string(o.count) +
                        ") leaves the set of " + std::to_string(count) + " patches");
        if (o.first < covered) throw Error("render_frame: objects overlap at patch " + std::to_string(o.first));
        if (o.first > covered) gaps.push_back({covered, o.first - covered, false});
        covered = o.first + o.count;
    }
    if (covered < count) gaps.push_back({covered, count - covered, false});
    // Object-level culls: the spans no pass or draw touches; every range runs on what is left.
    std::vector<PatchSpan> culled = params.object_culled;
    std::sort(culled.begin(), culled.end(), [](const PatchSpan& a, const PatchSpan& b) { return a.first < b.first; });
    std::size_t culled_end = 0;
    for (const PatchSpan& s : culled) {
        if (s.first > count || s.count > count - s.first)
            throw Error("render_frame: object-culled span [" + std::to_string(s.first) + ", +" + std::to_string(s.count) +
                        ") leaves the set of " + std::to_string(count) + " patches");
        if (s.first < culled_end) throw Error("render_frame: object-culled spans overlap at patch " + std::to_string(s.first));
        culled_end = s.first + s.count;
    }
    // The parts of [o.first, o.first + o.count) outside every culled span, in order.
    auto active_spans = [&culled](const ObjectRange& o) {
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
    };
    // Dispatch spans: an object (or gap) culled whole gets no pass; one with culled clusters
    // inside is dispatched whole, its culled words pre-marked kCullObject so that every pass
    // skips them (the chain's rule). Draws issue only the patches outside the culled spans.
    std::vector<std::vector<PatchSpan>> object_spans, gap_spans;
    std::vector<PatchSpan> drawn, gaps_drawn;
    // (Re)plans the dispatch and draw spans from `culled` (again after an ObjectPass added to it).
    auto plan_spans = [&] {
        object_spans.clear();
        gap_spans.clear();
        drawn.clear();
        gaps_drawn.clear();
        auto dispatch_spans = [&](const ObjectRange& o, std::vector<PatchSpan>* also_drawn) {
            std::vector<PatchSpan> active = active_spans(o);
            drawn.insert(drawn.end(), active.begin(), active.end());
            if (also_drawn) also_drawn->insert(also_drawn->end(), active.begin(), active.end());
            if (active.empty()) return std::vector<PatchSpan>{};
            return std::vector<PatchSpan>{{o.first, o.count}};
        };
        for (const ObjectRange& o : objects) object_spans.push_back(dispatch_spans(o, nullptr));
        for (const ObjectRange& g : gaps) gap_spans.push_back(dispatch_spans(g, &gaps_drawn));
    };
    plan_spans();
    if (params.object_pass && params.objects.empty())
        throw Error("render_frame: an object pass needs PipelineParams::objects");
    auto buffers_of = [&chain](const PatchSpan& s) {
        PatchBuffers b = chain;
        b.first = s.first;
        b.count = s.count;
        return b;
    };

    if (m.primed_generation != r.flag_generation()) m.prime_statuses();
    r.set_culled_occluders(params.culled_occluders);
    m.ensure_counter_slots(objects.size() + 1);
    PassClock clock(method, m.timer_queries);
    clock.mark();
    // The flag chain (gl_passes.h) per culled object, in three timed parts: begin + frustum,
    // back-patch, the rest.
    // The culled spans' words within [first, end): kFlagObject, status cleared (a buffer clear
    // after begin's shader writes, no pass).
    auto mark_culled = [&](std::size_t first, std::size_t end) {
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        const std::uint32_t object_word = sh::kCullObject;
        for (const PatchSpan& s : culled) {
            const std::size_t a = std::max(s.first, first), b = std::min(s.first + s.count, end);
            if (a < b)
                glClearNamedBufferSubData(r.flag_buffer(), GL_R32UI, static_cast<GLintptr>(a * sizeof(std::uint32_t)),
                                          static_cast<GLsizeiptr>((b - a) * sizeof(std::uint32_t)), GL_RED_INTEGER,
                                          GL_UNSIGNED_INT, &object_word);
        }
    };
    // The chain on the objects `only` names (every object and every gap when it is null),
    // marking the clock between its parts when timed.
    auto run_chain = [&](const HiZTexture* hiz, const std::vector<std::size_t>* only = nullptr, bool timed = true) {
        std::vector<std::size_t> all_objects;
        if (!only) {
            for (std::size_t i = 0; i < objects.size(); ++i) all_objects.push_back(i);
            only = &all_objects;
        }
        const bool with_gaps = only == &all_objects;
        for (std::size_t i : *only)
            for (const PatchSpan& s : object_spans[i]) m.status.begin(buffers_of(s));
        if (with_gaps)
            for (const std::vector<PatchSpan>& spans : gap_spans)
                for (const PatchSpan& s : spans) m.status.begin(buffers_of(s));
        if (with_gaps) {
            if (!culled.empty()) mark_culled(0, count);
        } else {
            for (std::size_t i : *only) mark_culled(objects[i].first, objects[i].first + objects[i].count);
        }
        const FrustumPlanes planes = make_frustum_planes(object_to_clip, rp.depth);
        if (fused) {
            // One dispatch per span for all three tests; its time counts as chain A.
            const std::uint32_t fused_tests =
                (tests & (sh::kCullFrustum | sh::kCullBackPatch)) | (hiz ? (tests & sh::kCullOcclusion) : 0u);
            for (std::size_t i : *only)
                if (objects[i].cull)
                    for (const PatchSpan& s : object_spans[i])
                        m.fused.run(buffers_of(s), fused_tests, object_to_clip, rp.depth, params.backpatch,
                                    eye, hiz);
        }
        for (std::size_t i : *only)
            if (!fused && objects[i].cull && (tests & sh::kCullFrustum))
                for (const PatchSpan& s : object_spans[i]) {
                    if (aabb)
                        m.frustum_disp.run(buffers_of(s), object_to_clip, rp.depth);
                    else
                        m.frustum.run(buffers_of(s), planes);
                }
        if (timed) clock.mark();
        for (std::size_t i : *only) {
            if (fused || !objects[i].cull || !(tests & sh::kCullBackPatch)) continue;
            for (const PatchSpan& s : object_spans[i]) {
                if (params.backpatch == BackpatchMethod::ptp)
                    m.ptp.run(buffers_of(s), object_to_clip, clip_space_eye_alpha(rp.projection), params.ptp_rule);
                else
                    m.cones.run(buffers_of(s), params.backpatch, eye);
            }
        }
        if (timed) clock.mark();
        // The frustum pass ran first when the mode has it: the occlusion pass only tests Hi-Z.
        const HiZTexture* occluding = (tests & sh::kCullOcclusion) ? hiz : nullptr;
        // The displaced pass runs when either test is asked for, with the bound's frustum test
        // too (a bound outside the frustum is invisible), against the pyramid when occluding.
        // With the aabb frustum test the box (grown by max |D|) already tested the displaced patches
        // against the frustum: the bound is built only for the Hi-Z test.
        const bool bounds = ranges && (aabb ? occluding != nullptr : (tests & (sh::kCullFrustum | sh::kCullOcclusion)) != 0);
        const DisplacedCullView view =
            bounds ? make_displaced_cull_view(rp.view, rp.projection, rp.depth) : DisplacedCullView{};
        for (std::size_t i : *only) {
            if (!objects[i].cull) continue;
            for (const PatchSpan& s : object_spans[i]) {
                if (occluding && !fused) m.occlusion.run(buffers_of(s), object_to_clip, rp.depth, *occluding, false);
                if (bounds) m.displaced.run(buffers_of(s), ranges, params.bound, params.cone, view, occluding, true);
            }
        }
        for (std::size_t i : *only)
            for (const PatchSpan& s : object_spans[i]) m.status.end(buffers_of(s), m.counters, i * m.counter_stride);
        if (with_gaps)
            for (const std::vector<PatchSpan>& spans : gap_spans)
                for (const PatchSpan& s : spans) m.status.end(buffers_of(s), m.counters, objects.size() * m.counter_stride);
        if (timed) clock.mark();
    };
    // The object pass (PipelineParams::object_pass): its drawer draws an object's first-pass
    // patches (two-pass) or runs the chain on it and draws what passed (one pass); the objects
    // it leaves out become object-culled spans.
    struct Drawer final : ObjectDrawer {
        std::function<void(std::size_t)> draw_object;
        PatchRenderer* target = nullptr;
        std::vector<std::uint8_t> done;
        void draw(std::size_t object) override {
            if (object >= done.size()) throw Error("ObjectDrawer::draw: object " + std::to_string(object) + " out of range");
            if (done[object]) return;
            done[object] = 1;
            draw_object(object);
        }
        PatchRenderer& renderer() override { return *target; }
    };
    auto run_object_pass = [&](bool chain_per_object) {
        Drawer drawer;
        drawer.target = &r;
        drawer.done.assign(objects.size(), 0);
        drawer.draw_object = [&](std::size_t i) {
            if (chain_per_object) {
                const std::vector<std::size_t> one{i};
                run_chain(nullptr, &one, false);
            }
            const std::vector<PatchSpan> active = active_spans(objects[i]);
            if (!active.empty()) r.draw_selected(sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass, active);
        };
        params.object_pass->run(drawer);
        for (std::size_t i = 0; i < objects.size(); ++i) {
            if (drawer.done[i]) continue;
            ++stats.objects_left_out;
            for (const PatchSpan& s : active_spans(objects[i])) culled.push_back(s);
        }
        std::sort(culled.begin(), culled.end(), [](const PatchSpan& a, const PatchSpan& b) { return a.first < b.first; });
        plan_spans();
    };
    if (two_pass) {
        // 1. occluders + patches tagged visible: with an object pass, the pass draws each object
        // it finds visible (its patches tagged visible), then the patches outside every object.
        r.begin_frame(rp);
        if (params.object_pass) {
            run_object_pass(false);
            r.draw_selected(sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass, gaps_drawn);
        } else {
            r.draw_selected(sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass, drawn);
        }
        clock.mark();
        // 2. Hi-Z from that depth.
        m.ensure_hiz();
        m.hiz_build.run(r.depth_texture(), m.hiz, rp.depth);
        clock.mark();
        // 3. test every patch (of the objects drawn), update statuses.
        run_chain(&m.hiz);
        // 4. newly visible patches (Niessner & Loop §3.1: skipped when aggressive).
        if (!frame.aggressive) r.draw_selected(sh::kDrawMaskSecondPass, sh::kDrawValueSecondPass, drawn);
        clock.mark();
    } else if (params.object_pass) {
        // One pass: the object pass runs the chain on each object it draws; the objects it left
        // out get their culled words; then the gaps. Every part counts as pass 1.
        clock.mark();
        clock.mark();
        clock.mark();
        r.begin_frame(rp);
        run_object_pass(true);
        for (std::size_t i = 0; i < objects.size(); ++i)
            if (object_spans[i].empty()) mark_culled(objects[i].first, objects[i].first + objects[i].count);
        for (const std::vector<PatchSpan>& spans : gap_spans)
            for (const PatchSpan& s : spans) m.status.begin(buffers_of(s));
        for (const std::vector<PatchSpan>& spans : gap_spans)
            for (const PatchSpan& s : spans) m.status.end(buffers_of(s), m.counters, objects.size() * m.counter_stride);
        r.draw_selected(sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass, gaps_drawn);
        clock.mark();
    } else {
        run_chain(nullptr);
        r.begin_frame(rp);
        r.draw_selected(sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass, drawn);
        clock.mark();
    }
    check_gl("render_frame");

    std::vector<std::uint32_t> slots((objects.size() + 1) * m.counter_stride / sizeof(std::uint32_t));
    glGetNamedBufferSubData(m.counters, 0, static_cast<GLsizeiptr>(slots.size() * sizeof(std::uint32_t)), slots.data());
    check_gl("render_frame counters");
    std::uint32_t c[sh::kCounterCount] = {};
    for (std::size_t i = 0; i <= objects.size(); ++i) {
        const std::uint32_t* slot = slots.data() + i * m.counter_stride / sizeof(std::uint32_t);
        for (std::uint32_t k = 0; k < sh::kCounterCount; ++k) c[k] += slot[k];
        if (i == objects.size()) break;
        ObjectStats o;
        o.patches = objects[i].count;
        o.object_culled = objects[i].count;
        for (const PatchSpan& s : active_spans(objects[i])) o.object_culled -= s.count;
        o.frustum_culled = slot[sh::kCounterFrustum];
        o.backpatch_culled = slot[sh::kCounterBackPatch];
        o.occlusion_culled = slot[sh::kCounterOcclusion];
        o.visible = slot[sh::kCounterVisible];
        stats.objects.push_back(o);
    }
    for (const PatchSpan& s : culled) stats.object_culled += s.count;
    stats.frustum_culled = c[sh::kCounterFrustum];
    stats.backpatch_culled = c[sh::kCounterBackPatch];
    stats.occlusion_culled = c[sh::kCounterOcclusion];
    stats.displaced_occlusion_culled = c[sh::kCounterDisplacedOcclusion];
    stats.visible = c[sh::kCounterVisible];
    stats.newly_visible = c[sh::kCounterNewlyVisible];
    if (two_pass) {
        stats.pass1_drawn = c[sh::kCounterWasVisible];
        stats.pass2_drawn = frame.aggressive ? 0 : stats.newly_visible;
    } else {
        stats.pass1_drawn = stats.visible;
    }
    const std::vector<double> ms = clock.intervals();
    if (!ms.empty()) {
        // Two-pass marks: pass1 | hiz | chain A | back-patch | chain B | pass2; one pass: chain A |
        // back-patch | chain B | pass1.
        const std::size_t chain_first = two_pass ? 2 : 0;
        stats.cull_ms = ms[chain_first] + ms[chain_first + 1] + ms[chain_first + 2];
        if ((tests & sh::kCullBackPatch) && !fused) stats.backpatch_ms = ms[chain_first + 1];
        if (two_pass) {
            stats.pass1_ms = ms[0];
            stats.hiz_ms = ms[1];
            stats.pass2_ms = ms[5];
        } else {
            stats.pass1_ms = ms[3];
        }
        for (double t : ms) stats.total_ms += t;
    }
    return stats;
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
