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
// The run (eval_gl/temporal_eval.h): per speed the pipeline starts from a first frame; frame 0
// primes the statuses, and occluded_fraction is the mean over frames 1..N-1 of occlusion_culled /
// patches. converged_occluded_fraction is the mean over the same views of the converged
// pipeline's fraction (converge_frame, as `eval occlusion`; at most 8 frames), i.e. what the frame
// would cull without motion; the difference is the loss due to motion.
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

#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "cli_options.h"
#include "commands.h"
#include "eval_progress.h"
#include "patchcull/core/error.h"
#include "patchcull/eval_gl/temporal_eval.h"

namespace patchcull::cli {

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

int run_temporal_eval(const TemporalEvalOptions& o) {
    eval_gl::TemporalEvalOptions run;
    parse_size("--size", o.size, run.width, run.height);
    run.speeds = parse_speeds("--speeds", o.speeds);
    run.frames = o.frames;
    run.tess = o.tess;
    Scheme scheme = Scheme::acc;
    if (!parse_scheme(o.scheme, scheme)) throw Error("--scheme: unknown scheme '" + o.scheme + "'");
    if (o.model == "default")
        throw Error("MODEL: eval temporal takes one model (an OBJ path or 'teapot'), not the default scene");
    LoadedModel model = load_model(o.model, scheme, 0);
    print_warnings(model.warnings);
    EvalProgress progress("eval temporal", "frames", o.json);
    const eval_gl::TemporalEvalResult r = eval_gl::run_temporal_eval(std::move(model), run, progress.hooks());
    if (r.unstable_views > 0)
        print_warnings({"eval temporal: " + std::to_string(r.unstable_views) +
                        " views had no stable visible set after " + std::to_string(eval_gl::kTemporalConvergeFrames) +
                        " frames (their last frame counts as converged)"});
    if (o.json) {
        nlohmann::json rows = nlohmann::json::array();
        for (const eval_gl::TemporalSpeedRow& row : r.speeds)
            rows.push_back({{"degrees_per_frame", row.degrees_per_frame},
                            {"occluded_fraction", row.occluded_fraction},
                            {"converged_occluded_fraction", row.converged_occluded_fraction},
                            {"frustum_fraction", row.frustum_fraction},
                            {"false_culls", row.false_culls}});
        nlohmann::json out;
        out["model"] = r.model;
        out["scheme"] = r.scheme;
        out["patches"] = r.patches;
        out["size"] = {run.width, run.height};
        out["tess"] = o.tess;
        out["frames"] = o.frames;
        out["speeds"] = rows;
        out["false_culls"] = r.false_culls;
        std::cout << out.dump() << "\n";
    } else {
        std::printf("%s (%s): %zu patches, %d frames per speed at %dx%d, level %d, cull occlusion\n", r.model.c_str(),
                    r.scheme.c_str(), r.patches, o.frames, run.width, run.height, o.tess);
        std::printf("  %9s  %9s  %9s  %9s  %6s  (mean over frames 1..%d)\n", "deg/frame", "occluded", "converged",
                    "frustum", "false", o.frames - 1);
        for (const eval_gl::TemporalSpeedRow& row : r.speeds)
            std::printf("  %9g  %8.2f%%  %8.2f%%  %8.2f%%  %6zu\n", row.degrees_per_frame, 100 * row.occluded_fraction,
                        100 * row.converged_occluded_fraction, 100 * row.frustum_fraction, row.false_culls);
    }
    // A false cull breaks the conservative promise: a failure, as in `render --verify`.
    return r.false_culls > 0 ? 1 : 0;
}

}  // namespace patchcull::cli
