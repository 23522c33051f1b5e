// `patchcull eval ...`: the papers' evaluations, a subcommand group: `eval occlusion` (here),
// `eval displaced` (tools/eval/eval_displaced.cpp) and `eval temporal` (tools/eval/eval_temporal.cpp);
// `eval osd-cull` (tools/eval/eval_osd_cull.cpp): OpenSubdiv's own TCS culling beside patchcull's passes.
//
// `eval occlusion MODEL [--split N] [--views N] --json` reproduces Niessner & Loop §6.2 for non-displaced
// models (culling within one object): views that contain the whole object (camera.h, contain
// mode); on each view the pipeline (Niessner & Loop §3, cull mode occlusion) runs on the static model from
// a first frame until its visible set is stable (converge_frame, eval_gl/reference_frame.h; the run:
// eval_gl/occlusion_eval.h: two consecutive frames tag the same patches visible; at most
// --max-frames frames), and the occluded fraction of that frame is recorded. Every
// final frame is compared with the unculled render (false culls). For comparison with Niessner & Loop's
// back-patch figures it also reports the GPU tcone/ncone back-patch cull fractions of each view.
// Output (--json): {"model","scheme","split","patches","views","size","tess","seed",
//   "occluded_fraction" (mean over views),"occluded_fraction_min","occluded_fraction_max",
//   "frustum_fraction","backpatch_fraction":{"tcone","ncone"},"frames_mean","unstable_views",
//   "false_culls"}
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include <CLI/CLI.hpp>

#include "cli_options.h"
#include "commands.h"
#include "eval/eval_displaced.h"
#include "eval/eval_fused.h"
#include "eval/eval_osd_cull.h"
#include "eval/eval_progress.h"
#include "eval/eval_scene.h"
#include "eval/eval_temporal.h"
#include "patchcull/core/error.h"
#include "patchcull/eval_gl/occlusion_eval.h"

namespace patchcull::cli {
namespace {

struct OcclusionOptions {
    std::string model;
    std::string scheme = "acc";
    int split = 0;
    int views = 20;
    std::uint64_t seed = 1;
    std::string size = "512x512";
    int tess = 8;
    int max_frames = 8;
    bool json = false;
};

int run_occlusion(const OcclusionOptions& o) {
    eval_gl::OcclusionEvalOptions run;
    parse_size("--size", o.size, run.width, run.height);
    Scheme scheme = Scheme::acc;
    if (!parse_scheme(o.scheme, scheme)) throw Error("--scheme: unknown scheme '" + o.scheme + "'");
    const LoadedModel model = load_model(o.model, scheme, o.split);
    print_warnings(model.warnings);
    run.views = o.views;
    run.seed = o.seed;
    run.tess = o.tess;
    run.max_frames = o.max_frames;
    EvalProgress progress("eval occlusion", "views", o.json);
    const eval_gl::OcclusionEvalResult r = eval_gl::run_occlusion_eval(model, run, progress.hooks());
    const int width = run.width, height = run.height;
    const std::size_t patches = r.patches;
    const double n = std::max(o.views, 1);
    nlohmann::json out;
    out["model"] = model.name;
    out["scheme"] = model.subdiv ? scheme_name(model.subdiv->scheme) : "bezier";
    out["split"] = o.split;
    out["patches"] = patches;
    out["views"] = o.views;
    out["size"] = {width, height};
    out["tess"] = o.tess;
    out["seed"] = o.seed;
    out["occluded_fraction"] = r.occluded_sum / n;
    out["occluded_fraction_min"] = o.views ? r.occluded_min : 0.0;
    out["occluded_fraction_max"] = r.occluded_max;
    out["frustum_fraction"] = r.frustum_sum / n;
    out["backpatch_fraction"] = {{"tcone", r.tcone_sum / n}, {"ncone", r.ncone_sum / n}};
    out["frames_mean"] = r.frames_sum / n;
    out["unstable_views"] = r.unstable_views;
    out["false_culls"] = r.false_culls;
    if (o.json) {
        std::cout << out.dump() << "\n";
    } else {
        std::printf("%s: %zu patches, %d whole-object views at %dx%d, level %d\n", model.name.c_str(), patches, o.views,
                    width, height, o.tess);
        std::printf(
            "  occluded (Niessner & Loop §6.2): %.2f%% (min %.2f%%, max %.2f%%), %.1f frames to a stable "
            "visible set, %zu views unstable\n",
            100 * r.occluded_sum / n, 100 * (o.views ? r.occluded_min : 0.0), 100 * r.occluded_max, r.frames_sum / n,
            r.unstable_views);
        std::printf("  back-patch (GPU, same views): tcone %.2f%%, ncone %.2f%%; false culls %zu\n",
                    100 * r.tcone_sum / n, 100 * r.ncone_sum / n, r.false_culls);
    }
    return 0;
}

}  // namespace

Runner add_eval_command(CLI::App& app) {
    CLI::App* eval = app.add_subcommand(
        "eval", "Reproduce the papers' evaluations (eval occlusion, displaced, temporal, scene, fused, osd-cull)");
    // At most one; none is reported by the runner ("eval: expected a subcommand ..."), which names
    // the command, unlike CLI11's own message.
    eval->require_subcommand(0, 1);
    auto occlusion = std::make_shared<OcclusionOptions>();
    CLI::App* command = eval->add_subcommand(
        "occlusion", "Niessner & Loop §6.2: occluded fraction of a non-displaced model over whole-object views");
    add_text_option(*command, "MODEL", occlusion->model, "OBJ control mesh, or 'teapot'")->required();
    add_choice_option(*command, "--scheme", occlusion->scheme, {"acc", "osd"}, "Catmull-Clark to Bezier scheme");
    add_int_option(*command, "--split", occlusion->split, 0, 4, "uniform 1-to-4 patch splits");
    add_int_option(*command, "--views", occlusion->views, 1, 100000, "number of whole-object views");
    add_uint64_option(*command, "--seed", occlusion->seed, UINT64_MAX, "view generator seed");
    add_size_option(*command, "--size", occlusion->size, "framebuffer size");
    add_int_option(*command, "--tess", occlusion->tess, 1, 64, "uniform tessellation level");
    add_int_option(*command, "--max-frames", occlusion->max_frames, 2, 100, "frames per view at most");
    command->add_flag("--json", occlusion->json, "print one JSON object");

    auto displaced = std::make_shared<DisplacedEvalOptions>();
    CLI::App* displaced_command = eval->add_subcommand(
        "displaced", "Niessner & Loop, Table 1: cull rates of the six displaced-patch bounds over whole-object views");
    add_text_option(*displaced_command, "MODEL", displaced->model, "OBJ control mesh, or 'teapot'")->required();
    add_choice_option(*displaced_command, "--scheme", displaced->scheme, {"acc", "osd"},
                      "Catmull-Clark to Bezier scheme");
    add_int_option(*displaced_command, "--split", displaced->split, 0, 4, "uniform 1-to-4 patch splits");
    add_int_option(*displaced_command, "--views", displaced->views, 1, 100000, "number of whole-object views");
    add_uint64_option(*displaced_command, "--seed", displaced->seed, UINT64_MAX, "view generator seed");
    add_text_option(*displaced_command, "--displace", displaced->displace, "height map: a PNG file or 'procedural'");
    add_float_option(*displaced_command, "--displace-scale", displaced->displace_scale, 0, kMaxDisplaceScale,
                     "displacement of height 1 in object units (default 2% of the model's diagonal)");
    add_size_option(*displaced_command, "--size", displaced->size, "framebuffer size");
    add_int_option(*displaced_command, "--tess", displaced->tess, 1, 64, "uniform tessellation level");
    add_clip_depth_option(*displaced_command, displaced->clip_depth);
    displaced_command->add_flag("--json", displaced->json, "print one JSON object");

    auto temporal = std::make_shared<TemporalEvalOptions>();
    CLI::App* temporal_command = eval->add_subcommand(
        "temporal",
        "Niessner & Loop, Fig. 9 right: occluded fraction of the running pipeline against the camera's rotation speed");
    add_text_option(*temporal_command, "MODEL", temporal->model, "OBJ control mesh, or 'teapot'")->required();
    add_choice_option(*temporal_command, "--scheme", temporal->scheme, {"acc", "osd"},
                      "Catmull-Clark to Bezier scheme");
    temporal_command
        ->add_option_function<std::string>(
            "--speeds",
            [temporal](const std::string& text) {
                parse_speeds("--speeds", text);  // throws naming --speeds
                temporal->speeds = text;
            },
            "camera rotation speeds in degrees per frame, comma-separated (1.." + std::to_string(kMaxSpeeds) +
                " values in 0..180)")
        ->type_name("LIST")
        ->default_str(temporal->speeds);
    add_int_option(*temporal_command, "--frames", temporal->frames, 2, 10000,
                   "frames per speed (frame 0 primes the statuses)");
    add_size_option(*temporal_command, "--size", temporal->size, "framebuffer size");
    add_int_option(*temporal_command, "--tess", temporal->tess, 1, 64, "uniform tessellation level");
    temporal_command->add_flag("--json", temporal->json, "print one JSON object");

    auto scene = std::make_shared<SceneEvalOptions>();
    CLI::App* scene_command = eval->add_subcommand(
        "scene",
        "Object-level occlusion (queries, CHC, CHC++, horizon, portals) beside per-patch Hi-Z on a scene's path");
    add_text_option(*scene_command, "SCENE", scene->scene,
                    "a built-in scene (city, building, default), a scene file (.json), or a model (OBJ or teapot) as "
                    "render takes it")
        ->required();
    add_choice_option(*scene_command, "--scheme", scene->scheme, {"acc", "osd"}, "Catmull-Clark to Bezier scheme");
    add_int_option(*scene_command, "--frames", scene->frames, 1, 10000, "frames of the scene's camera path");
    add_size_option(*scene_command, "--size", scene->size, "framebuffer size");
    add_int_option(*scene_command, "--tess", scene->tess, 1, 64, "uniform tessellation level");
    add_text_option(*scene_command, "--methods", scene->methods,
                    "comma list of methods (default: all the scene allows; 'none' is always run)");
    add_int_option(*scene_command, "--batch", scene->batch, 1, 1024, "batched and CHC++ I-queue batch size b");
    add_float_option(*scene_command, "--sigma", scene->sigma, 1, 16, "CHC++ tight bounding volumes' area factor");
    add_int_option(*scene_command, "--max-tight-boxes", scene->max_tight_boxes, 1, 256, "CHC++ tight boxes per object");
    add_float_option(*scene_command, "--c1", scene->c1, 0, 100, "CHC++ multiquery cost per object, C(M) = 1 + c1 |M|");
    add_int_option(*scene_command, "--visible-interval", scene->visible_interval, 1, 100,
                   "CHC++: previously visible objects queried every N frames");
    scene_command->add_flag("--json", scene->json, "print one JSON object");

    auto fused = std::make_shared<FusedEvalOptions>();
    CLI::App* fused_command = eval->add_subcommand(
        "fused", "The fused CPU cull kernel's fixed plans against its cost model on a scene's path");
    add_text_option(*fused_command, "SCENE", fused->scene,
                    "a built-in scene (city, building, default), a scene file (.json), or a model (OBJ or teapot) as "
                    "render takes it")
        ->required();
    add_choice_option(*fused_command, "--scheme", fused->scheme, {"acc", "osd"}, "Catmull-Clark to Bezier scheme");
    add_int_option(*fused_command, "--frames", fused->frames, 1, 10000, "frames of the scene's camera path");
    add_size_option(*fused_command, "--size", fused->size, "framebuffer size (the depth that feeds the Hi-Z pyramid)");
    add_int_option(*fused_command, "--tess", fused->tess, 1, 64,
                   "uniform tessellation level of the unculled render (the check)");
    add_int_option(*fused_command, "--repeats", fused->repeats, 1, 1000,
                   "timed runs per object, plan and frame (minimum kept)");
    add_int_option(*fused_command, "--profile-interval", fused->profile_interval, 1, 10000,
                   "frames between an object's profiling runs (cost model)");
    add_choice_option(*fused_command, "--cone", fused->cone, {"tcone", "ncone"}, "the back-patch cone test");
    add_clip_depth_option(*fused_command, fused->clip_depth);
    fused_command->add_flag("--json", fused->json, "print one JSON object");

    auto osd_cull = std::make_shared<OsdCullEvalOptions>();
    CLI::App* osd_cull_command = eval->add_subcommand(
        "osd-cull",
        "OpenSubdiv's own TCS frustum culling (OSD_ENABLE_PATCH_CULL) beside patchcull's passes on OpenSubdiv's patch "
        "table: patches tessellated and frame time");
    add_text_option(*osd_cull_command, "MODEL", osd_cull->model, "OBJ control mesh or a shipped model ('bigguy')")
        ->required();
    add_int_option(*osd_cull_command, "--level", osd_cull->level, 1, 4, "adaptive isolation level");
    add_int_option(*osd_cull_command, "--tess", osd_cull->tess, 1, 16, "OpenSubdiv's uniform tessellation level");
    add_size_option(*osd_cull_command, "--size", osd_cull->size, "framebuffer size");
    add_int_option(*osd_cull_command, "--rounds", osd_cull->rounds, 1, 1000,
                   "timed rounds per view (one frame of each mode)");
    add_int_option(*osd_cull_command, "--warmup", osd_cull->warmup, 0, 100, "untimed rounds per view first");
    return [command, occlusion, displaced_command, displaced, temporal_command, temporal, scene_command, scene,
            fused_command, fused, osd_cull_command, osd_cull]() {
        if (command->parsed()) return run_occlusion(*occlusion);
        if (displaced_command->parsed()) return run_displaced_eval(*displaced);
        if (temporal_command->parsed()) return run_temporal_eval(*temporal);
        if (scene_command->parsed()) return run_scene_eval(*scene);
        if (fused_command->parsed()) return run_fused_eval(*fused);
        if (osd_cull_command->parsed()) return run_osd_cull_eval(*osd_cull);
        throw Error(
            "eval: expected a subcommand: occlusion, displaced, temporal, scene, fused or osd-cull (e.g. patchcull "
            "eval occlusion MODEL --json)");
    };
}

}  // namespace patchcull::cli
