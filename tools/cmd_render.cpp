// `patchcull render [MODEL|default] ... --json`: Niessner & Loop §3's GPU pipeline (with Loop,
// Niessner & Eisenacher's GPU back-patch pass) over an animated scene and a moving camera,
// optionally verified frame by frame against the unculled render (compare_frames: a patch
// visible unculled but culled is a false cull). Output (--json), one object:
//   {"api","model","patch_source","patches","size":[w,h],"tess","tess_mode","cull","backpatch","aggressive","verified",
//    "displace","displace_scale","displaced_patches","bound","cone","frustum",
//    "frames":[{"frame","pass1_drawn","pass2_drawn","frustum_culled","backpatch_culled",
//               "occlusion_culled","displaced_occlusion_culled","visible","newly_visible","submitted",
//               "ms":{"pass1","hiz","cull","pass2",
//               "total"[,"reference"]},"false_culls"[,"false_culled_patches":[indices]]}],
//    "false_culls"}
// --dump-hiz DIR adds "hiz_dump" (hiz.json's object) and --draw-bounds P[,P...] adds
// "draw_bounds" (one object per patch): tools/render_dumps.h (Niessner & Loop, Figs. 3 and 6).
// Without --verify nothing is compared: every false_culls is 0 and "verified" is false. Patch
// indices are positions in the scene's pose (instances in order, each in its model's order).
// "backpatch" is "off" when no back-patch test ran (--cull none/frustum/occlusion, or `all` on a
// scene with an open surface, see applicable_cull_mode). "tess_mode" is "uniform" (--tess on every
// patch) or "adaptive" (--tess-mode adaptive: tessellation by distance, Niessner & Loop §6.3, "tess" is
// the maximum; render_options.h's resolve_tess_mode gives the reference distance). "displace" is
// the scene's map ("none", "procedural" or the PNG path; the default scene displaces its
// MonsterFrogs), "displaced_patches" the patches with a nonzero displacement range; displaced
// patches are culled by the frustum and the running pipeline's Hi-Z with the bound ("caf" or
// "oobb") and cone ("full", "acon", "con") of Niessner & Loop §4.2, and never by back-patch tests;
// "displaced_occlusion_culled" counts those of "occlusion_culled" that are displaced.
// --frustum hull|aabb (gl_pipeline.h's FrustumTest; "frustum" in the JSON): the frustum test of the
// chain, hull (Niessner & Loop: the control points, the default) or aabb (Sathe: the control
// points' box grown by max |D|, which also bounds the displaced patches against the frustum).
// --cull auto (cull_auto_policy.h: Niessner & Loop §6.3's per-object switch): each object of the scene
// (eval_gl/scene_setup.h scene_objects: one per instance) is culled with the tests of `all` (back-patch
// only where applicable_cull_mode allows) or drawn whole, decided per frame from the measured pass
// costs, its recent cull rate and its tessellation factor; "cull" is "auto" and every frame gains
//   "auto_objects":[{"name","patches","culling":"on"|"off","break_even","cull_rate"}]
// (break_even: x = (RT0 + CT) / (RT - RT0) at the object's tess factor, null until the costs are
// measured or when there is no tessellation cost to save; cull_rate: the object's average rate the
// decision used, null until measured). Without --json a line per frame says how many objects are
// culled, and why each is on or off.
// --objects frustum|bvh|bvh+backface (object_level_options.h): the object level runs
// before the patch passes (instances and environment objects; culled ones cost no patch work);
// every frame (also with the default --objects none: zeros) gains
//   "objects":{"total","frustum_culled","backface_culled","detail_culled","plane_tests",
//              "bvh_nodes_visited","cluster_tests","patches_culled","triangles_culled",
//              "backface_patches_culled"}
// (with --verify also "false_culled_objects", "false_culled_triangles", "detail_pixels"; "ms" gains
// "object_level" and "cpu_frustum_after_objects", CPU wall-clock times outside "total"), and
// "false_culls" counts object-level false culls too (culled patches and environment triangles
// in the unculled id buffer); --detail-cull's changes are reported as detail_pixels, not false culls.
// --fused-pass: the frustum, back-patch and Hi-Z tests in one FusedCullPass dispatch per
// object (gl_pipeline.h's PipelineParams::fused_pass; same decisions); "fused_pass" in the JSON is
// the flag, each frame's "fused_pass" whether the fused pass ran (not with --backpatch ptp or
// --frustum aabb, which keep the separate passes).
// --pose cpu|gpu (frame_poser.h's PoseWhere): where each frame's animated patches
// are evaluated: cpu (the default: ScenePoser on the CPU, every patch and attribute re-uploaded)
// or gpu (only the control meshes go up, gl_posing.h's StencilPoser evaluates the stencils into
// the renderer's buffers, bit-identical). "pose" in the JSON is the flag; every frame gains
//   "pose":{"where","cpu_patches","cpu_ms","done_ms","meshes_ms","bytes_uploaded"}
// (cpu_patches: the CPU posed patches this frame, which gpu does only for a CPU reader: the object
// level, --cull auto, --draw-bounds, and frame 0, whose upload brings the attributes; cpu_ms: CPU
// time of posing and uploading; done_ms: until glFinish returns; meshes_ms: of cpu_ms, animating
// the control meshes (gpu); bytes_uploaded: bytes copied to GL).
// --draw flags|indirect ("draw" in the JSON; gl_pipeline.h's DrawMode): how the draw passes issue
// patches: indirect (the default: CompactPass lists each pass's survivors and indirect draws issue
// only those) or flags (every patch of the drawn objects; the TCS gives the culled ones levels 0). Every
// frame gains "submitted":{"pass1","pass2"}: the patches each draw pass issued (pass2 0 in one
// pass and when aggressive). --patch-source osd-table draws with the flags unless --draw indirect
// is given (render_osd_table.h).
// --compact scan|append ("compact"): how --draw indirect lists the survivors (render_options.h).
// --driver-threads spread|os ("driver_threads", and "pinned_driver_threads": how many were pinned):
// on a software rasterizer, each thread the driver starts pinned to a CPU of its own (the default),
// or left to the operating system (core/thread_placement.h).
// --api gl|vulkan ("api"): the OpenGL pipeline above, or the same frames on patchcull's headless
// Vulkan renderer (render_vulkan.h: one object, posed on the CPU; --vk-validation, --vk-device).
// --patch-source bezier|osd-table ("patch_source" in the JSON): bezier (the default) draws the
// scheme's Bezier patches through the pipeline above; osd-table (with --scheme osd, a single OBJ
// model) draws the model's OpenSubdiv patch table with OpenSubdiv's own GLSL patch shaders, culled
// in place (render_osd_table.h, its own JSON); --frames, --size, --cull (not auto), --backpatch,
// --clip-depth, --tess (up to 16), --verify and --json apply to it, any other flag is refused.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include <CLI/CLI.hpp>

#include "cli_options.h"
#include "commands.h"
#include "cull_mode_names.h"
#include "frame_poser.h"
#include "frame_report.h"
#include "object_level_options.h"
#include "patchcull/core/error.h"
#include "patchcull/eval_gl/reference_frame.h"
#include "patchcull/eval_gl/scene_setup.h"
#include "patchcull/gl/cull_auto_policy.h"
#include "patchcull/gl/gl_verification.h"
#include "patchcull/import/scene_file.h"
#include "patchcull/import/scene_poser.h"
#include "render_dumps.h"
#include "render_options.h"
#include "render_osd_table.h"
#include "render_support.h"
#include "render_vulkan.h"

namespace patchcull::cli {
namespace {

// A number of the objects array: null when not known (NaN) or infinite.
nlohmann::json number_or_null(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }

nlohmann::json auto_objects_json(const std::vector<eval_gl::SceneObject>& objects,
                                 const std::vector<gl::CullAutoPolicy::Decision>& decisions) {
    nlohmann::json out = nlohmann::json::array();
    for (std::size_t i = 0; i < objects.size(); ++i)
        out.push_back({{"name", objects[i].name},
                       {"patches", objects[i].range.count},
                       {"culling", decisions[i].cull ? "on" : "off"},
                       {"break_even", number_or_null(decisions[i].break_even)},
                       {"cull_rate", number_or_null(decisions[i].cull_rate)}});
    return out;
}

}  // namespace

Runner add_render_command(CLI::App& app) {
    struct State {
        std::string model = "default";
        std::string scheme = "acc";
        std::string patch_source = "bezier";
        int split = 0;
        int frames = 6;
        std::string cull = "all";
        std::string backpatch = "tcone";
        std::string frustum = "hull";
        std::string clip_depth = "zero-to-one";
        std::string pose = "cpu";
        bool fused_pass = false;
        std::string draw = "indirect";
        std::string driver_threads = "spread";
        std::string compact = "scan";
        std::string api = "gl";
        bool vk_validation = false;
        std::string vk_device = "cpu";
        int tess = 8;
        TessOptions tess_options;
        DisplaceOptions displace;
        std::string size = "640x360";
        bool aggressive = false;
        bool verify = false;
        std::string out;
        std::string dump_hiz;     // render_dumps.h
        std::string draw_bounds;  // patch indices, comma-separated
        bool json = false;
        ObjectLevelOptions objects;
    };
    auto state = std::make_shared<State>();
    CLI::App* command = app.add_subcommand("render", "Render an animated camera path with the GPU cull pipeline");
    add_text_option(*command, "MODEL", state->model,
                    "OBJ control mesh, 'teapot', 'bigguy', 'monsterfrog', a built-in scene ('default', 'city', "
                    "'building') or a scene file (.json)");
    add_choice_option(*command, "--scheme", state->scheme, {"acc", "osd"}, "Catmull-Clark to Bezier scheme");
    add_choice_option(*command, "--patch-source", state->patch_source, {"bezier", "osd-table"},
                      "bezier patches of --scheme, or (with --scheme osd) OpenSubdiv's own patch table and GLSL "
                      "patch shaders, culled in place");
    add_int_option(*command, "--split", state->split, 0, 4, "uniform 1-to-4 patch splits of MODEL");
    add_int_option(*command, "--frames", state->frames, 1, 1000, "number of frames");
    add_choice_option(*command, "--cull", state->cull, cull_mode_choices(),
                      "cull tests of the pipeline (auto: all, per object where it pays, Niessner & Loop §6.3)");
    add_choice_option(*command, "--backpatch", state->backpatch, backpatch_method_choices(),
                      "back-patch test of backpatch/all");
    add_choice_option(*command, "--frustum", state->frustum, {"hull", "aabb"},
                      "frustum test: hull (control points, Niessner & Loop) or aabb (box grown by max |D|, Sathe)");
    add_clip_depth_option(*command, state->clip_depth);
    command->add_flag("--fused-pass", state->fused_pass,
                      "frustum, back-patch (tcone/ncone) and Hi-Z tests in one compute pass");
    add_choice_option(*command, "--draw", state->draw, {"flags", "indirect"},
                      "how the draw passes issue patches: indirect (the default: the survivors compacted into indirect "
                      "draws, a culled patch is never issued) or flags (every patch, the TCS drops the culled)");
    add_compact_option(*command, state->compact);
    add_driver_threads_option(*command, state->driver_threads);
    add_choice_option(*command, "--api", state->api, {"gl", "vulkan"},
                      "graphics API of the renderer and the cull passes: gl (OpenGL 4.5 through EGL) or vulkan "
                      "(Vulkan 1.3 on a headless device; one object per frame: no --cull auto, --objects, "
                      "--object-occlusion, --pose gpu, --dump-hiz or --draw-bounds)");
    command->add_flag("--vk-validation", state->vk_validation,
                      "with --api vulkan: the Khronos validation layer (with synchronization validation) on; any "
                      "message it reports fails the run (exit status 1)");
    add_choice_option(*command, "--vk-device", state->vk_device, {"cpu", "gpu"},
                      "with --api vulkan: the kind of Vulkan device tried first, cpu (lavapipe: the same runs "
                      "everywhere) or gpu (for measurements); another device with what is needed otherwise");
    add_choice_option(*command, "--pose", state->pose, {"cpu", "gpu"},
                      "where animated patches are evaluated: cpu, or gpu (stencils in a compute pass, bit-identical)");
    add_int_option(*command, "--tess", state->tess, 1, 64, "tessellation level (adaptive: the maximum)");
    add_tess_options(*command, state->tess_options);
    add_displace_options(*command, state->displace);
    add_object_level_options(*command, state->objects);
    add_size_option(*command, "--size", state->size, "framebuffer size");
    command->add_flag("--aggressive", state->aggressive,
                      "skip the second pass (Niessner & Loop §3.1; not conservative)");
    command->add_flag("--verify", state->verify,
                      "render the unculled reference of every frame and count false culls (exit status 1 if any)");
    add_output_file_option(*command, "--out", state->out, "write the colour image of the last frame as a PNG");
    add_text_option(
        *command, "--dump-hiz", state->dump_hiz,
        "write the last frame's Hi-Z levels into DIR (created): hiz_level_NN.png (grey: white = depth 1, "
        "else black..grey 254 = the level's min..max depth below 1), raw .f32 levels, depth, ids, hiz.json");
    add_text_option(*command, "--draw-bounds", state->draw_bounds,
                    "P[,P...]: draw these patches' CAF (green) and OOBB (red) screen rectangles, as the occlusion "
                    "test uses them, over the last frame into --out (Niessner & Loop, Fig. 6)");
    command->add_flag("--json", state->json, "print one JSON object");
    return [state, command]() {
        int width = 0, height = 0;
        parse_size("--size", state->size, width, height);
        if (state->patch_source == "osd-table") {
            if (state->scheme != "osd") throw Error("--patch-source osd-table: needs --scheme osd");
            const std::set<std::string> applies = {"MODEL",  "--scheme",    "--patch-source",  "--frames",
                                                   "--cull", "--backpatch", "--clip-depth",    "--tess",
                                                   "--size", "--verify",    "--json",          "--help",
                                                   "--draw", "--compact",   "--driver-threads"};
            for (const CLI::Option* option : command->get_options())
                if (option->count() > 0 && !applies.count(option->get_name()))
                    throw Error("--patch-source osd-table: not with " + option->get_name());
            if (state->cull == "auto") throw Error("--patch-source osd-table: not with --cull auto");
            // The flag path stays the default here: --draw indirect must be asked for.
            const bool indirect = state->draw == "indirect" && command->get_option("--draw")->count() > 0;
            if (!indirect && command->get_option("--compact")->count() > 0)
                throw Error("--patch-source osd-table: --compact needs --draw indirect");
            if (state->compact == "fused")
                throw Error(
                    "--patch-source osd-table: not with --compact fused (scan or append; the fused list is "
                    "the Bezier pipeline's)");
            OsdTableRender o;
            o.model = state->model;
            o.frames = state->frames;
            o.width = width;
            o.height = height;
            o.cull = parse_cull_mode_option("--cull", state->cull);
            o.backpatch = parse_backpatch_method("--backpatch", state->backpatch);
            o.depth = parse_clip_depth_option(state->clip_depth);
            o.tess = state->tess;
            o.indirect = indirect;
            o.compact = parse_compact_option(state->compact);
            o.driver_threads = driver_threads_option(state->driver_threads);
            o.verify = state->verify;
            o.json = state->json;
            return run_osd_table_render(o);
        }
        const bool automatic = state->cull == "auto";
        const gl::CullMode cull = automatic ? gl::CullMode::all : parse_cull_mode_option("--cull", state->cull);
        const gl::BackpatchMethod backpatch = parse_backpatch_method("--backpatch", state->backpatch);
        if (!state->draw_bounds.empty() && state->out.empty())
            throw Error("--draw-bounds: needs --out FILE.png (the picture it draws)");
        if (!state->dump_hiz.empty()) {
            if (!(static_cast<std::uint32_t>(cull) & gl::kCullOcclusion))
                throw Error("--dump-hiz: the pyramid is built only with occlusion (--cull occlusion, all or auto)");
            prepare_output_dir("--dump-hiz", state->dump_hiz, {"hiz.json"});
        }
        Scene scene = load_scene(state->model, state->scheme, state->split);
        check_scene_motion(scene, state->model, state->frames, kSecondsPerFrame);  // before any GL work
        apply_displace_options(state->displace, scene);
        const std::vector<std::size_t> bounds_patches = state->draw_bounds.empty()
                                                            ? std::vector<std::size_t>{}
                                                            : parse_patch_list(state->draw_bounds, scene.patch_count());
        const TessMode tess_mode = resolve_tess_mode(state->tess_options, scene.camera);
        // Back-patch culling is conservative only on closed surfaces (both sides are drawn, and
        // through an opening the inside of a patch that faces away shows): `all` leaves it out
        // for a scene with an open model; an explicit `backpatch` keeps it, with a warning, so
        // that --verify can show what it would remove.
        const gl::CullMode applied = applicable_cull_mode(scene, cull, "render");
        const bool backpatch_applied = (static_cast<std::uint32_t>(applied) & gl::kCullBackPatch) != 0;
        const bool one_sided = eval_gl::scene_is_one_sided(scene);
        // Camera-relative frames (scene_model.h's rebase_scene): each frame is drawn and culled
        // in the float frame of the grid point nearest its eye, everything in it composed in
        // double and rounded once. A scene whose eyes stay within 1024 of the origin never leaves
        // the world frame (its cameras are camera_path's, as always).
        const float aspect = float(width) / float(height);
        const std::vector<WorldCamera> world_cameras = scene.world_camera_path(state->frames, aspect);
        auto same = [](DVec3 a, DVec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; };
        std::vector<DVec3> frame_origins;
        bool rebases = false;
        for (const WorldCamera& c : world_cameras) {
            frame_origins.push_back(scene_frame_near(c.eye));
            rebases = rebases || !same(frame_origins.back(), scene.frame_origin);
        }
        Scene world;  // the placements in world coordinates (without the models), when frames move
        if (rebases) world = rebase_scene_in_place(scene, frame_origins[0]);
        if (state->vk_validation && state->api != "vulkan") throw Error("--vk-validation: needs --api vulkan");
        if (command->get_option("--vk-device")->count() > 0 && state->api != "vulkan")
            throw Error("--vk-device: needs --api vulkan");
        if (state->api == "vulkan") {
            const std::set<std::string> applies = {
                "MODEL",           "--scheme",        "--split",    "--frames",
                "--cull",          "--backpatch",     "--frustum",  "--clip-depth",
                "--fused-pass",    "--draw",          "--compact",  "--tess",
                "--tess-mode",     "--tess-distance", "--displace", "--displace-scale",
                "--bound",         "--cone",          "--size",     "--aggressive",
                "--verify",        "--out",           "--json",     "--api",
                "--vk-validation", "--vk-device",     "--help",     "--driver-threads"};
            for (const CLI::Option* option : command->get_options())
                if (option->count() > 0 && !applies.count(option->get_name()))
                    throw Error("--api vulkan: not with " + option->get_name() +
                                " (the Vulkan renderer draws the scene as one object, posed on the CPU)");
            if (automatic) throw Error("--api vulkan: not with --cull auto");
            if (state->compact == "fused")
                throw Error("--api vulkan: not with --compact fused (scan or append; the fused list is OpenGL's)");
            const ClipDepth depth = parse_clip_depth_option(state->clip_depth);
            if (depth == ClipDepth::minus_one_to_one)
                throw Error(
                    "--api vulkan: not with --clip-depth minus-one-to-one (Vulkan's clip space has depth 0..1)");
            VulkanRenderJob job;
            job.scene = &scene;
            job.world = rebases ? &world : nullptr;
            job.frame_origins = frame_origins;
            job.cameras = scene.camera_path(state->frames, aspect);
            for (std::size_t f = 0; f < job.cameras.size(); ++f) {
                if (rebases) job.cameras[f] = world_cameras[f].local(frame_origins[f]);
                job.cameras[f].depth = depth;
            }
            job.width = width;
            job.height = height;
            job.tess = state->tess;
            job.frames = state->frames;
            job.tess_mode = tess_mode;
            job.tests = static_cast<std::uint32_t>(applied);
            job.cull_name = gl::cull_mode_name(cull);
            job.backpatch_name = backpatch_applied ? gl::backpatch_method_name(backpatch) : "off";
            job.backpatch = backpatch;
            job.bound = displace_bound(state->displace);
            job.cone = displace_cone(state->displace);
            job.bound_name = state->displace.bound;
            job.cone_name = state->displace.cone;
            job.frustum_name = state->frustum;
            job.frustum_aabb = state->frustum == "aabb";
            job.fused_pass = state->fused_pass;
            job.draw_name = state->draw;
            job.indirect = state->draw == "indirect";
            job.compact_name = state->compact;
            job.scan = parse_compact_option(state->compact) == gl::CompactMethod::prefix_scan;
            job.aggressive = state->aggressive;
            job.verify = state->verify;
            job.json = state->json;
            job.validation = state->vk_validation;
            job.prefer_gpu = state->vk_device == "gpu";
            job.driver_threads = driver_threads_option(state->driver_threads);
            job.out = state->out;
            return run_vulkan_render(job);
        }
        auto object_level =
            std::make_unique<ObjectLevelRun>(state->objects, scene, one_sided);  // before the occluders go up
        if (automatic && object_level->sets_objects())
            throw Error("--object-occlusion: a query method decides per object itself; not with --cull auto");

        gl::GlContext context = gl::GlContext::create_headless(driver_threads_option(state->driver_threads));
        gl::CullPipeline pipeline(context);
        struct ReleaseGuard {  // GlReleaseGuard for the object level of the frame
            std::unique_ptr<ObjectLevelRun>& run;
            ~ReleaseGuard() { run->release_gl(); }
        } release_object_level{object_level};
        ScenePoser poser(scene);
        // The CPU readers of posed patches (object level, --cull auto, --draw-bounds) keep a CPU
        // pose under --pose gpu: their bounds stay the CPU's, exactly.
        const bool cpu_patches = object_level->enabled() || automatic || !bounds_patches.empty();
        FramePoser frame_poser(context, poser, pipeline.renderer(), parse_pose_where("--pose", state->pose),
                               cpu_patches);
        const std::vector<BezierPatch>* pose = frame_poser.pose(0);  // a CPU pose (frame 0 uploads the attributes)
        pipeline.renderer().set_displacement_map(scene.displacement);
        eval_gl::upload_scene_occluders(pipeline.renderer(), scene);
        std::vector<Camera> cameras = scene.camera_path(state->frames, aspect);
        if (rebases)
            for (std::size_t f = 0; f < cameras.size(); ++f) cameras[f] = world_cameras[f].local(frame_origins[f]);
        const ClipDepth clip_depth = parse_clip_depth_option(state->clip_depth);
        for (Camera& c : cameras) c.depth = clip_depth;  // drawn, culled and verified in it
        const std::vector<eval_gl::SceneObject> objects = eval_gl::scene_objects(scene);
        std::vector<gl::ObjectRange> ranges;
        ranges.reserve(objects.size());
        for (const eval_gl::SceneObject& o : objects) ranges.push_back(o.range);
        std::vector<std::string> names;
        names.reserve(objects.size());
        for (const eval_gl::SceneObject& o : objects) names.push_back(o.name);
        gl::CullAutoPolicy policy(ranges, scene.patch_count());

        nlohmann::json frames = nlohmann::json::array();
        std::size_t total_false = 0;
        nlohmann::json hiz_dump, drawn_bounds;
        for (int f = 0; f < state->frames; ++f) {
            if (!same(frame_origins[static_cast<std::size_t>(f)], scene.frame_origin)) {
                // A new frame: the scene's floats rounded into it, the object level (built on the
                // occluders' order) and the occluders made again.
                rebase_scene(world, frame_origins[static_cast<std::size_t>(f)], scene);
                object_level->release_gl();
                object_level = std::make_unique<ObjectLevelRun>(state->objects, scene, one_sided);
                eval_gl::upload_scene_occluders(pipeline.renderer(), scene);
            }
            // gpu without a CPU reader: no CPU pose; `pose` keeps frame 0's, which nothing reads.
            if (f > 0)
                if (const std::vector<BezierPatch>* posed = frame_poser.pose(f * kSecondsPerFrame)) pose = posed;
            const PoseCost& pose_cost = frame_poser.last();
            gl::PipelineParams params;
            params.frame.render =
                eval_gl::render_params(cameras[static_cast<std::size_t>(f)], width, height, state->tess, one_sided);
            apply_tess_mode(tess_mode, params.frame.render);
            params.frame.cull = applied;
            params.frame.aggressive = state->aggressive;
            params.backpatch = backpatch;
            params.bound = displace_bound(state->displace);
            params.cone = displace_cone(state->displace);
            params.frustum = state->frustum == "aabb" ? gl::FrustumTest::aabb : gl::FrustumTest::hull;
            params.fused_pass = state->fused_pass;
            params.draw = state->draw == "indirect" ? gl::DrawMode::indirect : gl::DrawMode::flags;
            params.compact = parse_compact_option(state->compact);
            object_level->apply(poser, *pose, f * kSecondsPerFrame, cameras[static_cast<std::size_t>(f)], height,
                                params, width);
            if (automatic) {
                policy.decide(object_tess_factors(*pose, ranges, params.frame.render));
                params.objects = policy.objects();
                params.frame.cull = policy.frame_cull_mode(applied);
                if (policy.resumes_culling()) pipeline.forget_visibility();
            }
            const gl::FrameStats stats = pipeline.render_frame(params);
            if (automatic) policy.observe(stats);
            const bool last = f + 1 == state->frames;
            if (last && !state->out.empty() && bounds_patches.empty()) pipeline.renderer().write_color_png(state->out);
            if (last && !state->dump_hiz.empty()) hiz_dump = dump_hiz(pipeline, state->dump_hiz);
            if (last && !bounds_patches.empty()) {
                const std::vector<std::uint32_t> ids = pipeline.renderer().read_ids();
                const std::vector<DisplacementRange>& ranges = poser.displacement_ranges();
                std::vector<PatchBounds> bounds;
                drawn_bounds = nlohmann::json::array();
                for (std::size_t p : bounds_patches) {
                    PatchBounds b;
                    b.patch = p;
                    if (!ranges.empty() && !scene.displacement.empty()) b.range = ranges[p];  // else drawn undisplaced
                    b.caf =
                        screen_bound((*pose)[p], b.range, DisplacedBoundKind::caf, params.cone, params.frame.render);
                    b.oobb =
                        screen_bound((*pose)[p], b.range, DisplacedBoundKind::oobb, params.cone, params.frame.render);
                    drawn_bounds.push_back(patch_bounds_json(b, ids));
                    bounds.push_back(b);
                }
                write_bounds_png(state->out, pipeline.renderer().read_color(), ids, width, height, bounds);
            }
            nlohmann::json ms = frame_ms_json(stats);
            if (object_level->enabled()) {
                ms["object_level"] = object_level->object_level_ms();  // CPU, before the GPU frame
                ms["cpu_frustum_after_objects"] = object_level->cpu_frustum_ms();
            }
            std::size_t false_culls = 0, depth_ties = 0, differing_pixels = 0;
            std::vector<std::uint32_t> false_culled;  // patch indices, ascending
            ObjectVerification object_check;
            if (state->verify) {
                const gl::FrameCapture culled = eval_gl::capture_culled_frame(pipeline.renderer());
                const eval_gl::ReferenceFrame reference =
                    eval_gl::render_reference(pipeline.renderer(), params.frame.render);
                const gl::FrameComparison cmp = gl::compare_frames(reference.capture, culled);
                // Patches culled by detail culling are not false culls (it is not conservative):
                // they are reported as pixels changed.
                object_check = object_level->verify(reference.capture.ids, cmp.false_culled);
                false_culled = object_check.patch_false_culls;
                false_culls = false_culled.size() + object_check.false_culled_triangles;
                depth_ties = cmp.depth_ties;
                differing_pixels = cmp.differing_pixels;
                ms["reference"] = reference.ms;
            }
            total_false += false_culls;
            frames.push_back(frame_counts_json(f, stats));
            frames.back()["ms"] = ms;
            frames.back()["pose"] = {{"where", pose_where_name(pose_cost.where)},
                                     {"cpu_patches", pose_cost.cpu_patches},
                                     {"cpu_ms", pose_cost.cpu_ms},
                                     {"done_ms", pose_cost.done_ms},
                                     {"meshes_ms", pose_cost.meshes_ms},
                                     {"bytes_uploaded", pose_cost.bytes_uploaded}};
            frames.back()["false_culls"] = false_culls;
            frames.back()["depth_ties"] = depth_ties;
            if (!false_culled.empty()) frames.back()["false_culled_patches"] = false_culled;
            if (state->verify) frames.back()["differing_pixels"] = differing_pixels;
            if (automatic) frames.back()["auto_objects"] = auto_objects_json(objects, policy.decisions());
            {
                nlohmann::json& o = frames.back()["objects"] = object_level->frame_json();
                if (state->verify) {
                    o["false_culled_objects"] = object_check.false_culled_objects;
                    o["false_culled_triangles"] = object_check.false_culled_triangles;
                    o["detail_pixels"] = object_check.detail_pixels;
                    o["aggressive_pixels"] = object_check.aggressive_pixels;
                }
            }
            if (!state->json) {
                print_frame_line(f, stats);
                if (state->verify) std::printf("; false culls %zu", false_culls);
                std::printf("\n");
                if (object_level->enabled()) {
                    const ObjectCullStats& o = object_level->result().stats;
                    std::printf(
                        "  objects (%s): %zu of %zu culled (frustum %zu, back-face %zu, detail %zu); %zu patches "
                        "and %zu triangles skipped; %u plane tests, %u BVH nodes, %u cluster tests\n",
                        object_level->method_name(), o.frustum_culled + o.backface_culled + o.detail_culled, o.total,
                        o.frustum_culled, o.backface_culled, o.detail_culled, o.patches_culled, o.triangles_culled,
                        o.plane_tests, o.bvh_nodes_visited, o.cluster_tests);
                }
                if (automatic) std::printf("%s\n", auto_summary_line(names, policy.decisions()).c_str());
            }
        }
        if (state->json) {
            nlohmann::json out;
            out["api"] = "gl";
            out["model"] = scene.name;
            out["patch_source"] = "bezier";
            out["patches"] = scene.patch_count();
            out["size"] = {width, height};
            out["clip_depth"] = clip_depth_name(clip_depth);
            out["tess"] = state->tess;
            out["tess_mode"] = tess_mode.adaptive ? "adaptive" : "uniform";
            out["cull"] = automatic ? "auto" : gl::cull_mode_name(cull);
            out["backpatch"] = backpatch_applied ? gl::backpatch_method_name(backpatch) : "off";
            out["aggressive"] = state->aggressive;
            out["verified"] = state->verify;
            out["displace"] = scene.displacement_name;
            out["displace_scale"] = scene.displacement.empty() ? 0.0f : scene.displacement.scale;
            out["displaced_patches"] = displaced_patch_count(poser);
            out["bound"] = state->displace.bound;
            out["cone"] = state->displace.cone;
            out["frustum"] = state->frustum;
            out["pose"] = state->pose;
            out["fused_pass"] = state->fused_pass;
            out["draw"] = state->draw;
            out["compact"] = state->compact;
            out["objects_method"] = object_level->method_name();
            out["object_occlusion"] = object_level->occlusion_name();
            out["detail_cull"] = state->objects.detail_pixels;
            out["environment_objects"] = scene.environment.size();
            out["renderer"] = context.renderer();
            out["driver_threads"] = state->driver_threads;
            out["pinned_driver_threads"] = context.pinned_driver_threads();
            out["frames"] = frames;
            out["false_culls"] = total_false;
            if (!hiz_dump.is_null()) out["hiz_dump"] = hiz_dump;
            if (!drawn_bounds.is_null()) out["draw_bounds"] = drawn_bounds;
            std::cout << out.dump() << "\n";
        } else if (state->verify) {
            std::printf("false culls in total: %zu\n", total_false);
        }
        // A false cull breaks the conservative promise: a failure, as in the main job (demo).
        return total_false > 0 ? 1 : 0;
    };
}

}  // namespace patchcull::cli
