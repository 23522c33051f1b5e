// `patchcull eval temporal MODEL [--scheme acc|osd] [--speeds 0,2,5,10] [--frames N] [--size WxH]
// [--tess L] [--json]`: Fig. 9 right of Niessner & Loop, "Patch-Based Occlusion Culling for
// Hardware Tessellation" (Niessner & Loop §6.3, "Temporal Coherence"): the fraction of patches culled by
// occlusion against the camera's rotation speed, with the two-pass temporal-coherence pipeline
// (gl::CullPipeline, cull mode occlusion) running frame after frame.
//
// Static model, moving view: Niessner & Loop rotate the (non-displaced, not animated) BigGuy about its
// axis at each speed, "worst-case in terms of violating temporal visibility coherence"; a rigid
// rotation of the model before a fixed camera is the camera orbiting the still model, which is
// what runs here. The model is placed as make_model_scene places it (height 1, standing at the
// origin) and the camera follows that scene's orbit (the whole model in view, 30 degrees above
// the horizon, start angle 0) at `degrees_per_frame` = each speed, for --frames frames. No
// occluders: the ground quad of make_model_scene is left out, so every cull is the model hiding
// itself (culling within one object, as Niessner & Loop §6.2 and Fig. 9).
//
// Per speed the pipeline starts from a first frame (reset_visibility: half the patches tagged
// visible, Niessner & Loop §3); frame 0 primes the statuses, and occluded_fraction is the mean over
// frames 1..N-1 of occlusion_culled / patches. converged_occluded_fraction is the mean over the
// same views of the converged pipeline's fraction: a second CullPipeline runs each view from a
// first frame until its visible set is stable (converge_frame, as `eval occlusion`; at most 8
// frames), i.e. what the frame would cull without motion; the difference is the loss due to
// motion. Views repeated across frames and speeds (the same eye) are converged once.
// Every frame of the moving pipeline (frame 0 included) and every converged frame is compared with
// the unculled render of its view (render_reference / compare_frames): a patch of the unculled
// front set that was not drawn is a false cull; any false cull makes the exit status 1.
// Output (--json), one object:
//   {"model","scheme","patches","size":[w,h],"tess","frames",
//    "speeds":[{"degrees_per_frame","occluded_fraction","converged_occluded_fraction",
//               "frustum_fraction","false_culls"}],"false_culls"}
// frustum_fraction is the moving pipeline's mean frustum-culled fraction over frames 1..N-1 (0
// when the whole model stays in view).
#include "eval_temporal.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <iostream>
#include <map>

#include <nlohmann/json.hpp>

#include "cli_options.h"
#include "commands.h"
#include "patchcull/import/default_scene.h"
#include "patchcull/core/error.h"
#include "patchcull/gl/gl_verification.h"
#include "progress.h"
#include "render_support.h"

namespace patchcull::cli {
namespace {

constexpr int kMaxConvergeFrames = 8;  // `eval occlusion`'s default --max-frames

std::vector<bool> visible_set(const std::vector<std::uint32_t>& flags) {
    std::vector<bool> visible(flags.size());
    for (std::size_t p = 0; p < flags.size(); ++p) visible[p] = (flags[p] & gl::kStatusVisible) != 0;
    return visible;
}

}  // namespace

std::vector<double> parse_speeds(const std::string& flag, const std::string& text) {
    if (text.empty()) throw Error(flag + ": expected degrees per frame as a list such as 0,2,5,10, got ''");
    std::vector<double> speeds;
    std::size_t begin = 0;
    while (true) {
        const std::size_t comma = text.find(',', begin);
        const std::string item = text.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
        if (speeds.size() == kMaxSpeeds)
            throw Error(flag + ": at most " + std::to_string(kMaxSpeeds) + " speeds, got more in " + quote_input(text));
        if (item.empty()) throw Error(flag + ": empty item in " + quote_input(text));
        speeds.push_back(parse_real(flag, item, 0, 180));  // names the flag, quotes the item
        if (comma == std::string::npos) break;
        begin = comma + 1;
    }
    return speeds;
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

int run_temporal_eval(const TemporalEvalOptions& o) {
    int width = 0, height = 0;
    parse_size("--size", o.size, width, height);
    const std::vector<double> speeds = parse_speeds("--speeds", o.speeds);
    Scheme scheme = Scheme::acc;
    if (!parse_scheme(o.scheme, scheme)) throw Error("--scheme: unknown scheme '" + o.scheme + "'");
    if (o.model == "default")
        throw Error("MODEL: eval temporal takes one model (an OBJ path or 'teapot'), not the default scene");
    Scene scene = make_model_scene(load_model(o.model, scheme, 0));
    const LoadedModel& model = scene.models.front();
    print_warnings(model.warnings);
    const std::size_t patches = scene.patch_count();
    const double per_patch = 1.0 / double(std::max<std::size_t>(patches, 1));

    gl::GlContext context = gl::GlContext::create_headless();
    gl::CullPipeline moving(context);     // runs frame after frame along the orbit
    gl::CullPipeline converged(context);  // each view alone, until its visible set is stable
    ScenePoser poser(scene);
    const std::vector<BezierPatch>& rest = poser.pose(0);  // animate() at t = 0 is the rest pose
    const gl::PatchAttributes attributes = pose_attributes(poser);
    moving.set_patches(rest, attributes);
    converged.set_patches(rest, attributes);

    struct Converged {
        double occluded = 0;
    };
    std::map<std::array<float, 3>, Converged> converged_views;  // by eye position (all else equal)
    std::size_t unstable = 0;

    nlohmann::json rows = nlohmann::json::array();
    std::size_t total_false = 0;
    struct Row {
        double speed, occluded, converged, frustum;
        std::size_t false_culls;
    };
    std::vector<Row> table;
    Progress progress("eval temporal", "frames", std::uint64_t(speeds.size()) * std::uint64_t(o.frames),
                      progress_wanted(o.json));
    std::uint64_t frames_done = 0;
    for (double speed : speeds) {
        scene.camera.degrees_per_frame = static_cast<float>(speed);
        const std::vector<Camera> cameras = scene.camera_path(o.frames, float(width) / float(height));
        moving.reset_visibility();
        double occluded_sum = 0, converged_sum = 0, frustum_sum = 0;
        std::size_t false_culls = 0;
        for (int f = 0; f < o.frames; ++f) {
            const Camera& camera = cameras[static_cast<std::size_t>(f)];
            gl::PipelineParams params;
            params.frame.render = render_params(camera, width, height, o.tess, model.closed);
            params.frame.cull = gl::CullMode::occlusion;
            params.frame.timing = gl::TimingMethod::off;
            const gl::FrameStats stats = moving.render_frame(params);
            const gl::FrameCapture moving_frame = capture_culled_frame(moving.renderer());
            const ReferenceFrame reference = render_reference(moving.renderer(), params.frame.render);
            false_culls += gl::compare_frames(reference.capture, moving_frame).false_culled.size();
            if (f == 0) {  // primes the statuses
                progress.step(++frames_done);
                continue;
            }
            occluded_sum += double(stats.occlusion_culled) * per_patch;
            frustum_sum += double(stats.frustum_culled) * per_patch;

            const std::array<float, 3> eye{camera.eye.x, camera.eye.y, camera.eye.z};
            auto found = converged_views.find(eye);
            if (found == converged_views.end()) {
                const ConvergedFrame c = converge_frame(converged, params, kMaxConvergeFrames);
                if (!c.stable) ++unstable;
                false_culls += compare_with_reference(converged.renderer(), reference).false_culled.size();
                found = converged_views.emplace(eye, Converged{double(c.stats.occlusion_culled) * per_patch}).first;
            }
            converged_sum += found->second.occluded;
            progress.step(++frames_done);
        }
        const double n = std::max(o.frames - 1, 1);
        table.push_back({speed, occluded_sum / n, converged_sum / n, frustum_sum / n, false_culls});
        rows.push_back({{"degrees_per_frame", speed},
                        {"occluded_fraction", occluded_sum / n},
                        {"converged_occluded_fraction", converged_sum / n},
                        {"frustum_fraction", frustum_sum / n},
                        {"false_culls", false_culls}});
        total_false += false_culls;
    }
    if (unstable > 0)
        print_warnings({"eval temporal: " + std::to_string(unstable) + " views had no stable visible set after " +
                        std::to_string(kMaxConvergeFrames) + " frames (their last frame counts as converged)"});
    const std::string scheme_text = model.subdiv ? scheme_name(model.subdiv->scheme) : "bezier";
    if (o.json) {
        nlohmann::json out;
        out["model"] = model.name;
        out["scheme"] = scheme_text;
        out["patches"] = patches;
        out["size"] = {width, height};
        out["tess"] = o.tess;
        out["frames"] = o.frames;
        out["speeds"] = rows;
        out["false_culls"] = total_false;
        std::cout << out.dump() << "\n";
    } else {
        std::printf("%s (%s): %zu patches, %d frames per speed at %dx%d, level %d, cull occlusion\n",
                    model.name.c_str(), scheme_text.c_str(), patches, o.frames, width, height, o.tess);
        std::printf("  %9s  %9s  %9s  %9s  %6s  (mean over frames 1..%d)\n", "deg/frame", "occluded", "converged",
                    "frustum", "false", o.frames - 1);
        for (const Row& r : table)
            std::printf("  %9g  %8.2f%%  %8.2f%%  %8.2f%%  %6zu\n", r.speed, 100 * r.occluded, 100 * r.converged,
                        100 * r.frustum, r.false_culls);
    }
    // A false cull breaks the conservative promise: a failure, as in `render --verify`.
    return total_false > 0 ? 1 : 0;
}

}  // namespace patchcull::cli
