// `patchcull eval scene SCENE [--scheme acc|osd] [--frames N] [--size WxH] [--tess L]
// [--methods LIST] [--batch B] [--sigma S] [--max-tight-boxes K] [--c1 C] [--visible-interval N]
// [--json]`: a comparison of object-level occlusion culling (G. Zachmann's lecture
// "Advanced Visibility Computations"; Bittner et al.'s CHC, Mattausch et al.'s CHC++; Downs et
// al.'s occlusion horizons; Luebke & Georges' portals) with patchcull's per-patch Hi-Z culling
// (Niessner & Loop, "Patch-Based Occlusion Culling for Hardware Tessellation").
//
// SCENE is a built-in scene (city, building, default), a scene file, or a model as `render` takes it
// (make_model_scene: the model on a ground quad, no box occluders). Every method runs the
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

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "cli_options.h"
#include "commands.h"
#include "patchcull/objects/bounding_volumes.h"
#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/gl/gl_object_queries.h"
#include "patchcull/gl/gl_verification.h"
#include "patchcull/import/scene_object_level.h"
#include "patchcull/import/scene_occlusion.h"
#include "patchcull/import/scene_file.h"
#include "progress.h"
#include "render_support.h"

namespace patchcull::cli {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) { return std::chrono::duration<double, std::milli>(Clock::now() - start).count(); }

struct Method {
    std::string name;  // the row's name: the object method's, + "+hiz" when followed by the patch passes
    std::optional<gl::QueryMethod> queries;
    std::optional<SceneOcclusionMethod> scene_method;
    bool patch_hiz = false;
    bool object_level() const { return queries || scene_method; }
};

std::vector<Method> all_methods(bool has_boxes, bool has_cells) {
    std::vector<Method> out{{"none", {}, {}, false}, {"hiz", {}, {}, true}};
    auto both = [&](Method m) {
        out.push_back(m);
        m.name += "+hiz";
        m.patch_hiz = true;
        out.push_back(m);
    };
    for (gl::QueryMethod q : {gl::QueryMethod::stop_and_wait, gl::QueryMethod::batched, gl::QueryMethod::chc, gl::QueryMethod::chcpp})
        both({gl::query_method_name(q), q, {}, false});
    if (has_boxes) both({"horizon", {}, SceneOcclusionMethod::horizon, false});
    if (has_cells) both({"portals", {}, SceneOcclusionMethod::portals, false});
    return out;
}

std::vector<Method> chosen_methods(const std::string& list, const std::vector<Method>& available, const Scene& scene) {
    if (list.empty()) return available;
    std::vector<Method> out;
    std::size_t begin = 0;
    while (true) {
        const std::size_t comma = list.find(',', begin);
        const std::string item = list.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
        auto it = std::find_if(available.begin(), available.end(), [&](const Method& m) { return m.name == item; });
        if (it == available.end()) {
            std::string names;
            for (const Method& m : available) names += (names.empty() ? "" : ", ") + m.name;
            throw Error("--methods: " + quote_input(item) + " is not a method for scene '" + scene.name + "' (" + names + ")");
        }
        if (std::none_of(out.begin(), out.end(), [&](const Method& m) { return m.name == item; })) out.push_back(*it);
        if (comma == std::string::npos) break;
        begin = comma + 1;
    }
    // none first: the others' frame ratios need it.
    if (out.front().name != "none") {
        out.insert(out.begin(), available.front());
        auto dup = std::find_if(out.begin() + 1, out.end(), [](const Method& m) { return m.name == "none"; });
        if (dup != out.end()) out.erase(dup);
    }
    return out;
}

struct Totals {
    double objects_culled = 0, objects_hidden = 0, patches_hidden = 0, patches_culled = 0, patches_object = 0, patches_frustum = 0, patches_occlusion = 0;
    double queries = 0, multiqueries = 0, multiqueries_passed = 0, proxy_boxes = 0, waits = 0;
    double object_cpu = 0, pass1 = 0, hiz = 0, cull = 0, pass2 = 0, frame = 0;
    std::size_t wait_frames = 0, false_culls = 0;
};

// Culled occluder triangles that the unculled reference shows.
std::size_t false_culled_triangles(const std::vector<std::uint32_t>& reference_ids, const std::vector<IndexSpan>& culled) {
    if (culled.empty()) return 0;
    std::vector<std::uint32_t> seen;
    for (std::uint32_t id : reference_ids)
        if (id & gl::kIdOccluderBit) seen.push_back(id & ~gl::kIdOccluderBit);
    std::sort(seen.begin(), seen.end());
    seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
    std::size_t count = 0;
    for (std::uint32_t t : seen)
        for (const IndexSpan& s : culled)
            if (t >= s.first && t < s.first + s.count) ++count;
    return count;
}

}  // namespace

int run_scene_eval(const SceneEvalOptions& o) {
    int width = 0, height = 0;
    parse_size("--size", o.size, width, height);
    Scene scene = load_scene(o.scene, o.scheme, 0);
    place_scene_at_first_camera(scene, o.scene, o.frames, kSecondsPerFrame);
    const bool one_sided = scene_is_one_sided(scene);
    ObjectLevelSetup setup;
    setup.clusters = false;  // the object level here is the frustum (BVH); occluders keep their order
    SceneObjectLevel level(scene, setup);
    const bool has_boxes = !box_environment_objects(scene).empty();
    const std::vector<Method> methods = chosen_methods(o.methods, all_methods(has_boxes, !scene.cells.empty()), scene);

    gl::GlContext context = gl::GlContext::create_headless();
    gl::CullPipeline pipeline(context);
    gl::ObjectQueries queries(context);
    ScenePoser poser(scene);
    const std::vector<BezierPatch>& first_pose = poser.pose(0);
    pipeline.set_patches(first_pose, pose_attributes(poser));
    pipeline.renderer().set_displacement_map(scene.displacement);
    upload_scene_occluders(pipeline.renderer(), scene);
    SceneTightBounds tight(scene, first_pose, poser.displacement_ranges());
    const std::vector<Camera> cameras = scene.camera_path(o.frames, float(width) / float(height));
    std::vector<gl::ObjectRange> ranges;
    std::vector<std::uint32_t> object_patches;
    for (const SceneObject& so : scene_objects(scene)) {
        ranges.push_back(so.range);
        object_patches.push_back(static_cast<std::uint32_t>(so.range.count));
    }
    const std::size_t instances = scene.instances.size();

    gl::QueryOptions query_options;
    query_options.batch_size = static_cast<unsigned>(o.batch);
    query_options.c1 = o.c1;
    query_options.visible_interval = static_cast<unsigned>(o.visible_interval);

    // Warm-up, untimed: the first frame of a mode compiles its programs (seconds on llvmpipe), which
    // must not land in one method's times.
    {
        gl::PipelineParams warm;
        warm.frame.render = render_params(cameras[0], width, height, o.tess, one_sided);
        warm.frame.timing = gl::TimingMethod::off;
        for (gl::CullMode mode : {gl::CullMode::none, gl::CullMode::occlusion}) {
            warm.frame.cull = mode;
            pipeline.render_frame(warm);
        }
        gl::FrameObjects objects;
        objects.world_to_clip = warm.frame.render.projection * warm.frame.render.view;
        objects.eye = cameras[0].eye;
        ObjectCullOptions frustum;
        frustum.method = ObjectCullMethod::frustum;
        level.cull(first_pose, poser.displacement_ranges(), 0, cameras[0], height, frustum);
        objects.boxes = level.boxes().data();
        objects.count = instances;
        queries.set_frame(objects, query_options);
        warm.objects = ranges;
        warm.object_pass = &queries;
        pipeline.render_frame(warm);
        pipeline.renderer().finish();
    }
    nlohmann::json rows = nlohmann::json::array();
    double none_frame_ms = 0;
    std::size_t conservative_false = 0;
    Progress progress("eval scene", "frames", std::uint64_t(methods.size()) * std::uint64_t(o.frames), progress_wanted(o.json));
    std::uint64_t done = 0;
    for (const Method& method : methods) {
        std::unique_ptr<SceneOcclusion> scene_method;
        if (method.scene_method) scene_method = std::make_unique<SceneOcclusion>(scene, level, *method.scene_method);
        pipeline.reset_visibility();
        queries.reset();
        Totals t;
        for (int f = 0; f < o.frames; ++f) {
            const float seconds = float(f) * kSecondsPerFrame;
            const std::vector<BezierPatch>& pose = poser.pose(seconds);
            pipeline.update_patches(pose, pose_attributes(poser));
            const Camera& camera = cameras[static_cast<std::size_t>(f)];
            gl::PipelineParams params;
            params.frame.render = render_params(camera, width, height, o.tess, one_sided);
            params.frame.cull = method.patch_hiz ? gl::CullMode::occlusion : gl::CullMode::none;
            params.frame.timing = gl::TimingMethod::wall_clock;
            double object_cpu = 0;
            if (method.object_level()) {
                const Clock::time_point start = Clock::now();
                ObjectCullOptions options;
                options.method = method.scene_method ? ObjectCullMethod::bvh : ObjectCullMethod::frustum;
                const ObjectCullResult& result =
                    level.cull(pose, poser.displacement_ranges(), seconds, camera, height, options);
                if (method.scene_method) {
                    const ObjectCullResult& culled = scene_method->cull(result, camera, width, height);
                    for (const IndexSpan& s : culled.culled_patches) params.object_culled.push_back({s.first, s.count});
                    for (const IndexSpan& s : culled.culled_triangles) params.culled_occluders.push_back({s.first, s.count});
                    params.objects = ranges;  // an instance culled whole is then not dispatched at all
                    t.objects_culled += double(culled.stats.frustum_culled + scene_method->stats().objects_culled);
                    t.objects_hidden += double(scene_method->stats().objects_culled);
                    t.patches_hidden += double(scene_method->stats().patches_culled);
                } else {
                    gl::QueryOptions q = query_options;
                    q.method = *method.queries;
                    gl::FrameObjects objects;
                    objects.world_to_clip = params.frame.render.projection * params.frame.render.view;
                    objects.eye = camera.eye;
                    objects.boxes = level.boxes().data();
                    objects.count = instances;
                    objects.patches = object_patches.data();
                    if (q.method == gl::QueryMethod::chcpp && q.tight_bounds) {
                        tight.update(pose, poser.displacement_ranges(), o.sigma, static_cast<std::size_t>(o.max_tight_boxes));
                        objects.tight = tight.boxes().data();
                        objects.tight_first = tight.first().data();
                    }
                    queries.set_frame(objects, q);
                    params.objects = ranges;
                    params.object_pass = &queries;
                }
                object_cpu = ms_since(start);
            }
            const gl::FrameStats stats = pipeline.render_frame(params);
            if (method.queries) {
                // The objects the queries hid (not drawn, inside the frustum: the pass's own box test).
                const FrustumPlanes planes =
                    make_frustum_planes(params.frame.render.projection * params.frame.render.view, ClipDepth::zero_to_one);
                for (std::size_t i = 0; i < instances; ++i) {
                    if (queries.drawn()[i]) continue;
                    PlaneCullState state;
                    std::uint32_t plane_tests = 0;
                    if (classify_aabb(planes, level.boxes()[i], state, plane_tests) == Containment::outside) continue;
                    t.objects_hidden += 1;
                    t.patches_hidden += double(object_patches[i]);
                }
                const gl::QueryStats& q = queries.stats();
                t.objects_culled += double(q.frustum_culled + q.occlusion_culled);
                t.queries += q.queries;
                t.multiqueries += q.multiqueries;
                t.multiqueries_passed += q.multiquery_passed;
                t.proxy_boxes += q.proxy_boxes;
                t.waits += q.waits;
                if (q.waits > 0) ++t.wait_frames;
            }
            const std::size_t patches = pose.size();
            const std::size_t drawn_or_passed = stats.visible;
            t.patches_culled += double(patches - std::min(patches, drawn_or_passed));
            t.patches_object += double(stats.object_culled);
            t.patches_frustum += double(stats.frustum_culled);
            t.patches_occlusion += double(stats.occlusion_culled);
            t.object_cpu += object_cpu;
            t.pass1 += stats.pass1_ms;
            t.hiz += stats.hiz_ms;
            t.cull += stats.cull_ms;
            t.pass2 += stats.pass2_ms;
            t.frame += object_cpu + stats.total_ms;
            const gl::FrameCapture culled = capture_culled_frame(pipeline.renderer());
            const ReferenceFrame reference = render_reference(pipeline.renderer(), params.frame.render);
            const gl::FrameComparison cmp = gl::compare_frames(reference.capture, culled);
            std::vector<IndexSpan> culled_triangles;
            for (const gl::TriangleSpan& s : params.culled_occluders) culled_triangles.push_back({s.first, s.count});
            t.false_culls += cmp.false_culled.size() + false_culled_triangles(reference.capture.ids, culled_triangles);
            progress.step(++done);
        }
        const double n = std::max(o.frames, 1);
        const double frame_ms = t.frame / n;
        if (method.name == "none") none_frame_ms = frame_ms;
        conservative_false += t.false_culls;
        rows.push_back({{"name", method.name},
                        {"object_method", method.queries ? gl::query_method_name(*method.queries)
                                          : method.scene_method ? scene_occlusion_method_name(*method.scene_method)
                                                                : "none"},
                        {"patch_hiz", method.patch_hiz},
                        {"objects_culled", t.objects_culled / n},
                        {"objects_hidden", t.objects_hidden / n},
                        {"patches_hidden", t.patches_hidden / n},
                        {"patches_culled", t.patches_culled / n},
                        {"patches_object_culled", t.patches_object / n},
                        {"patches_frustum_culled", t.patches_frustum / n},
                        {"patches_occlusion_culled", t.patches_occlusion / n},
                        {"queries", t.queries / n},
                        {"multiqueries", t.multiqueries / n},
                        {"multiqueries_passed", t.multiqueries_passed / n},
                        {"proxy_boxes", t.proxy_boxes / n},
                        {"wait_frames", t.wait_frames},
                        {"waits", t.waits / n},
                        {"ms",
                         {{"object_cpu", t.object_cpu / n},
                          {"pass1", t.pass1 / n},
                          {"hiz", t.hiz / n},
                          {"cull", t.cull / n},
                          {"pass2", t.pass2 / n},
                          {"frame", frame_ms}}},
                        {"frame_ratio", none_frame_ms > 0 ? frame_ms / none_frame_ms : 0.0},
                        {"false_culls", t.false_culls}});
    }
    progress.finish();
    nlohmann::json out = {{"scene", scene.name},
                          {"scheme", o.scheme},
                          {"objects", level.culler().object_count()},
                          {"characters", instances},
                          {"patches", scene.patch_count()},
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
        std::printf("%s: %zu characters, %zu patches, %d frames at %dx%d, tess %d\n", scene.name.c_str(), instances,
                    scene.patch_count(), o.frames, width, height, o.tess);
        std::printf("%-18s %9s %10s %9s %8s %7s %9s %7s %6s\n", "method", "objects", "patches", "queries", "multi", "waits",
                    "frame ms", "ratio", "false");
        for (const nlohmann::json& r : rows)
            std::printf("%-18s %9.1f %10.0f %9.1f %8.1f %7d %9.2f %7.2f %6d\n", r["name"].get<std::string>().c_str(),
                        r["objects_culled"].get<double>(), r["patches_culled"].get<double>(), r["queries"].get<double>(),
                        r["multiqueries"].get<double>(), int(r["wait_frames"].get<std::size_t>()),
                        r["ms"]["frame"].get<double>(), r["frame_ratio"].get<double>(), int(r["false_culls"].get<std::size_t>()));
    }
    return conservative_false == 0 ? 0 : 1;
}

}  // namespace patchcull::cli
