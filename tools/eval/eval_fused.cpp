// `patchcull eval fused SCENE [--scheme acc|osd] [--frames N] [--size WxH] [--tess L] [--repeats R]
// [--profile-interval K] [--cone tcone|ncone] [--json]`: a measurement of the fused CPU
// cull kernel (fused_cull.h) and of the cost model that picks its plan per object and frame
// (fused_cost_model.h), on a scene's camera path.
//
// Per frame: the scene is posed (the animation at kSecondsPerFrame), its occluders (the
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
#include <chrono>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <map>

#include <nlohmann/json.hpp>

#include "cli_options.h"
#include "commands.h"
#include "patchcull/core/backpatch.h"
#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/fused_cost_model.h"
#include "patchcull/core/fused_cull.h"
#include "patchcull/core/hiz.h"
#include "patchcull/import/scene_file.h"
#include "progress.h"
#include "render_support.h"

namespace patchcull::cli {
namespace {

using Clock = std::chrono::steady_clock;

// The minimum over repeats of run()'s wall time, in seconds.
template <class Run>
double min_seconds(int repeats, const Run& run) {
    double best = 0;
    for (int r = 0; r < repeats; ++r) {
        const Clock::time_point start = Clock::now();
        run();
        const double s = std::chrono::duration<double>(Clock::now() - start).count();
        if (r == 0 || s < best) best = s;
    }
    return best;
}

bool instance_displaced(const std::vector<DisplacementRange>& ranges, const gl::ObjectRange& range) {
    if (ranges.empty()) return false;
    for (std::size_t p = range.first; p < range.first + range.count; ++p)
        if (ranges[p].max_abs() > 0) return true;
    return false;
}

}  // namespace

int run_fused_eval(const FusedEvalOptions& o) {
    int width = 0, height = 0;
    parse_size("--size", o.size, width, height);
    const BackPatchCone cone = o.cone == "ncone" ? BackPatchCone::ncone : BackPatchCone::tcone;
    Scene scene = load_scene(o.scene, o.scheme, 0);
    place_scene_at_first_camera(scene, o.scene, o.frames, kSecondsPerFrame);
    const bool one_sided = scene_is_one_sided(scene);

    gl::GlContext context = gl::GlContext::create_headless();
    gl::PatchRenderer renderer(context);
    ScenePoser poser(scene);
    renderer.set_patches(poser.pose(0), pose_attributes(poser));
    renderer.set_displacement_map(scene.displacement);
    upload_scene_occluders(renderer, scene);
    std::vector<Camera> cameras = scene.camera_path(o.frames, float(width) / float(height));
    const ClipDepth clip_depth = parse_clip_depth_option(o.clip_depth);
    for (Camera& c : cameras) c.depth = clip_depth;  // drawn and culled in it

    std::vector<gl::ObjectRange> fused;  // the objects the fused kernel may cull
    const std::vector<SceneObject> objects = scene_objects(scene);
    std::size_t fused_patches = 0;
    for (const SceneObject& so : objects)
        if (!instance_displaced(poser.displacement_ranges(), so.range)) {
            fused.push_back(so.range);
            fused_patches += so.range.count;
        }

    FusedPlan fixed[6];
    const int fixed_count = fused_plans_of(kAllFusedStages, fixed);
    FusedCostModel::Config config;
    config.profile_interval = o.profile_interval;
    FusedCostModel model(fused.size(), config);

    std::vector<double> plan_seconds(static_cast<std::size_t>(fixed_count), 0.0);
    double model_seconds = 0, profile_seconds = 0, oracle_seconds = 0, separate_seconds = 0;
    std::size_t agreements = 0, object_frames = 0, profiled = 0, false_culls = 0;
    std::size_t culled[4] = {};
    std::map<std::string, std::size_t> choices;

    std::vector<std::uint8_t> decision, scratch, scratch2;
    std::vector<bool> shown;
    const std::vector<std::uint8_t> all_culled(scene.patch_count(), 1);
    HiZPyramid hiz;
    Progress progress("eval fused", "frames", static_cast<std::uint64_t>(o.frames), progress_wanted(o.json));
    for (int f = 0; f < o.frames; ++f) {
        const std::vector<BezierPatch>& pose = poser.pose(static_cast<float>(f) * kSecondsPerFrame);
        renderer.update_patches(pose, pose_attributes(poser));
        const Camera& camera = cameras[static_cast<std::size_t>(f)];
        gl::RenderParams params = render_params(camera, width, height, o.tess, one_sided);
        // The pyramid: the occluders alone (every patch flagged culled), so that no patch is
        // tested against its own depth (its fragments may lie a few ulps in front of its control
        // points' zmin: hiz.h's precision note; seen once in 48 city frames).
        renderer.set_cull_flags(all_culled.data());
        params.use_cull_flags = true;
        renderer.render(params);
        const std::vector<float> depth = renderer.read_depth_bottom_up();  // hiz.h's row order
        // The truth: the unculled frame's id buffer.
        params.use_cull_flags = false;
        renderer.render(params);
        const std::vector<std::uint32_t> ids = renderer.read_ids();
        hiz.build(depth.data(), width, height, camera.depth);
        shown.assign(pose.size(), false);
        for (std::uint32_t id : ids)
            if (id != 0 && (id & gl::kIdOccluderBit) == 0 && id <= pose.size()) shown[id - 1] = true;

        const PatchBatch batch = make_batch(pose);
        const FusedCullSetup setup = make_fused_setup(params.projection * params.view, camera.depth,
                                                      camera.eye, cone, &hiz);
        for (std::size_t i = 0; i < fused.size(); ++i) {
            const PatchBatchView view = batch.view().subrange(fused[i].first, fused[i].count);
            decision.resize(view.count);
            scratch.resize(view.count);
            scratch2.resize(view.count);
            double best = 0;
            std::vector<double> times(static_cast<std::size_t>(fixed_count));
            for (int p = 0; p < fixed_count; ++p) {
                times[static_cast<std::size_t>(p)] =
                    min_seconds(o.repeats, [&] { cull_fused_simd(view, setup, fixed[p], decision.data()); });
                plan_seconds[static_cast<std::size_t>(p)] += times[static_cast<std::size_t>(p)];
                if (p == 0 || times[static_cast<std::size_t>(p)] < best) best = times[static_cast<std::size_t>(p)];
            }
            oracle_seconds += best;
            // Decisions of the first fixed plan (FBH): counts and the strict check.
            cull_fused_simd(view, setup, fixed[0], decision.data());
            for (std::size_t p = 0; p < view.count; ++p) {
                ++culled[decision[p]];
                if (decision[p] != kFusedVisible && shown[fused[i].first + p]) {
                    if (++false_culls <= 10) {
                        // What the Hi-Z test saw, and the patch's own depth where the frame shows it.
                        PatchScreenBounds b;
                        const bool projectable = patch_screen_bounds(view, p, params.projection * params.view,
                                                                     camera.depth, width, height, b);
                        const std::vector<float> frame_depth = renderer.read_depth();
                        float own = 2;
                        for (std::size_t px = 0; px < ids.size(); ++px)
                            if (ids[px] == fused[i].first + p + 1) own = std::min(own, frame_depth[px]);
                        std::cerr << std::setprecision(9) << "eval fused: false cull: frame " << f << ", patch " << fused[i].first + p
                                  << " (object " << i << "), culled by "
                                  << (decision[p] == kFusedFrustumCulled ? "frustum"
                                      : decision[p] == kFusedOccluded ? "occlusion" : "backpatch")
                                  << "; zmin " << (projectable ? b.zmin : -1.0f) << ", pyramid max "
                                  << (projectable ? hiz_rect_max(hiz, b.rect) : -1.0f) << ", its own nearest depth " << own
                                  << "\n";
                    }
                }
            }
            // The model.
            const FusedPlan plan = model.choose(i, kAllFusedStages);
            ++choices[fused_plan_name(plan)];
            double t = 0;
            if (model.should_profile(i, kAllFusedStages)) {
                FusedProfile profile;
                t = min_seconds(o.repeats, [&] {
                    profile = FusedProfile{};
                    cull_fused_profile_simd(view, setup, plan, scratch.data(), profile);
                });
                model.observe_profile(i, kAllFusedStages, profile, view.count);
                profile_seconds += t;
                ++profiled;
            } else {
                FusedCullStats stats;
                t = min_seconds(o.repeats, [&] {
                    stats = FusedCullStats{};
                    cull_fused_simd(view, setup, plan, scratch.data(), &stats);
                });
                model.observe(i, plan, stats);
            }
            model_seconds += t;
            for (int p = 0; p < fixed_count; ++p)
                if (fused_plan_name(fixed[p]) == fused_plan_name(plan) && times[static_cast<std::size_t>(p)] <= best * 1.03)
                    ++agreements;
            ++object_frames;
            // The separate kernels.
            separate_seconds += min_seconds(o.repeats, [&] {
                (cone == BackPatchCone::tcone ? cull_tcone_simd : cull_ncone_simd)(view, camera.eye, scratch.data());
                cull_occlusion_simd(view, params.projection * params.view, camera.depth, hiz, scratch2.data());
            });
        }
        model.next_frame();
        progress.step(static_cast<std::uint64_t>(f + 1));
    }

    const double frames = static_cast<double>(o.frames);
    double best_fixed = plan_seconds[0];
    std::string best_plan = fused_plan_name(fixed[0]);
    for (int p = 1; p < fixed_count; ++p)
        if (plan_seconds[static_cast<std::size_t>(p)] < best_fixed) {
            best_fixed = plan_seconds[static_cast<std::size_t>(p)];
            best_plan = fused_plan_name(fixed[p]);
        }
    auto ratio = [&](double s) { return best_fixed > 0 ? s / best_fixed : 0.0; };
    const double counted = static_cast<double>(std::max<std::size_t>(1, culled[0] + culled[1] + culled[2] + culled[3]));

    nlohmann::json out;
    out["scene"] = scene.name;
    out["clip_depth"] = clip_depth_name(clip_depth);
    out["scheme"] = o.scheme;
    out["target"] = simd_target_name();
    out["objects"] = objects.size();
    out["fused_objects"] = fused.size();
    out["patches"] = scene.patch_count();
    out["fused_patches"] = fused_patches;
    out["frames"] = o.frames;
    out["size"] = {width, height};
    out["tess"] = o.tess;
    out["repeats"] = o.repeats;
    out["profile_interval"] = o.profile_interval;
    out["cone"] = o.cone;
    out["culled"] = {{"frustum", double(culled[kFusedFrustumCulled]) / counted},
                     {"backpatch", double(culled[kFusedBackPatchCulled]) / counted},
                     {"occlusion", double(culled[kFusedOccluded]) / counted},
                     {"visible", double(culled[kFusedVisible]) / counted}};
    nlohmann::json plans = nlohmann::json::array();
    for (int p = 0; p < fixed_count; ++p)
        plans.push_back({{"plan", fused_plan_name(fixed[p])},
                         {"seconds", plan_seconds[static_cast<std::size_t>(p)] / frames},
                         {"ratio_to_best", ratio(plan_seconds[static_cast<std::size_t>(p)])}});
    out["plans"] = plans;
    out["best_plan"] = best_plan;
    nlohmann::json chosen = nlohmann::json::object();
    for (const auto& [name, n] : choices) chosen[name] = n;
    out["model"] = {{"seconds", model_seconds / frames},
                    {"profile_seconds", profile_seconds / frames},
                    {"ratio_to_best", ratio(model_seconds)},
                    {"ratio_to_oracle", oracle_seconds > 0 ? model_seconds / oracle_seconds : 0.0},
                    {"agreement", object_frames ? double(agreements) / double(object_frames) : 0.0},
                    {"profiled", profiled},
                    {"choices", chosen}};
    out["oracle"] = {{"seconds", oracle_seconds / frames}, {"ratio_to_best", ratio(oracle_seconds)}};
    out["separate"] = {{"seconds", separate_seconds / frames}, {"ratio_to_best", ratio(separate_seconds)}};
    out["false_culls"] = false_culls;
    if (o.json) {
        std::cout << out.dump() << "\n";
    } else {
        std::printf("eval fused: %s, %zu of %zu objects (%zu patches), %d frames, %s\n", scene.name.c_str(), fused.size(),
                    objects.size(), fused_patches, o.frames, simd_target_name());
        for (const auto& row : plans)
            std::printf("  plan %-4s %10.1f us/frame  x%.3f\n", row["plan"].get<std::string>().c_str(),
                        row["seconds"].get<double>() * 1e6, row["ratio_to_best"].get<double>());
        std::printf("  model     %10.1f us/frame  x%.3f (profiling %.1f us, agreement %.2f)\n", model_seconds / frames * 1e6,
                    ratio(model_seconds), profile_seconds / frames * 1e6,
                    object_frames ? double(agreements) / double(object_frames) : 0.0);
        std::printf("  oracle    %10.1f us/frame  x%.3f\n", oracle_seconds / frames * 1e6, ratio(oracle_seconds));
        std::printf("  separate  %10.1f us/frame  x%.3f\n", separate_seconds / frames * 1e6, ratio(separate_seconds));
        std::printf("  false culls: %zu\n", false_culls);
    }
    return false_culls == 0 ? 0 : 1;
}

}  // namespace patchcull::cli
