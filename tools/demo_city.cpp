// The main job's object-level rows (demo_city.h).
#include "demo_city.h"

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "object_level_options.h"
#include "patchcull/eval_gl/reference_frame.h"
#include "patchcull/eval_gl/scene_setup.h"
#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/gl/gl_verification.h"
#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/scene_poser.h"
#include "progress.h"
#include "render_support.h"

namespace patchcull::cli {
namespace {

// The demo's city: smaller than `render city`'s default so that the main job stays under a
// minute on two cores (the object level's share of the work is the same).
CityParams demo_city_params() {
    CityParams p;
    p.blocks_x = 4;
    p.blocks_z = 4;
    p.characters = 48;
    return p;
}

}  // namespace

std::size_t run_demo_city(const gl::GlContext& context, const DemoCityOptions& options) {
    Scene scene = make_city_scene(Scheme::acc, demo_city_params());
    const bool one_sided = eval_gl::scene_is_one_sided(scene);
    gl::CullPipeline pipeline(context);
    gl::PatchRenderer& renderer = pipeline.renderer();
    ScenePoser poser(scene);
    std::vector<std::vector<BezierPatch>> poses;
    std::vector<gl::PatchAttributes> attributes;
    for (int f = 0; f < options.frames; ++f) {
        poses.push_back(poser.pose(f * kSecondsPerFrame));
        attributes.push_back(eval_gl::pose_attributes(poser));
    }
    const std::vector<Camera> cameras = scene.camera_path(options.frames, float(options.width) / float(options.height));
    // One object level per method, built before the occluders go up (clusters reorder them; the
    // same triangles, so one upload serves every method).
    const char* methods[] = {"none", "frustum", "bvh", "bvh+backface"};
    std::vector<std::unique_ptr<ObjectLevelRun>> levels;
    for (const char* m : methods) {
        ObjectLevelOptions o;
        o.method = m;
        levels.push_back(std::make_unique<ObjectLevelRun>(o, scene, one_sided));
    }
    pipeline.set_patches(poses[0], attributes[0]);
    eval_gl::upload_scene_occluders(renderer, scene);
    renderer.set_displacement_map(scene.displacement);
    std::printf(
        "\npatchcull city: %zu characters (BigGuy, MonsterFrog; ACC, animated, some rigid and walking, some "
        "displaced), %zu patches,\n%zu buildings + ground (%zu triangles); %d frames of the street walk, %dx%d, "
        "tessellation level %d, cull mode all.\nObject level before the patch passes (per frame, frames 1..%d): "
        "objects culled whole, patches skipped, plane tests, BVH nodes, cluster tests.\n\n",
        scene.instances.size(), scene.patch_count(), scene.environment.size() - 1, renderer.occluder_triangle_count(),
        options.frames, options.width, options.height, options.tess, options.frames - 1);
    std::printf("%-13s %8s %8s %8s %8s %8s %8s %8s %8s %8s %6s %6s\n", "objects", "culled", "skipped", "tris", "planes",
                "nodes", "clusters", "patch-cl", "drawn", "ms", "x none", "false");
    std::size_t total_false = 0;
    double none_ms = 0;
    // Frames rendered so far, on stderr when it is a terminal (progress.h), erased before each row.
    Progress progress("demo city", "frames", levels.size() * static_cast<std::uint64_t>(options.frames),
                      progress_wanted(false));
    progress.erase_when_done();
    std::uint64_t frames_done = 0;
    for (std::size_t k = 0; k < levels.size(); ++k) {
        ObjectLevelRun& level = *levels[k];
        pipeline.set_patches(poses[0], attributes[0]);
        double objects = 0, skipped = 0, tris = 0, planes = 0, nodes = 0, clusters = 0, patch_culled = 0, drawn = 0,
               ms = 0;
        std::size_t false_culls = 0;
        int timed = 0;
        for (int f = 0; f < options.frames; ++f) {
            const std::size_t i = static_cast<std::size_t>(f);
            if (f > 0) pipeline.update_patches(poses[i], attributes[i]);
            gl::PipelineParams params;
            params.frame.render =
                eval_gl::render_params(cameras[i], options.width, options.height, options.tess, one_sided);
            params.frame.cull = gl::CullMode::all;
            level.apply(poser, poses[i], f * kSecondsPerFrame, cameras[i], options.height, params);
            const gl::FrameStats s = pipeline.render_frame(params);
            const gl::FrameCapture culled = eval_gl::capture_culled_frame(renderer);
            const eval_gl::ReferenceFrame reference = eval_gl::render_reference(renderer, params.frame.render);
            const gl::FrameComparison cmp = gl::compare_frames(reference.capture, culled);
            const ObjectVerification v = level.verify(reference.capture.ids, cmp.false_culled);
            false_culls += v.patch_false_culls.size() + v.false_culled_triangles;
            progress.step(++frames_done);
            if (f == 0 && options.frames > 1) continue;
            ++timed;
            const ObjectCullStats& o = level.result().stats;
            objects += double(o.frustum_culled + o.backface_culled + o.detail_culled);
            skipped += double(o.patches_culled);
            tris += double(o.triangles_culled);
            planes += o.plane_tests;
            nodes += o.bvh_nodes_visited;
            clusters += o.cluster_tests;
            patch_culled += double(s.frustum_culled + s.backpatch_culled + s.occlusion_culled);
            drawn += double(s.pass1_drawn + s.pass2_drawn);
            ms += s.total_ms;
        }
        const double n = timed;
        if (k == 0) none_ms = ms / n;
        progress.clear();
        std::printf("%-13s %8.1f %8.0f %8.0f %8.0f %8.0f %8.0f %8.0f %8.0f %8.1f %6.2f %6zu\n", methods[k], objects / n,
                    skipped / n, tris / n, planes / n, nodes / n, clusters / n, patch_culled / n, drawn / n, ms / n,
                    ms / n / none_ms, false_culls);
        total_false += false_culls;
    }
    std::printf(
        "(culled: objects culled whole of %zu; skipped: patches no pass touched; tris: occluder triangles "
        "culled;\npatch-cl: patches culled by the patch passes; ms: the pipeline frame; false: against the "
        "unculled render, must be 0)\n",
        scene.instances.size() + scene.environment.size());
    return total_false;
}

}  // namespace patchcull::cli
