// The frames an evaluation run compares (reference_frame.h).
#include "patchcull/eval_gl/reference_frame.h"

#include <chrono>
#include <utility>
#include <vector>

#include "patchcull/gl/gl_cull_flags.h"

namespace patchcull::eval_gl {
namespace {

std::vector<bool> visible_set(const std::vector<std::uint32_t>& flags) {
    std::vector<bool> visible(flags.size());
    for (std::size_t p = 0; p < flags.size(); ++p) visible[p] = (flags[p] & gl::kStatusVisible) != 0;
    return visible;
}

}  // namespace

gl::RenderParams render_params(const Camera& camera, int width, int height, int tess_level, bool one_sided) {
    gl::RenderParams params;
    params.discard_back_facing = one_sided;
    params.view = camera.view();
    params.projection = camera.projection();
    params.depth = camera.depth;
    params.width = width;
    params.height = height;
    params.tess_level = tess_level;
    return params;
}

ReferenceFrame render_reference(gl::PatchRenderer& renderer, const gl::RenderParams& params) {
    gl::RenderParams unculled = params;
    unculled.use_cull_flags = false;
    renderer.finish();
    const auto start = std::chrono::steady_clock::now();
    renderer.render(unculled);
    renderer.finish();
    ReferenceFrame reference;
    reference.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    reference.capture.ids = renderer.read_ids();
    reference.capture.depth = renderer.read_depth();
    reference.capture.patches = renderer.mark_front_patches(unculled);
    return reference;
}

gl::FrameCapture capture_culled_frame(const gl::PatchRenderer& renderer) {
    return {renderer.read_ids(), renderer.read_depth(), renderer.read_drawn_patches()};
}

gl::FrameComparison compare_with_reference(const gl::PatchRenderer& renderer, const ReferenceFrame& reference) {
    return gl::compare_frames(reference.capture, capture_culled_frame(renderer));
}

ConvergedFrame converge_frame(gl::CullPipeline& pipeline, const gl::PipelineParams& params, int max_frames) {
    ConvergedFrame result;
    pipeline.reset_visibility();
    std::vector<bool> previous;
    while (result.frames < max_frames && !result.stable) {
        result.stats = pipeline.render_frame(params);
        ++result.frames;
        std::vector<bool> visible = visible_set(pipeline.renderer().read_cull_flags());
        result.stable = visible == previous;
        previous = std::move(visible);
    }
    return result;
}

}  // namespace patchcull::eval_gl
