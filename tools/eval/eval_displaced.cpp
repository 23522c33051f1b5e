// `patchcull eval displaced MODEL [--split N] [--views N] [--displace FILE.png|procedural]
// [--displace-scale X] --json`: Niessner & Loop's Table 1 (§4.2, §6.2): cull rates of the six bounds of a
// displaced patch, {oobb, caf} x {full, acon, con} (patchcull/core/displaced_bounds.h), by the frustum
// and by occlusion inside the object, over views that contain the whole object.
//
// The run (eval_gl/displaced_eval.h), per view (camera.h, contain mode): the displaced model is rendered unculled (GPU,
// the renderer's TES displaces along the unit normal of the patch's own derivatives, as the bounds assume); its depth
// buffer gives the CPU Hi-Z pyramid (hiz.h), which is what Niessner & Loop §3's pipeline converges to on a static view
// (its visible set stable); each bound is then tested against the frustum and that pyramid (cull_displaced_occlusion).
// A patch culled although its id is in the unculled id buffer is a false cull. Next to these converged-depth rates, the
// running pipeline's (temporal coherence, Niessner & Loop §3): per view and combination, CullPipeline::render_frame
// (frustum + occlusion; the displaced patches tested by DisplacedPass against the pipeline's own Hi-Z, built from the
// patches the previous frame found visible) from a first frame until its visible set is stable (at most 8 frames), its
// last frame compared with the unculled render (render_reference: a false cull is judged per
// patch). Output (--json):
//   {"model","clip_depth","patches","views","displace","displace_scale","size","tess","seed",
//    "rows":[{"bound":"oobb"|"caf","cone":"full"|"acon"|"con","cull_rate":0..1,"false_culls":n,
//             "pipeline_cull_rate":0..1,"pipeline_frames":mean,"pipeline_false_culls":n}, ...]}
// with one row per combination (cull_rate, pipeline_cull_rate: the mean over views of the culled
// fraction).
#include "eval_displaced.h"

#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "cli_options.h"
#include "commands.h"
#include "eval_progress.h"
#include "patchcull/eval_gl/displaced_eval.h"

namespace patchcull::cli {

int run_displaced_eval(const DisplacedEvalOptions& o) {
    eval_gl::DisplacedEvalOptions run;
    parse_size("--size", o.size, run.width, run.height);
    ModelOptions model_options;
    model_options.model = o.model;
    model_options.scheme = o.scheme;
    model_options.split = o.split;
    model_options.displace = o.displace;
    model_options.displace_scale = o.displace_scale;
    const LoadedModel model = load_model_from_options(model_options);
    print_warnings(model.warnings);
    const DisplacementMap map = displacement_from_options(model_options, model);
    run.views = o.views;
    run.seed = o.seed;
    run.tess = o.tess;
    run.clip_depth = parse_clip_depth_option(o.clip_depth);
    EvalProgress progress("eval displaced", "view-bounds", o.json);
    const eval_gl::DisplacedEvalResult r = eval_gl::run_displaced_eval(model, map, run, progress.hooks());
    const int width = run.width, height = run.height;
    if (o.json) {
        nlohmann::json out;
        out["model"] = model.name;
        out["clip_depth"] = clip_depth_name(run.clip_depth);
        out["patches"] = r.patches;
        out["views"] = o.views;
        out["displace"] = o.displace;
        out["displace_scale"] = map.scale;
        out["size"] = {width, height};
        out["tess"] = o.tess;
        out["seed"] = o.seed;
        out["rows"] = nlohmann::json::array();
        for (const eval_gl::DisplacedEvalRow& row : r.rows)
            out["rows"].push_back({{"bound", displaced_bound_name(row.bound)},
                                   {"cone", normal_cone_name(row.cone)},
                                   {"cull_rate", row.rate_sum / o.views},
                                   {"false_culls", row.false_culls},
                                   {"pipeline_cull_rate", row.pipeline_rate_sum / o.views},
                                   {"pipeline_frames", row.pipeline_frames_sum / o.views},
                                   {"pipeline_false_culls", row.pipeline_false_culls}});
        std::cout << out.dump() << "\n";
    } else {
        std::printf("%s: %zu patches, %d whole-object views at %dx%d, level %d, displacement %s (scale %g)\n",
                    model.name.c_str(), r.patches, o.views, width, height, o.tess, o.displace.c_str(), map.scale);
        for (const eval_gl::DisplacedEvalRow& row : r.rows)
            std::printf(
                "  %-4s %-4s  cull rate %6.2f%%  false culls %zu   running pipeline %6.2f%% (%.1f frames), "
                "false culls %zu\n",
                displaced_bound_name(row.bound), normal_cone_name(row.cone), 100 * row.rate_sum / o.views,
                row.false_culls, 100 * row.pipeline_rate_sum / o.views, row.pipeline_frames_sum / o.views,
                row.pipeline_false_culls);
    }
    return r.false_culls() > 0 ? 1 : 0;  // a false cull breaks the conservative promise, as in `render --verify`
}

}  // namespace patchcull::cli
