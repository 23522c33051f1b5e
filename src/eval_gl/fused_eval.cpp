// The fused CPU cull kernel's plans against its cost model (fused_eval.h).
//
// The Hi-Z pyramid holds the occluders alone (the environment's triangles): a patch tested
// against a depth buffer holding its own fragments can be culled by itself, since those may lie a
// few ulps in front of its control points' zmin (hiz.h's precision note; the running pipeline
// never draws a patch only after testing it against its own depth). So the Hi-Z stage here culls
// what the occluders hide, not what patches hide. Displaced instances are left out: the fused
// kernel has no displacement margins, like the cone and Hi-Z kernels.
#include "patchcull/eval_gl/fused_eval.h"

#include <algorithm>
#include <chrono>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/fused_cost_model.h"
#include "patchcull/core/hiz.h"
#include "patchcull/eval_gl/reference_frame.h"
#include "patchcull/eval_gl/scene_setup.h"
#include "patchcull/gl/gl_cull_flags.h"
#include "patchcull/import/scene_poser.h"

namespace patchcull::eval_gl {
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

FusedEvalResult run_fused_eval(const Scene& scene, const FusedEvalOptions& o, const RunProgress& progress) {
    const int width = o.width, height = o.height;
    const BackPatchCone cone = o.cone;
    const bool one_sided = scene_is_one_sided(scene);

    gl::GlContext context = gl::GlContext::create_headless();
    gl::PatchRenderer renderer(context);
    ScenePoser poser(scene);
    const std::vector<BezierPatch>& first_pose = poser.pose(0);  // before its attributes are read
    renderer.set_patches(first_pose, pose_attributes(poser));
    renderer.set_displacement_map(scene.displacement);
    upload_scene_occluders(renderer, scene);
    std::vector<Camera> cameras = scene.camera_path(o.frames, float(width) / float(height));
    for (Camera& c : cameras) c.depth = o.clip_depth;  // drawn and culled in it

    FusedEvalResult r;
    std::vector<gl::ObjectRange> fused;  // the objects the fused kernel may cull
    const std::vector<SceneObject> objects = scene_objects(scene);
    for (const SceneObject& so : objects)
        if (!instance_displaced(poser.displacement_ranges(), so.range)) {
            fused.push_back(so.range);
            r.fused_patches += so.range.count;
        }
    r.scene = scene.name;
    r.objects = objects.size();
    r.fused_objects = fused.size();
    r.patches = scene.patch_count();

    FusedPlan fixed[6];
    const int fixed_count = fused_plans_of(kAllFusedStages, fixed);
    for (int p = 0; p < fixed_count; ++p) r.plan_names.push_back(fused_plan_name(fixed[p]));
    FusedCostModel::Config config;
    config.profile_interval = o.profile_interval;
    FusedCostModel model(fused.size(), config);

    r.plan_seconds.assign(static_cast<std::size_t>(fixed_count), 0.0);
    std::vector<std::uint8_t> decision, scratch, scratch2;
    std::vector<bool> shown;
    const std::vector<std::uint8_t> all_culled(scene.patch_count(), 1);
    HiZPyramid hiz;
    progress.begin(static_cast<std::uint64_t>(o.frames));
    for (int f = 0; f < o.frames; ++f) {
        const std::vector<BezierPatch>& pose = poser.pose(static_cast<float>(f) * o.seconds_per_frame);
        renderer.update_patches(pose, pose_attributes(poser));
        const Camera& camera = cameras[static_cast<std::size_t>(f)];
        gl::RenderParams params = render_params(camera, width, height, o.tess, one_sided);
        // The pyramid: the occluders alone (every patch flagged culled), so that no patch is
        // tested against its own depth (seen once in 48 city frames).
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
        const FusedCullSetup setup =
            make_fused_setup(params.projection * params.view, camera.depth, camera.eye, cone, &hiz);
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
                r.plan_seconds[static_cast<std::size_t>(p)] += times[static_cast<std::size_t>(p)];
                if (p == 0 || times[static_cast<std::size_t>(p)] < best) best = times[static_cast<std::size_t>(p)];
            }
            r.oracle_seconds += best;
            // Decisions of the first fixed plan (FBH): counts and the strict check.
            cull_fused_simd(view, setup, fixed[0], decision.data());
            for (std::size_t p = 0; p < view.count; ++p) {
                ++r.culled[decision[p]];
                if (decision[p] != kFusedVisible && shown[fused[i].first + p]) {
                    if (++r.false_culls <= 10) {
                        // What the Hi-Z test saw, and the patch's own depth where the frame shows it.
                        PatchScreenBounds b;
                        const bool projectable = patch_screen_bounds(view, p, params.projection * params.view,
                                                                     camera.depth, width, height, b);
                        const std::vector<float> frame_depth = renderer.read_depth();
                        float own = 2;
                        for (std::size_t px = 0; px < ids.size(); ++px)
                            if (ids[px] == fused[i].first + p + 1) own = std::min(own, frame_depth[px]);
                        r.first_false_culls.push_back({f, fused[i].first + p, i, decision[p],
                                                       projectable ? b.zmin : -1.0f,
                                                       projectable ? hiz_rect_max(hiz, b.rect) : -1.0f, own});
                    }
                }
            }
            // The model.
            const FusedPlan plan = model.choose(i, kAllFusedStages);
            ++r.choices[fused_plan_name(plan)];
            double t = 0;
            if (model.should_profile(i, kAllFusedStages)) {
                FusedProfile profile;
                t = min_seconds(o.repeats, [&] {
                    profile = FusedProfile{};
                    cull_fused_profile_simd(view, setup, plan, scratch.data(), profile);
                });
                model.observe_profile(i, kAllFusedStages, profile, view.count);
                r.profile_seconds += t;
                ++r.profiled;
            } else {
                FusedCullStats stats;
                t = min_seconds(o.repeats, [&] {
                    stats = FusedCullStats{};
                    cull_fused_simd(view, setup, plan, scratch.data(), &stats);
                });
                model.observe(i, plan, stats);
            }
            r.model_seconds += t;
            for (int p = 0; p < fixed_count; ++p)
                if (fused_plan_name(fixed[p]) == fused_plan_name(plan) &&
                    times[static_cast<std::size_t>(p)] <= best * 1.03)
                    ++r.agreements;
            ++r.object_frames;
            // The separate kernels.
            r.separate_seconds += min_seconds(o.repeats, [&] {
                (cone == BackPatchCone::tcone ? cull_tcone_simd : cull_ncone_simd)(view, camera.eye, scratch.data());
                cull_occlusion_simd(view, params.projection * params.view, camera.depth, hiz, scratch2.data());
            });
        }
        model.next_frame();
        progress.done(static_cast<std::uint64_t>(f) + 1);
    }
    return r;
}

}  // namespace patchcull::eval_gl
