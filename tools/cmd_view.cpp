// `patchcull view [MODEL|default] ...`: the `render` pipeline (seed 000 §3 with seed 001's GPU
// back-patch pass) shown in a window: the same scene, camera path, PatchRenderer and CullPipeline
// as `render`, in a GlContext::create_window context instead of a headless one. Each frame's
// colour image is blitted to the window and swapped in; the camera path loops until the window
// is closed (or Escape), or stops after --frames frames. --screenshot writes the window's content
// after the last frame (tests run it under xvfb-run and compare it with `render --out`).
// --tess-mode / --tess-distance as `render` (render_support.h: TessOptions). --cull auto as
// `render` (cull_auto.h: per object and frame, culled where it pays); each frame's line is then
// followed by the policy's summary line.
#include <cstdio>
#include <memory>

#include "cli_options.h"
#include "commands.h"
#include "cull_auto.h"
#include "object_level_options.h"
#include "patchcull/default_scene.h"
#include "patchcull/error.h"
#include "render_support.h"

namespace patchcull::cli {

Runner add_view_command(CLI::App& app) {
    struct State {
        std::string model = "default";
        std::string scheme = "acc";
        int split = 0;
        int frames = 0;
        std::string cull = "all";
        std::string backpatch = "tcone";
        int tess = 8;
        TessOptions tess_options;
        DisplaceOptions displace;
        std::string size = "960x540";
        std::string screenshot;
        ObjectLevelOptions objects;
    };
    auto state = std::make_shared<State>();
    CLI::App* command = app.add_subcommand("view", "Show the GPU cull pipeline in a window (GLFW)");
    add_text_option(*command, "MODEL", state->model, "OBJ control mesh, 'teapot', a built-in scene ('default', 'city', 'building') or a scene file (.json)");
    add_choice_option(*command, "--scheme", state->scheme, {"acc", "osd"}, "Catmull-Clark to Bezier scheme");
    add_int_option(*command, "--split", state->split, 0, 4, "uniform 1-to-4 patch splits of MODEL");
    add_int_option(*command, "--frames", state->frames, 0, 1000000,
                   "stop after N frames (0: loop until the window is closed)");
    add_choice_option(*command, "--cull", state->cull, {"none", "frustum", "backpatch", "occlusion", "all", "auto"},
                      "cull tests of the pipeline (auto: all, per object where it pays, seed 000 §6.3)");
    add_choice_option(*command, "--backpatch", state->backpatch, {"tcone", "ncone", "ptp"},
                      "back-patch test of backpatch/all");
    add_int_option(*command, "--tess", state->tess, 1, 64, "tessellation level (adaptive: the maximum)");
    add_tess_options(*command, state->tess_options);
    add_displace_options(*command, state->displace);
    add_object_level_options(*command, state->objects);
    add_size_option(*command, "--size", state->size, "window size");
    add_output_file_option(*command, "--screenshot", state->screenshot,
                           "after the last frame, write the window's content as a PNG");
    return [state]() {
        int width = 0, height = 0;
        parse_size("--size", state->size, width, height);
        const bool automatic = state->cull == "auto";
        const gl::CullMode cull = automatic ? gl::CullMode::all : parse_cull_mode_option("--cull", state->cull);
        const gl::BackpatchMethod backpatch = parse_backpatch_method("--backpatch", state->backpatch);
        if (!state->screenshot.empty() && state->frames == 0)
            throw Error("--screenshot: needs --frames N (the last frame is the one saved)");
        Scene scene = load_scene(state->model, state->scheme, state->split);
        apply_displace_options(state->displace, scene);
        const TessMode tess_mode = resolve_tess_mode(state->tess_options, scene.camera);
        const gl::CullMode applied = applicable_cull_mode(scene, cull, "view");
        ObjectLevelRun object_level(state->objects, scene, scene_is_one_sided(scene));  // before the occluders go up

        gl::GlContext context = gl::GlContext::create_window(width, height, "patchcull view: " + scene.name);
        gl::CullPipeline pipeline(context);
        ScenePoser poser(scene);
        const std::vector<BezierPatch>& first_pose = poser.pose(0);  // before pose_attributes reads it
        pipeline.set_patches(first_pose, pose_attributes(poser));
        pipeline.renderer().set_displacement_map(scene.displacement);
        upload_scene_occluders(pipeline.renderer(), scene);
        // One lap of the camera path, repeated (the same cameras as `render --frames lap`).
        const int lap = state->frames > 0 ? state->frames : 72;
        const std::vector<Camera> cameras = scene.camera_path(lap, float(width) / float(height));
        std::vector<gl::ObjectRange> ranges;
        std::vector<std::string> names;
        for (const SceneObject& o : scene_objects(scene)) ranges.push_back(o.range), names.push_back(o.name);
        CullAutoPolicy policy(ranges, scene.patch_count());
        const std::vector<BezierPatch>* pose = &first_pose;
        for (int f = 0; state->frames == 0 || f < state->frames; ++f) {
            if (!context.window_open()) break;
            if (f > 0) {
                pose = &poser.pose(f * kSecondsPerFrame);
                pipeline.update_patches(*pose, pose_attributes(poser));
            }
            gl::PipelineParams params;
            params.frame.render = render_params(cameras[static_cast<std::size_t>(f % lap)], width, height, state->tess,
                                                scene_is_one_sided(scene));
            apply_tess_mode(tess_mode, params.frame.render);
            params.frame.cull = applied;
            params.backpatch = backpatch;
            params.bound = displace_bound(state->displace);
            params.cone = displace_cone(state->displace);
            object_level.apply(poser, *pose, f * kSecondsPerFrame, cameras[static_cast<std::size_t>(f % lap)], height,
                               params);
            if (automatic) {
                policy.decide(object_tess_factors(*pose, ranges, params.frame.render));
                params.objects = policy.objects();
                params.frame.cull = policy.frame_cull_mode(applied);
            }
            const gl::FrameStats stats = pipeline.render_frame(params);
            if (automatic) policy.observe(stats);
            pipeline.renderer().blit_color_to_window(width, height);
            const bool last = state->frames > 0 && f + 1 == state->frames;
            if (last && !state->screenshot.empty()) context.write_window_png(state->screenshot);
            context.swap_buffers();
            std::printf("frame %d: drawn %zu + %zu of %zu; culled frustum %zu, back-patch %zu, occlusion %zu "
                        "(displaced %zu); %.1f ms\n",
                        f, stats.pass1_drawn, stats.pass2_drawn, stats.patches, stats.frustum_culled,
                        stats.backpatch_culled, stats.occlusion_culled, stats.displaced_occlusion_culled,
                        stats.total_ms);
            if (automatic) std::printf("%s\n", auto_summary_line(names, policy.decisions()).c_str());
            if (object_level.enabled())
                std::printf("  objects (%s): %zu frustum-culled, %zu back-face-culled of %zu; %zu patches skipped\n",
                            object_level.method_name(), object_level.result().stats.frustum_culled,
                            object_level.result().stats.backface_culled, object_level.result().stats.total,
                            object_level.result().stats.patches_culled);
        }
        return 0;
    };
}

}  // namespace patchcull::cli
