// Fig. 9 right of Niessner & Loop (temporal_eval.h).
//
// A rigid rotation of the model before a fixed camera is the camera orbiting the still model,
// which is what runs here: the model is placed as make_model_scene places it (height 1, standing
// at the origin) and the camera follows that scene's orbit (the whole model in view, 30 degrees
// above the horizon, start angle 0) at degrees_per_frame = each speed. The ground quad is left out.
// Per speed the pipeline starts from a first frame (reset_visibility); frame 0 primes the
// statuses. converged_occluded_fraction: a second CullPipeline runs each view from a first frame
// until its visible set is stable, i.e. what the frame would cull without motion.
#include "patchcull/eval_gl/temporal_eval.h"

#include <algorithm>
#include <array>
#include <map>
#include <utility>

#include "patchcull/eval_gl/reference_frame.h"
#include "patchcull/eval_gl/scene_setup.h"
#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/scene_poser.h"

namespace patchcull::eval_gl {

TemporalEvalResult run_temporal_eval(LoadedModel loaded, const TemporalEvalOptions& o, const RunProgress& progress) {
    Scene scene = make_model_scene(std::move(loaded));
    const LoadedModel& model = scene.models.front();
    TemporalEvalResult result;
    result.model = model.name;
    result.scheme = model.subdiv ? scheme_name(model.subdiv->scheme) : "bezier";
    const std::size_t patches = scene.patch_count();
    result.patches = patches;
    const double per_patch = 1.0 / double(std::max<std::size_t>(patches, 1));

    gl::GlContext context = gl::GlContext::create_headless();
    gl::CullPipeline moving(context);     // runs frame after frame along the orbit
    gl::CullPipeline converged(context);  // each view alone, until its visible set is stable
    ScenePoser poser(scene);
    const std::vector<BezierPatch>& rest = poser.pose(0);  // animate() at t = 0 is the rest pose
    const gl::PatchAttributes attributes = pose_attributes(poser);
    moving.set_patches(rest, attributes);
    converged.set_patches(rest, attributes);

    std::map<std::array<float, 3>, double> converged_views;  // occluded fraction by eye (all else equal)
    progress.begin(std::uint64_t(o.speeds.size()) * std::uint64_t(o.frames));
    std::uint64_t frames_done = 0;
    for (double speed : o.speeds) {
        scene.camera.degrees_per_frame = static_cast<float>(speed);
        const std::vector<Camera> cameras = scene.camera_path(o.frames, float(o.width) / float(o.height));
        moving.reset_visibility();
        double occluded_sum = 0, converged_sum = 0, frustum_sum = 0;
        std::size_t false_culls = 0;
        for (int f = 0; f < o.frames; ++f) {
            const Camera& camera = cameras[static_cast<std::size_t>(f)];
            gl::PipelineParams params;
            params.frame.render = render_params(camera, o.width, o.height, o.tess, model.closed);
            params.frame.cull = gl::CullMode::occlusion;
            params.frame.timing = gl::TimingMethod::off;
            const gl::FrameStats stats = moving.render_frame(params);
            const gl::FrameCapture moving_frame = capture_culled_frame(moving.renderer());
            const ReferenceFrame reference = render_reference(moving.renderer(), params.frame.render);
            false_culls += gl::compare_frames(reference.capture, moving_frame).false_culled.size();
            if (f == 0) {  // primes the statuses
                progress.done(++frames_done);
                continue;
            }
            occluded_sum += double(stats.occlusion_culled) * per_patch;
            frustum_sum += double(stats.frustum_culled) * per_patch;

            const std::array<float, 3> eye{camera.eye.x, camera.eye.y, camera.eye.z};
            auto found = converged_views.find(eye);
            if (found == converged_views.end()) {
                const ConvergedFrame c = converge_frame(converged, params, kTemporalConvergeFrames);
                if (!c.stable) ++result.unstable_views;
                false_culls += compare_with_reference(converged.renderer(), reference).false_culled.size();
                found = converged_views.emplace(eye, double(c.stats.occlusion_culled) * per_patch).first;
            }
            converged_sum += found->second;
            progress.done(++frames_done);
        }
        const double n = std::max(o.frames - 1, 1);
        result.speeds.push_back({speed, occluded_sum / n, converged_sum / n, frustum_sum / n, false_culls});
        result.false_culls += false_culls;
    }
    return result;
}

}  // namespace patchcull::eval_gl
