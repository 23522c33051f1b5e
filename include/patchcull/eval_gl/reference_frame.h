// The frames an evaluation run compares: render parameters from a camera, the unculled reference
// frame of the current patches and its comparison with a culled one (gl::compare_frames), and the
// pipeline's frame repeated until its visible set is stable.
#pragma once

#include "patchcull/core/camera.h"
#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/gl/gl_verification.h"

namespace patchcull::eval_gl {

/// The camera's view, projection and depth convention at width x height, uniform level
/// tess_level; one_sided: RenderParams::discard_back_facing (the scene's models all closed).
gl::RenderParams render_params(const Camera& camera, int width, int height, int tess_level, bool one_sided);

/// The unculled render of the current patches (every patch drawn, flags ignored, statuses kept),
/// its front set (PatchRenderer::mark_front_patches) and the wall-clock time of the render alone
/// (glFinish before and after; the front-set pass is not timed).
struct ReferenceFrame {
    gl::FrameCapture capture;
    double ms = 0;
};
ReferenceFrame render_reference(gl::PatchRenderer& renderer, const gl::RenderParams& params);

/// The renderer's last frame as compare_frames takes a culled frame: ids, depth, drawn patches.
gl::FrameCapture capture_culled_frame(const gl::PatchRenderer& renderer);

/// Compares the renderer's current framebuffer (a culled frame) with a reference.
gl::FrameComparison compare_with_reference(const gl::PatchRenderer& renderer, const ReferenceFrame& reference);

/// A frame of the pipeline repeated from a first frame until its visible set is stable.
struct ConvergedFrame {
    gl::FrameStats stats;  ///< of the last frame run
    int frames = 0;        ///< frames run
    bool stable = false;   ///< the last two frames tagged the same patches visible
};

/// Niessner & Loop §3's pipeline on a static view as `eval occlusion` runs it: reset_visibility (the
/// next frame is a first frame, half the patches tagged visible), then params' frame again and
/// again until two consecutive frames tag the same patches visible (kStatusVisible), at most
/// max_frames frames. The renderer's framebuffer then holds the last frame.
ConvergedFrame converge_frame(gl::CullPipeline& pipeline, const gl::PipelineParams& params, int max_frames);

}  // namespace patchcull::eval_gl
