// Niessner & Loop §6.2 on non-displaced models (occlusion_eval.h).
#include "patchcull/eval_gl/occlusion_eval.h"

#include <algorithm>
#include <vector>

#include "patchcull/eval_gl/reference_frame.h"
#include "patchcull/gl/gl_backpatch.h"

namespace patchcull::eval_gl {
namespace {

double fraction_culled(const std::vector<std::uint8_t>& culled) {
    if (culled.empty()) return 0;
    return double(std::count_if(culled.begin(), culled.end(), [](std::uint8_t c) { return c != 0; })) /
           double(culled.size());
}

}  // namespace

OcclusionEvalResult run_occlusion_eval(const LoadedModel& model, const OcclusionEvalOptions& o,
                                       const RunProgress& progress) {
    OcclusionEvalResult r;
    const std::size_t patches = model.rest.patches.size();
    r.patches = patches;

    gl::GlContext context = gl::GlContext::create_headless();
    gl::CullPipeline pipeline(context);
    gl::PatchAttributes attributes;  // refinement depths: osd patches meet without cracks
    for (const PatchInfo& info : model.rest.info) attributes.depth.push_back(info.depth);
    pipeline.set_patches(model.rest.patches, attributes);
    gl::BackpatchCuller culler(context);  // the back-patch fractions, on the pipeline's patches
    culler.use_patch_buffer(pipeline.renderer().patch_buffer(), patches);
    ViewGenerator views(patch_bounds(model.rest), ViewMode::contain, o.seed, float(o.width) / float(o.height));

    std::vector<std::uint8_t> culled;
    progress.begin(std::uint64_t(o.views));
    for (int v = 0; v < o.views; ++v) {
        const Camera camera = views.next();
        gl::PipelineParams params;
        params.frame.render = render_params(camera, o.width, o.height, o.tess, model.closed);
        params.frame.cull = gl::CullMode::occlusion;
        params.frame.timing = gl::TimingMethod::off;
        const ConvergedFrame converged = converge_frame(pipeline, params, o.max_frames);
        const gl::FrameStats& stats = converged.stats;
        if (!converged.stable) ++r.unstable_views;
        r.frames_sum += converged.frames;
        const double occluded = double(stats.occlusion_culled) / double(std::max<std::size_t>(patches, 1));
        r.occluded_sum += occluded;
        r.occluded_min = std::min(r.occluded_min, occluded);
        r.occluded_max = std::max(r.occluded_max, occluded);
        r.frustum_sum += double(stats.frustum_culled) / double(std::max<std::size_t>(patches, 1));
        const gl::FrameCapture culled_frame = capture_culled_frame(pipeline.renderer());
        const ReferenceFrame reference = render_reference(pipeline.renderer(), params.frame.render);
        r.false_culls += gl::compare_frames(reference.capture, culled_frame).false_culled.size();

        const gl::RenderParams& rp = params.frame.render;
        const Vec3 eye = gl::eye_of_view(rp.view);
        culler.cull(gl::BackpatchMethod::tcone, rp.projection * rp.view, eye, 0, PtpRule::ncnt, &culled);
        r.tcone_sum += fraction_culled(culled);
        culler.cull(gl::BackpatchMethod::ncone, rp.projection * rp.view, eye, 0, PtpRule::ncnt, &culled);
        r.ncone_sum += fraction_culled(culled);
        progress.done(std::uint64_t(v) + 1);
    }
    return r;
}

}  // namespace patchcull::eval_gl
