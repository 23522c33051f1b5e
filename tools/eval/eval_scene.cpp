// `patchcull eval scene SCENE [--scheme acc|osd] [--frames N] [--size WxH] [--tess L]
// [--methods LIST] [--batch B] [--sigma S] [--max-tight-boxes K] [--c1 C] [--visible-interval N]
// [--json]`: a comparison of object-level occlusion culling (G. Zachmann's lecture
// "Advanced Visibility Computations"; Bittner et al.'s CHC, Mattausch et al.'s CHC++; Downs et
// al.'s occlusion horizons; Luebke & Georges' portals) with patchcull's per-patch Hi-Z culling
// (Niessner & Loop, "Patch-Based Occlusion Culling for Hardware Tessellation").
//
// SCENE is a built-in scene (city, building, default), a scene file, or a model as `render` takes it
// (make_model_scene: the model on a ground quad, no box occluders). The run: eval_gl/scene_eval.h.
// Every method runs the
// scene's camera path (frames 0..N-1, the animation at kSecondsPerFrame) from a first frame:
//   none                the unculled frame (the ratios' denominator);
//   hiz                 patchcull alone: cull mode occlusion (frustum + Hi-Z per patch), no object level;
//   M, M+hiz            object method M alone (cull mode none) and followed by patchcull's patch
//                       passes (cull mode occlusion) on the objects it lets through, for M in
//                       stop-and-wait, batched, chc, chc++ (hardware queries on the characters,
//                       gl_object_queries.h; the environment's triangles are drawn first as
//                       occluders) and horizon (scenes with box occluders) and portals (scenes
//                       with cells) (scene_occlusion.h, after the object level's BVH frustum test).
// Per method and frame the frame is compared with the unculled render of the same view (strict:
// a patch of its front set not drawn, or a culled occluder triangle in its id buffer, is a false
// cull); any false cull of a conservative method makes the exit status 1.
// Times: wall clock around glFinish() per pass (gl_pipeline.h; serialises the passes, as on
// llvmpipe), plus the method's CPU work before the frame (object boxes, horizon or portal
// traversal, tight boxes); frame_ratio = the method's mean frame time over none's.
// Output (--json): {"scene","scheme","objects","characters","patches","frames","size":[w,h],"tess","batch",
//   "sigma","c1","visible_interval","methods":[{"name","object_method","patch_hiz",
//   "objects_culled","objects_hidden","patches_hidden","patches_culled","patches_object_culled","patches_frustum_culled",
//   "patches_occlusion_culled","queries","multiqueries","multiqueries_passed","proxy_boxes",
//   "wait_frames","waits","ms":{"object_cpu","pass1","hiz","cull","pass2","frame"},
//   "frame_ratio","false_culls"}]} with per-frame means (wait_frames and false_culls: totals;
//   objects_culled: the characters (queries) or all objects (horizon, portals) left out by the
//   object level, frustum included; objects_hidden / patches_hidden: those the occlusion method
//   itself hid (inside the frustum) and their patches; patches_culled: every patch not drawn,
//   object level and patch passes together).
#include "eval_scene.h"

#include <cmath>
#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "cli_options.h"
#include "commands.h"
#include "eval_progress.h"
#include "patchcull/eval_gl/scene_eval.h"
#include "patchcull/import/scene_file.h"
#include "render_support.h"

namespace patchcull::cli {
namespace {

// "a,b" -> {"a", "b"} (an empty item kept: the run names it); "" -> {} (every method).
std::vector<std::string> split_methods(const std::string& list) {
    std::vector<std::string> names;
    if (list.empty()) return names;
    std::size_t begin = 0;
    while (true) {
        const std::size_t comma = list.find(',', begin);
        names.push_back(list.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin));
        if (comma == std::string::npos) break;
        begin = comma + 1;
    }
    return names;
}

}  // namespace

int run_scene_eval(const SceneEvalOptions& o) {
    eval_gl::SceneEvalOptions run;
    parse_size("--size", o.size, run.width, run.height);
    Scene scene = load_scene(o.scene, o.scheme, 0);
    place_scene_at_first_camera(scene, o.scene, o.frames, kSecondsPerFrame);
    run.frames = o.frames;
    run.seconds_per_frame = kSecondsPerFrame;
    run.tess = o.tess;
    run.methods = split_methods(o.methods);
    run.batch = o.batch;
    run.sigma = o.sigma;
    run.max_tight_boxes = o.max_tight_boxes;
    run.c1 = o.c1;
    run.visible_interval = o.visible_interval;
    EvalProgress progress("eval scene", "frames", o.json);
    const eval_gl::SceneEvalResult r = eval_gl::run_scene_eval(std::move(scene), run, progress.hooks());
    progress.finish();
    nlohmann::json rows = nlohmann::json::array();
    for (const eval_gl::SceneEvalRow& row : r.rows)
        rows.push_back({{"name", row.name},
                        {"object_method", row.object_method},
                        {"patch_hiz", row.patch_hiz},
                        {"objects_culled", row.objects_culled},
                        {"objects_hidden", row.objects_hidden},
                        {"patches_hidden", row.patches_hidden},
                        {"patches_culled", row.patches_culled},
                        {"patches_object_culled", row.patches_object_culled},
                        {"patches_frustum_culled", row.patches_frustum_culled},
                        {"patches_occlusion_culled", row.patches_occlusion_culled},
                        {"queries", row.queries},
                        {"multiqueries", row.multiqueries},
                        {"multiqueries_passed", row.multiqueries_passed},
                        {"proxy_boxes", row.proxy_boxes},
                        {"wait_frames", row.wait_frames},
                        {"waits", row.waits},
                        {"ms",
                         {{"object_cpu", row.ms_object_cpu},
                          {"pass1", row.ms_pass1},
                          {"hiz", row.ms_hiz},
                          {"cull", row.ms_cull},
                          {"pass2", row.ms_pass2},
                          {"frame", row.ms_frame}}},
                        {"frame_ratio", row.frame_ratio},
                        {"false_culls", row.false_culls}});
    const int width = run.width, height = run.height;
    nlohmann::json out = {{"scene", r.scene},
                          {"scheme", o.scheme},
                          {"objects", r.objects},
                          {"characters", r.characters},
                          {"patches", r.patches},
                          {"frames", o.frames},
                          {"size", {width, height}},
                          {"tess", o.tess},
                          {"batch", o.batch},
                          // The float flags as given (1.4, not 1.39999997...).
                          {"sigma", std::round(double(o.sigma) * 1e6) / 1e6},
                          {"c1", std::round(double(o.c1) * 1e6) / 1e6},
                          {"visible_interval", o.visible_interval},
                          {"methods", rows}};
    if (o.json) {
        std::cout << out.dump() << "\n";
    } else {
        std::printf("%s: %zu characters, %zu patches, %d frames at %dx%d, tess %d\n", r.scene.c_str(), r.characters,
                    r.patches, o.frames, width, height, o.tess);
        std::printf("%-18s %9s %10s %9s %8s %7s %9s %7s %6s\n", "method", "objects", "patches", "queries", "multi",
                    "waits", "frame ms", "ratio", "false");
        for (const eval_gl::SceneEvalRow& row : r.rows)
            std::printf("%-18s %9.1f %10.0f %9.1f %8.1f %7d %9.2f %7.2f %6d\n", row.name.c_str(), row.objects_culled,
                        row.patches_culled, row.queries, row.multiqueries, int(row.wait_frames), row.ms_frame,
                        row.frame_ratio, int(row.false_culls));
    }
    return r.false_culls == 0 ? 0 : 1;
}

}  // namespace patchcull::cli
