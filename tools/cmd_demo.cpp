// The main job (`patchcull` with no arguments, or `patchcull demo`): renders the built-in default
// scene (patchcull/import/builtin_scenes.h; Niessner & Loop, Fig. 1 (c): animated characters among triangle
// occluders) headless with the GPU pipeline (Niessner & Loop §3; Loop, Niessner & Eisenacher's
// back-patch tests), along the scene's camera path, once without culling (the reference) and
// once per cull method. Every culled frame is compared with the unculled one (compare_frames; a
// false cull fails the job, exit 1).
// Writes OUT/frame.png (colour, last frame, cull mode all) and OUT/cull.png (the patch statuses of
// that frame seen from another camera, turned 90 degrees and above, so that culled patches show) and
// prints, per method, cull rates and pass times. The `auto` row is --cull auto (cull_auto_policy.h: Niessner
// & Loop §6.3's per-object switch, the tests of `all` on the objects where culling pays), measured
// and verified as the other rows. Then the object level (demo_city.h): the built-in city with
// each --objects method in front of the patch passes.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "cli_options.h"
#include "commands.h"
#include "demo_city.h"
#include "patchcull/core/error.h"
#include "patchcull/eval_gl/reference_frame.h"
#include "patchcull/eval_gl/scene_setup.h"
#include "patchcull/gl/cull_auto_policy.h"
#include "patchcull/gl/gl_backpatch_passes.h"
#include "patchcull/gl/gl_verification.h"
#include "patchcull/import/scene_file.h"
#include "patchcull/import/scene_poser.h"
#include "progress.h"
#include "render_support.h"

namespace patchcull::cli {
namespace {

struct DemoOptions {
    std::string size = "640x360";
    int frames = 6;
    int tess = 8;
    std::string out_dir = "out";
    std::string scene = "default";
    int city_frames = 3;
};

struct Method {
    std::string label;
    gl::CullMode cull;
    gl::BackpatchMethod backpatch;
    bool automatic = false;  ///< --cull auto: `cull` on the objects CullAutoPolicy turns on
};

struct Sums {
    double frustum = 0, backpatch = 0, occlusion = 0, drawn = 0;
    double pass1 = 0, hiz = 0, cull = 0, pass2 = 0, total = 0;
    std::size_t false_culls = 0;
    int frames = 0;
    double objects_culled = 0;  ///< auto: objects culled, summed over the timed frames
};

int run_demo(const DemoOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    int width = 0, height = 0;
    parse_size("--size", options.size, width, height);
    // Before any rendering: a bad --out-dir (the default `out` included) is an error now, not
    // after the whole job (seconds to minutes) has run.
    prepare_output_dir("--out-dir", options.out_dir, {"frame.png", "cull.png"});
    Scene scene = load_scene(options.scene, "acc", 0);
    place_scene_at_first_camera(scene, options.scene, options.frames, kSecondsPerFrame);
    gl::GlContext context = gl::GlContext::create_headless();
    gl::CullPipeline pipeline(context);
    gl::PatchRenderer& renderer = pipeline.renderer();

    // Poses and cameras of every frame, computed once and replayed for every method.
    ScenePoser poser(scene);
    std::vector<std::vector<BezierPatch>> poses;
    std::vector<gl::PatchAttributes> attributes;  // ACC tangent patches for shading
    for (int f = 0; f < options.frames; ++f) {
        poses.push_back(poser.pose(f * kSecondsPerFrame));
        attributes.push_back(eval_gl::pose_attributes(poser));
    }
    const std::vector<Camera> cameras = scene.camera_path(options.frames, float(width) / float(height));
    const bool one_sided = eval_gl::scene_is_one_sided(scene);
    auto params_of = [&](int f) {
        return eval_gl::render_params(cameras[static_cast<std::size_t>(f)], width, height, options.tess, one_sided);
    };
    const std::size_t patches = scene.patch_count();

    pipeline.set_patches(poses[0], attributes[0]);
    eval_gl::upload_scene_occluders(renderer, scene);
    renderer.set_displacement_map(scene.displacement);  // the frogs are displaced (Niessner & Loop §6)
    if (options.scene == "default")
        std::printf(
            "patchcull default scene: 3 BigGuy + 3 displaced MonsterFrog (ACC, animated), %zu patches, %zu "
            "occluder triangles;\n",
            patches, renderer.occluder_triangle_count());
    else
        std::printf("patchcull scene %s: %zu objects, %zu patches, %zu occluder triangles;\n", scene.name.c_str(),
                    scene.instances.size(), patches, renderer.occluder_triangle_count());
    std::printf("%d frames along the camera path, %dx%d, tessellation level %d; %s (%s).\n", options.frames, width,
                height, options.tess, context.renderer().c_str(),
                context.is_software() ? "software: wall-clock pass times" : "GPU timer queries");

    // The rows: frustum, each back-patch method with a GPU pass (gl::gpu_backpatch_methods),
    // occlusion, all and auto.
    const std::vector<gl::BackpatchMethod> backpatch_methods = gl::gpu_backpatch_methods();
    std::vector<Method> methods = {{"frustum", gl::CullMode::frustum, gl::BackpatchMethod::tcone}};
    for (gl::BackpatchMethod m : backpatch_methods)
        methods.push_back({std::string("backpatch ") + gl::backpatch_method_name(m), gl::CullMode::backpatch, m});
    methods.push_back({"occlusion", gl::CullMode::occlusion, gl::BackpatchMethod::tcone});
    methods.push_back({"all (tcone)", gl::CullMode::all, gl::BackpatchMethod::tcone});
    methods.push_back({"auto (tcone)", gl::CullMode::all, gl::BackpatchMethod::tcone, true});
    // Frames rendered so far, on stderr when it is a terminal (progress.h): one warm-up frame per back-patch method,
    // the references and every method's frames. Cleared before each line printed on stdout.
    const std::uint64_t frames = static_cast<std::uint64_t>(options.frames);
    Progress progress("demo", "frames", backpatch_methods.size() + frames + methods.size() * frames,
                      progress_wanted(false));
    progress.erase_when_done();
    std::uint64_t frames_done = 0;
    // Compiles every pass's program before anything is timed (llvmpipe takes seconds for ncone):
    // one untimed frame per back-patch method with every test.
    for (gl::BackpatchMethod m : backpatch_methods) {
        gl::PipelineParams warm_up;
        warm_up.frame.render = params_of(0);
        warm_up.frame.cull = gl::CullMode::all;
        warm_up.frame.timing = gl::TimingMethod::off;
        warm_up.backpatch = m;
        pipeline.render_frame(warm_up);
        progress.step(++frames_done);
    }
    std::vector<eval_gl::ReferenceFrame> references;
    double reference_ms = 0;
    for (int f = 0; f < options.frames; ++f) {
        pipeline.update_patches(poses[static_cast<std::size_t>(f)], attributes[static_cast<std::size_t>(f)]);
        references.push_back(eval_gl::render_reference(renderer, params_of(f)));
        if (f > 0 || options.frames == 1) reference_ms += references.back().ms;
        progress.step(++frames_done);
    }
    const int timed_frames = options.frames > 1 ? options.frames - 1 : 1;
    reference_ms /= timed_frames;

    std::vector<gl::ObjectRange> ranges;
    for (const eval_gl::SceneObject& o : eval_gl::scene_objects(scene)) ranges.push_back(o.range);
    progress.clear();
    std::printf(
        "\nPer method, averaged over frames 1..%d (frame 0 starts with half the patches tagged visible, "
        "Niessner & Loop §3);\ncull rates are fractions of the %zu patches; times in ms; 'x ref' = total / "
        "unculled render.\n\n",
        options.frames - 1, patches);
    std::printf("%-17s %7s %7s %7s %7s %7s %7s %7s %7s %7s %8s %6s %6s\n", "method", "culled", "frustum", "back",
                "occl", "drawn", "pass1", "hiz", "cull", "pass2", "total", "x ref", "false");
    std::printf("%-17s %7s %7s %7s %7s %6.1f%% %7s %7s %7s %7s %8.1f %6.2f %6s\n", "none (reference)", "0.0%", "-", "-",
                "-", 100.0, "-", "-", "-", "-", reference_ms, 1.0, "-");
    std::size_t total_false = 0;
    const std::filesystem::path out_dir(options.out_dir);
    bool wrote_images = false;
    for (const Method& method : methods) {
        // Back-patch tests are conservative only on closed surfaces (README: "What contributes a
        // pixel"): on a --scene with an open model those rows are left out.
        if (!one_sided && (static_cast<std::uint32_t>(method.cull) & gl::kCullBackPatch)) {
            frames_done += frames;  // not rendered: counted as done
            progress.clear();
            std::printf("%-17s (left out: the scene has an open model, back-patch culling is not conservative on it)\n",
                        method.label.c_str());
            continue;
        }
        pipeline.set_patches(poses[0], attributes[0]);  // fresh statuses: a first frame
        Sums sums;
        gl::CullAutoPolicy policy(ranges, patches);
        for (int f = 0; f < options.frames; ++f) {
            if (f > 0)
                pipeline.update_patches(poses[static_cast<std::size_t>(f)], attributes[static_cast<std::size_t>(f)]);
            gl::PipelineParams params;
            params.frame.render = params_of(f);
            params.frame.cull = method.cull;
            params.backpatch = method.backpatch;
            if (method.automatic) {
                policy.decide(gl::object_tess_factors(poses[static_cast<std::size_t>(f)], ranges, params.frame.render));
                params.objects = policy.objects();
                params.frame.cull = policy.frame_cull_mode(method.cull);
                if (policy.resumes_culling()) pipeline.forget_visibility();
            }
            const gl::FrameStats s = pipeline.render_frame(params);
            if (method.automatic) policy.observe(s);
            const gl::FrameComparison cmp =
                eval_gl::compare_with_reference(renderer, references[static_cast<std::size_t>(f)]);
            sums.false_culls += cmp.false_culled.size();
            progress.step(++frames_done);
            if (f == 0 && options.frames > 1) continue;
            ++sums.frames;
            sums.objects_culled += static_cast<double>(policy.culled_objects());
            sums.frustum += s.frustum_culled;
            sums.backpatch += s.backpatch_culled;
            sums.occlusion += s.occlusion_culled;
            sums.drawn += s.pass1_drawn + s.pass2_drawn;
            sums.pass1 += s.pass1_ms;
            sums.hiz += s.hiz_ms;
            sums.cull += s.cull_ms;
            sums.pass2 += s.pass2_ms;
            sums.total += s.total_ms;
        }
        const double n = sums.frames, pct = 100.0 / (n * double(patches));
        progress.clear();
        std::printf("%-17s %6.1f%% %6.1f%% %6.1f%% %6.1f%% %6.1f%% %7.1f %7.1f %7.1f %7.1f %8.1f %6.2f %6zu\n",
                    method.label.c_str(), (sums.frustum + sums.backpatch + sums.occlusion) * pct, sums.frustum * pct,
                    sums.backpatch * pct, sums.occlusion * pct, sums.drawn * pct, sums.pass1 / n, sums.hiz / n,
                    sums.cull / n, sums.pass2 / n, sums.total / n, sums.total / n / reference_ms, sums.false_culls);
        total_false += sums.false_culls;
        if (method.automatic)
            std::printf(
                "%-17s (objects culled per frame: %.1f of %zu, where the measured costs and cull rates say "
                "it pays)\n",
                "", sums.objects_culled / n, ranges.size());
        if (method.cull == gl::CullMode::all && !method.automatic) {
            wrote_images = true;
            renderer.write_color_png((out_dir / "frame.png").string());
            // The last camera's view turned 90 degrees about the target, farther out and above:
            // the sides facing away from the path's camera (back-patch and occlusion culled) show.
            Camera overview = cameras.back();
            const Vec3 d = overview.eye - overview.target;
            overview.eye = overview.target + Vec3{-d.z, 0, d.x} * 1.4f + Vec3{0, 1.8f, 0};
            overview.fovy_radians = 1.0471976f;
            overview.z_far *= 2;
            renderer.write_status_png((out_dir / "cull.png").string(),
                                      eval_gl::render_params(overview, width, height, options.tess, one_sided));
        }
    }
    progress.finish();
    // The object level: the city's objects culled before the patch passes.
    if (options.city_frames > 0) {
        DemoCityOptions city;
        city.width = width;
        city.height = height;
        city.frames = options.city_frames;
        total_false += run_demo_city(context, city);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (wrote_images)
        std::printf(
            "\nWrote %s (colour, cull mode all) and %s (statuses, seen from the side and above: green "
            "visible,\nyellow newly visible, blue frustum-culled, magenta back-patch-culled, red "
            "occlusion-culled, grey occluders).\n",
            (out_dir / "frame.png").string().c_str(), (out_dir / "cull.png").string().c_str());
    std::printf(
        "False culls (patches and objects in the unculled image but culled) in total: %zu (must be 0); "
        "%.1f s.\n",
        total_false, seconds);
    return total_false == 0 ? 0 : 1;
}

}  // namespace

Runner add_demo_command(CLI::App& app) {
    auto options = std::make_shared<DemoOptions>();
    CLI::App* command = app.add_subcommand(
        "demo", "Render the built-in default scene and the city's object level (the main job; the default command)");
    add_size_option(*command, "--size", options->size, "framebuffer size");
    add_int_option(*command, "--frames", options->frames, 2, 100, "frames along the camera path");
    add_int_option(*command, "--tess", options->tess, 1, 64, "uniform tessellation level");
    add_text_option(*command, "--out-dir", options->out_dir,
                    "directory of frame.png and cull.png (created if missing)");
    add_text_option(*command, "--scene", options->scene,
                    "the scene of the method table: 'default', 'city', 'building', a scene file (.json) or a model");
    add_int_option(*command, "--city-frames", options->city_frames, 0, 100,
                   "frames of the object-level rows on the city (0: leave them out)");
    return [options]() { return run_demo(*options); };
}

}  // namespace patchcull::cli
