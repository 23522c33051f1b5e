// CullPipeline (patchcull/gl_pipeline.h): seed 000 §3's frame with seed 001's back-patch test as a
// GPU pass feeding the renderer's back-patch hook.
#include <epoxy/gl.h>

#include <chrono>

#include "patchcull/error.h"
#include "patchcull/gl_pipeline.h"
#include "renderer_internal.h"

namespace patchcull::gl {

struct CullPipeline::Impl {
    Impl(const GlContext& ctx) : renderer(ctx), culler(ctx), software(ctx.is_software()) {}
    ~Impl() {
        if (timer_query) glDeleteQueries(1, &timer_query);
    }
    PatchRenderer renderer;
    BackpatchCuller culler;
    bool software;
    GLuint timer_query = 0;
};

CullPipeline::CullPipeline(const GlContext& ctx) : impl_(std::make_unique<Impl>(ctx)) {}
CullPipeline::CullPipeline(CullPipeline&&) noexcept = default;
CullPipeline& CullPipeline::operator=(CullPipeline&&) noexcept = default;
CullPipeline::~CullPipeline() = default;

void CullPipeline::set_patches(const std::vector<BezierPatch>& patches, const PatchAttributes& attributes) {
    impl_->renderer.set_patches(patches, attributes);
    impl_->culler.use_patch_buffer(impl_->renderer.patch_buffer(), impl_->renderer.patch_count());
}

void CullPipeline::update_patches(const std::vector<BezierPatch>& patches, const PatchAttributes& attributes) {
    impl_->renderer.update_patches(patches, attributes);
    // Same buffer name and count: the culler keeps reading it. Re-pointing only checks the size.
    impl_->culler.use_patch_buffer(impl_->renderer.patch_buffer(), impl_->renderer.patch_count());
}

std::size_t CullPipeline::patch_count() const { return impl_->renderer.patch_count(); }

Vec3 eye_of_view(const Mat4& view) {
    Mat4 inverse;
    if (!invert(view, inverse)) throw Error("render: the view matrix is singular (no eye position)");
    return cartesian(inverse * Vec4{0, 0, 0, 1});
}

FrameStats CullPipeline::render_frame(const PipelineParams& params) {
    Impl& m = *impl_;
    FrameParams frame = params.frame;
    frame.backpatch_culled = nullptr;
    frame.backpatch_buffer = 0;
    const bool backpatch = (static_cast<std::uint32_t>(frame.cull) & kFlagBackPatch) != 0;
    TimingMethod method = frame.timing;
    if (method == TimingMethod::automatic) method = m.software ? TimingMethod::wall_clock : TimingMethod::timer_query;

    double backpatch_ms = 0;
    if (backpatch && m.renderer.patch_count() > 0) {
        const RenderParams& rp = frame.render;
        const Mat4 object_to_clip = rp.projection * rp.view;
        const Vec3 eye = eye_of_view(rp.view);
        const float alpha = clip_space_eye_alpha(rp.projection);
        if (method == TimingMethod::wall_clock) {
            glFinish();
            const auto start = std::chrono::steady_clock::now();
            m.culler.cull(params.backpatch, object_to_clip, eye, alpha, params.ptp_rule);
            glFinish();
            backpatch_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        } else if (method == TimingMethod::timer_query) {
            if (!m.timer_query) glCreateQueries(GL_TIME_ELAPSED, 1, &m.timer_query);
            glBeginQuery(GL_TIME_ELAPSED, m.timer_query);
            m.culler.cull(params.backpatch, object_to_clip, eye, alpha, params.ptp_rule);
            glEndQuery(GL_TIME_ELAPSED);
        } else {
            m.culler.cull(params.backpatch, object_to_clip, eye, alpha, params.ptp_rule);
        }
        frame.backpatch_buffer = m.culler.flag_buffer();
    }
    FrameStats stats = m.renderer.render_frame(frame);
    if (backpatch && method == TimingMethod::timer_query && m.timer_query && m.renderer.patch_count() > 0) {
        GLuint64 ns = 0;
        glGetQueryObjectui64v(m.timer_query, GL_QUERY_RESULT, &ns);
        backpatch_ms = static_cast<double>(ns) * 1e-6;
    }
    detail::check_gl("CullPipeline::render_frame");
    stats.backpatch_ms = backpatch_ms;
    stats.cull_ms += backpatch_ms;
    stats.total_ms += backpatch_ms;
    return stats;
}

PatchRenderer& CullPipeline::renderer() { return impl_->renderer; }
const PatchRenderer& CullPipeline::renderer() const { return impl_->renderer; }
BackpatchCuller& CullPipeline::culler() { return impl_->culler; }

}  // namespace patchcull::gl
