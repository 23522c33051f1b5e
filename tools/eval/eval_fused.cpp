// `patchcull eval fused SCENE [--scheme acc|osd] [--frames N] [--size WxH] [--tess L] [--repeats R]
// [--profile-interval K] [--cone tcone|ncone] [--json]`: a measurement of the fused CPU
// cull kernel (fused_cull.h) and of the cost model that picks its plan per object and frame
// (fused_cost_model.h), on a scene's camera path.
//
// The run (eval_gl/fused_eval.h), per frame: the scene is posed (the animation at kSecondsPerFrame), its occluders (the
// environment's triangles: walls, pillars, buildings, ground) are drawn on the GPU (llvmpipe here)
// at --size, and that depth becomes the CPU Hi-Z pyramid. Patches are not in it: a patch tested
// against a depth buffer holding its own fragments can be culled by itself, since those may lie a
// few ulps in front of its control points' zmin (hiz.h's precision note; the running pipeline
// never draws a patch only after testing it against its own depth). So the Hi-Z stage here culls
// what the occluders hide, not what patches hide. Then the frame is drawn unculled at --tess for
// the id buffer. Then, for every object (an instance's patch range; displaced
// instances are left out: the fused kernel has no displacement margins, like the cone and Hi-Z
// kernels), on one core, each measured as the minimum of --repeats runs:
//   plans      every fixed plan with all three tests, FBH, FHB, BFH (F frustum, B back-patch cone,
//              H Hi-Z; same decisions, so the same patches drawn), the same plan for all objects;
//   model      FusedCostModel's choice per object and frame, its profiling runs included (an
//              object's first frame and every --profile-interval frames, staggered);
//   oracle     per object and frame the fastest fixed plan as measured (a lower bound no model
//              can beat without knowing the times in advance);
//   separate   the separate SIMD kernels on the same patches, cull_tcone_simd and
//              cull_occlusion_simd (which runs the frustum test itself): what the fused kernel
//              replaces.
// Every culled patch is checked against the unculled frame's id buffer: a patch that shows there
// but was culled is a false cull (one line on stderr each, up to 10, with what the Hi-Z test saw);
// any makes the exit status 1.
// Output (--json), one object, times in seconds per frame (sums over the objects, mean over frames):
//   {"scene","clip_depth","scheme","target","objects","fused_objects","patches","fused_patches","frames",
//    "size":[w,h],"tess","repeats","profile_interval","cone",
//    "culled":{"frustum","backpatch","occlusion","visible"} (fractions of fused_patches, plan FBH),
//    "plans":[{"plan","seconds","ratio_to_best"}], "best_plan",
//    "model":{"seconds","profile_seconds","ratio_to_best","ratio_to_oracle","agreement","profiled",
//             "choices":{"FBH":n,...}},
//    "oracle":{"seconds","ratio_to_best"}, "separate":{"seconds","ratio_to_best"},
//    "false_culls"}
// ratio_to_best divides by the best fixed plan's seconds; agreement is the fraction of
// object-frames in which the model ran the plan that measured fastest (ties within 3% count).
#include "eval_fused.h"

#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <iostream>

#include <nlohmann/json.hpp>

#include "cli_options.h"
#include "commands.h"
#include "eval_progress.h"
#include "patchcull/core/frustum.h"
#include "patchcull/eval_gl/fused_eval.h"
#include "patchcull/import/scene_file.h"
#include "render_support.h"

namespace patchcull::cli {
namespace {

void print_false_cull(const eval_gl::FusedFalseCull& c) {
    std::cerr << std::setprecision(9) << "eval fused: false cull: frame " << c.frame << ", patch " << c.patch
              << " (object " << c.object << "), culled by "
              << (c.decision == kFusedFrustumCulled ? "frustum"
                  : c.decision == kFusedOccluded    ? "occlusion"
                                                    : "backpatch")
              << "; zmin " << c.zmin << ", pyramid max " << c.pyramid_max << ", its own nearest depth " << c.own_depth
              << "\n";
}

}  // namespace

int run_fused_eval(const FusedEvalOptions& o) {
    eval_gl::FusedEvalOptions run;
    parse_size("--size", o.size, run.width, run.height);
    run.cone = o.cone == "ncone" ? BackPatchCone::ncone : BackPatchCone::tcone;
    Scene scene = load_scene(o.scene, o.scheme, 0);
    place_scene_at_first_camera(scene, o.scene, o.frames, kSecondsPerFrame);
    run.frames = o.frames;
    run.seconds_per_frame = kSecondsPerFrame;
    run.tess = o.tess;
    run.repeats = o.repeats;
    run.profile_interval = o.profile_interval;
    run.clip_depth = parse_clip_depth_option(o.clip_depth);
    EvalProgress progress("eval fused", "frames", o.json);
    const eval_gl::FusedEvalResult r = eval_gl::run_fused_eval(scene, run, progress.hooks());
    for (const eval_gl::FusedFalseCull& c : r.first_false_culls) print_false_cull(c);

    const double frames = static_cast<double>(o.frames);
    const std::size_t fixed_count = r.plan_seconds.size();
    double best_fixed = r.plan_seconds[0];
    std::string best_plan = r.plan_names[0];
    for (std::size_t p = 1; p < fixed_count; ++p)
        if (r.plan_seconds[p] < best_fixed) {
            best_fixed = r.plan_seconds[p];
            best_plan = r.plan_names[p];
        }
    auto ratio = [&](double s) { return best_fixed > 0 ? s / best_fixed : 0.0; };
    const double counted =
        static_cast<double>(std::max<std::size_t>(1, r.culled[0] + r.culled[1] + r.culled[2] + r.culled[3]));

    nlohmann::json out;
    out["scene"] = r.scene;
    out["clip_depth"] = clip_depth_name(run.clip_depth);
    out["scheme"] = o.scheme;
    out["target"] = simd_target_name();
    out["objects"] = r.objects;
    out["fused_objects"] = r.fused_objects;
    out["patches"] = r.patches;
    out["fused_patches"] = r.fused_patches;
    out["frames"] = o.frames;
    out["size"] = {run.width, run.height};
    out["tess"] = o.tess;
    out["repeats"] = o.repeats;
    out["profile_interval"] = o.profile_interval;
    out["cone"] = o.cone;
    out["culled"] = {{"frustum", double(r.culled[kFusedFrustumCulled]) / counted},
                     {"backpatch", double(r.culled[kFusedBackPatchCulled]) / counted},
                     {"occlusion", double(r.culled[kFusedOccluded]) / counted},
                     {"visible", double(r.culled[kFusedVisible]) / counted}};
    nlohmann::json plans = nlohmann::json::array();
    for (std::size_t p = 0; p < fixed_count; ++p)
        plans.push_back({{"plan", r.plan_names[p]},
                         {"seconds", r.plan_seconds[p] / frames},
                         {"ratio_to_best", ratio(r.plan_seconds[p])}});
    out["plans"] = plans;
    out["best_plan"] = best_plan;
    nlohmann::json chosen = nlohmann::json::object();
    for (const auto& [name, n] : r.choices) chosen[name] = n;
    const double agreement = r.object_frames ? double(r.agreements) / double(r.object_frames) : 0.0;
    out["model"] = {{"seconds", r.model_seconds / frames},
                    {"profile_seconds", r.profile_seconds / frames},
                    {"ratio_to_best", ratio(r.model_seconds)},
                    {"ratio_to_oracle", r.oracle_seconds > 0 ? r.model_seconds / r.oracle_seconds : 0.0},
                    {"agreement", agreement},
                    {"profiled", r.profiled},
                    {"choices", chosen}};
    out["oracle"] = {{"seconds", r.oracle_seconds / frames}, {"ratio_to_best", ratio(r.oracle_seconds)}};
    out["separate"] = {{"seconds", r.separate_seconds / frames}, {"ratio_to_best", ratio(r.separate_seconds)}};
    out["false_culls"] = r.false_culls;
    if (o.json) {
        std::cout << out.dump() << "\n";
    } else {
        std::printf("eval fused: %s, %zu of %zu objects (%zu patches), %d frames, %s\n", r.scene.c_str(),
                    r.fused_objects, r.objects, r.fused_patches, o.frames, simd_target_name());
        for (const auto& row : plans)
            std::printf("  plan %-4s %10.1f us/frame  x%.3f\n", row["plan"].get<std::string>().c_str(),
                        row["seconds"].get<double>() * 1e6, row["ratio_to_best"].get<double>());
        std::printf("  model     %10.1f us/frame  x%.3f (profiling %.1f us, agreement %.2f)\n",
                    r.model_seconds / frames * 1e6, ratio(r.model_seconds), r.profile_seconds / frames * 1e6,
                    agreement);
        std::printf("  oracle    %10.1f us/frame  x%.3f\n", r.oracle_seconds / frames * 1e6, ratio(r.oracle_seconds));
        std::printf("  separate  %10.1f us/frame  x%.3f\n", r.separate_seconds / frames * 1e6,
                    ratio(r.separate_seconds));
        std::printf("  false culls: %zu\n", r.false_culls);
    }
    return r.false_culls == 0 ? 0 : 1;
}

}  // namespace patchcull::cli
