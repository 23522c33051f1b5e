// Object-level occlusion beside per-patch Hi-Z on a scene's path (scene_eval.h).
//
// Every method runs the scene's camera path from a first frame: none (the unculled frame, the
// ratios' denominator); hiz (cull mode occlusion, no object level); M and M+hiz, object method M
// alone (cull mode none) and followed by the patch passes (cull mode occlusion) on the objects it
// lets through, for M the hardware queries on the characters (gl_object_queries.h; the
// environment's triangles drawn first as occluders), horizon (scenes with box occluders) and
// portals (scenes with cells) (scene_occlusion.h, after the object level's BVH frustum test).
// Times: wall clock around glFinish() per pass, plus the method's CPU work before the frame.
#include "patchcull/eval_gl/scene_eval.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <optional>

#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/eval_gl/reference_frame.h"
#include "patchcull/eval_gl/scene_setup.h"
#include "patchcull/gl/gl_cull_flags.h"
#include "patchcull/gl/gl_object_queries.h"
#include "patchcull/import/scene_object_level.h"
#include "patchcull/import/scene_poser.h"
#include "patchcull/objects/bounding_volumes.h"

namespace patchcull::eval_gl {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

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
    for (gl::QueryMethod q :
         {gl::QueryMethod::stop_and_wait, gl::QueryMethod::batched, gl::QueryMethod::chc, gl::QueryMethod::chcpp})
        both({gl::query_method_name(q), q, {}, false});
    if (has_boxes) both({"horizon", {}, SceneOcclusionMethod::horizon, false});
    if (has_cells) both({"portals", {}, SceneOcclusionMethod::portals, false});
    return out;
}

std::vector<Method> chosen_methods(const std::vector<std::string>& names, const std::vector<Method>& available,
                                   const Scene& scene) {
    if (names.empty()) return available;
    std::vector<Method> out;
    for (const std::string& item : names) {
        auto it = std::find_if(available.begin(), available.end(), [&](const Method& m) { return m.name == item; });
        if (it == available.end()) {
            std::string list;
            for (const Method& m : available) list += (list.empty() ? "" : ", ") + m.name;
            throw Error("--methods: " + quote_input(item) + " is not a method for scene '" + scene.name + "' (" + list +
                        ")");
        }
        if (std::none_of(out.begin(), out.end(), [&](const Method& m) { return m.name == item; })) out.push_back(*it);
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
    double objects_culled = 0, objects_hidden = 0, patches_hidden = 0, patches_culled = 0, patches_object = 0,
           patches_frustum = 0, patches_occlusion = 0;
    double queries = 0, multiqueries = 0, multiqueries_passed = 0, proxy_boxes = 0, waits = 0;
    double object_cpu = 0, pass1 = 0, hiz = 0, cull = 0, pass2 = 0, frame = 0;
    std::size_t wait_frames = 0, false_culls = 0;
};

// Culled occluder triangles that the unculled reference shows.
std::size_t false_culled_triangles(const std::vector<std::uint32_t>& reference_ids,
                                   const std::vector<IndexSpan>& culled) {
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

SceneEvalRow make_row(const Method& method, const Totals& t, int frames, double none_frame_ms) {
    const double n = std::max(frames, 1);
    SceneEvalRow r;
    r.name = method.name;
    r.object_method = method.queries        ? gl::query_method_name(*method.queries)
                      : method.scene_method ? scene_occlusion_method_name(*method.scene_method)
                                            : "none";
    r.patch_hiz = method.patch_hiz;
    r.objects_culled = t.objects_culled / n;
    r.objects_hidden = t.objects_hidden / n;
    r.patches_hidden = t.patches_hidden / n;
    r.patches_culled = t.patches_culled / n;
    r.patches_object_culled = t.patches_object / n;
    r.patches_frustum_culled = t.patches_frustum / n;
    r.patches_occlusion_culled = t.patches_occlusion / n;
    r.queries = t.queries / n;
    r.multiqueries = t.multiqueries / n;
    r.multiqueries_passed = t.multiqueries_passed / n;
    r.proxy_boxes = t.proxy_boxes / n;
    r.wait_frames = t.wait_frames;
    r.waits = t.waits / n;
    r.ms_object_cpu = t.object_cpu / n;
    r.ms_pass1 = t.pass1 / n;
    r.ms_hiz = t.hiz / n;
    r.ms_cull = t.cull / n;
    r.ms_pass2 = t.pass2 / n;
    r.ms_frame = t.frame / n;
    r.frame_ratio = none_frame_ms > 0 ? r.ms_frame / none_frame_ms : 0.0;
    r.false_culls = t.false_culls;
    return r;
}

}  // namespace

SceneEvalResult run_scene_eval(Scene scene, const SceneEvalOptions& o, const RunProgress& progress) {
    const int width = o.width, height = o.height;
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
    SceneEvalResult result;
    double none_frame_ms = 0;
    progress.begin(std::uint64_t(methods.size()) * std::uint64_t(o.frames));
    std::uint64_t done = 0;
    for (const Method& method : methods) {
        std::unique_ptr<SceneOcclusion> scene_method;
        if (method.scene_method) scene_method = std::make_unique<SceneOcclusion>(scene, level, *method.scene_method);
        pipeline.reset_visibility();
        queries.reset();
        Totals t;
        for (int f = 0; f < o.frames; ++f) {
            const float seconds = float(f) * o.seconds_per_frame;
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
                const ObjectCullResult& culled_objects =
                    level.cull(pose, poser.displacement_ranges(), seconds, camera, height, options);
                if (method.scene_method) {
                    const ObjectCullResult& culled = scene_method->cull(culled_objects, camera, width, height);
                    for (const IndexSpan& s : culled.culled_patches) params.object_culled.push_back({s.first, s.count});
                    for (const IndexSpan& s : culled.culled_triangles)
                        params.culled_occluders.push_back({s.first, s.count});
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
                        tight.update(pose, poser.displacement_ranges(), o.sigma,
                                     static_cast<std::size_t>(o.max_tight_boxes));
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
                const FrustumPlanes planes = make_frustum_planes(
                    params.frame.render.projection * params.frame.render.view, ClipDepth::zero_to_one);
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
            progress.done(++done);
        }
        if (method.name == "none") none_frame_ms = t.frame / std::max(o.frames, 1);
        result.rows.push_back(make_row(method, t, o.frames, none_frame_ms));
        result.false_culls += t.false_culls;
    }
    result.scene = scene.name;
    result.objects = level.culler().object_count();
    result.characters = instances;
    result.patches = scene.patch_count();
    return result;
}

}  // namespace patchcull::eval_gl
