// Benchmarks of the object level on the real `city` scene (make_city_scene's defaults: 6 x 6 box
// buildings + ground, 220 animated BigGuys and MonsterFrogs, ~300k ACC patches; G.
// Zachmann's lecture "Advanced Visibility Computations"): the CPU time that
// `render city --objects ...` spends before the patch passes, which render's JSON does not time.
//
// - object_level/city/setup: SceneObjectLevel's construction (objects, the triangle clusters of the
//   one-sided environment objects and the patch clusters of the rigid instances: Johannsen &
//   Carter's clustered back-face culling with Loop, Niessner & Eisenacher's tangent control planes
//   for patches); one scene copy per iteration outside the timed part.
// - object_level/city/pose: ScenePoser::pose of one frame, for scale (the CLI poses every frame
//   whatever --objects says).
// - object_level/city/frame/<variant>: SceneObjectLevel::cull per frame (the instances' boxes from
//   the posed control points, grown by |D|, then ObjectCuller::cull): what the CLI adds per frame.
// - object_level/city/cull/<variant>: ObjectCuller::cull alone on the same frames' boxes (the
//   frustum test flat or through the BVH, including the BVH refit, then the back-face part).
//
// Frames 1..16 of the CLI's walk (time f / 12 s, render's 640x360 aspect and height), posed once
// before the timing; each iteration is one frame, cycling through them. Counters per frame:
// plane_tests, bvh_nodes_visited, plane_tests_per_object, objects culled (frustum, back-face),
// cluster_tests, triangle_tests, patches_culled, triangles_culled. One thread.
//
// Run (docs/PERFORMANCE.md, "Object level"):
//   build-perf/bench/patchcull_bench --benchmark_filter='^object_level/' --benchmark_min_time=0.2
//       --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "patchcull/core/camera.h"
#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/scene_object_level.h"
#include "patchcull/import/scene_poser.h"
#include "patchcull/objects/object_culling.h"

using namespace patchcull;

namespace {

constexpr float kSecondsPerFrame = 1.0f / 12.0f;  // tools/render_support.h
constexpr int kWidth = 640, kHeight = 360;        // render's default --size
constexpr int kFrames = 16;                       // timed frames 1..16

bool one_sided(const Scene& scene) {  // tools/render_support.cpp scene_is_one_sided
    for (const LoadedModel& m : scene.models)
        if (!m.closed) return false;
    return true;
}

struct CityCase {
    Scene scene;  // built once; SceneObjectLevel reorders its occluder indices (same triangles)
    std::unique_ptr<ScenePoser> poser;
    std::vector<std::vector<BezierPatch>> poses;  // frames 1..kFrames
    std::vector<DisplacementRange> ranges;
    std::vector<Camera> cameras;  // frames 0..kFrames
    std::unique_ptr<SceneObjectLevel> level;
    // Per timed frame: the boxes of SceneObjectLevel::cull and the world -> object maps of the
    // instances (for the cull/* benchmarks, which call ObjectCuller::cull directly).
    std::vector<std::vector<Bounds>> boxes;
    std::vector<std::vector<Mat4>> world_to_object;
};

CityCase& city() {
    static std::unique_ptr<CityCase> c;
    if (c) return *c;
    c = std::make_unique<CityCase>();
    c->scene = make_city_scene(Scheme::acc);
    ObjectLevelSetup setup;
    setup.patches_one_sided = one_sided(c->scene);
    c->level = std::make_unique<SceneObjectLevel>(c->scene, setup);
    c->poser = std::make_unique<ScenePoser>(c->scene);
    c->cameras = c->scene.camera_path(kFrames + 1, float(kWidth) / float(kHeight));
    ObjectCullOptions o;
    o.method = ObjectCullMethod::bvh;
    for (int f = 1; f <= kFrames; ++f) {
        const float t = f * kSecondsPerFrame;
        c->poses.push_back(c->poser->pose(t));
        c->ranges = c->poser->displacement_ranges();
        c->level->cull(c->poses.back(), c->ranges, t, c->cameras[static_cast<std::size_t>(f)], kHeight, o);
        c->boxes.push_back(c->level->boxes());
        std::vector<Mat4> maps(c->level->culler().object_count());  // identity
        for (std::size_t i = 0; i < c->scene.instances.size(); ++i) {
            Mat4 inverse;
            if (invert(instance_to_world(c->scene.instances[i], t), inverse)) maps[i] = inverse;
        }
        c->world_to_object.push_back(std::move(maps));
    }
    return *c;
}

struct Variant {
    const char* name;
    ObjectCullMethod method;
    bool masking, coherence, meta;
    TriangleBackface triangles;
    int sectors;
};

const Variant kVariants[] = {
    {"frustum", ObjectCullMethod::frustum, false, true, false, TriangleBackface::clusters, 1},
    {"frustum_nocoherence", ObjectCullMethod::frustum, false, false, false, TriangleBackface::clusters, 1},
    {"bvh", ObjectCullMethod::bvh, true, true, false, TriangleBackface::clusters, 1},
    {"bvh_nomasking", ObjectCullMethod::bvh, false, true, false, TriangleBackface::clusters, 1},
    {"bvh_nocoherence", ObjectCullMethod::bvh, true, false, false, TriangleBackface::clusters, 1},
    {"bvh_nomasking_nocoherence", ObjectCullMethod::bvh, false, false, false, TriangleBackface::clusters, 1},
    {"bvh_meta", ObjectCullMethod::bvh, true, true, true, TriangleBackface::clusters, 1},
    {"bvh+backface", ObjectCullMethod::bvh_backface, true, true, false, TriangleBackface::clusters, 1},
    {"bvh+backface_masks", ObjectCullMethod::bvh_backface, true, true, false, TriangleBackface::normal_masks, 1},
    {"bvh+backface_masks4", ObjectCullMethod::bvh_backface, true, true, false, TriangleBackface::normal_masks, 4},
    {"bvh+backface_triangles", ObjectCullMethod::bvh_backface, true, true, false, TriangleBackface::per_triangle, 1},
};

ObjectCullOptions options_of(const Variant& v) {
    ObjectCullOptions o;
    o.method = v.method;
    o.plane_masking = v.masking;
    o.coherence = v.coherence;
    o.meta_bvs = v.meta;
    o.triangle_backface = v.triangles;
    o.mask_sectors = v.sectors;
    return o;
}

void report(benchmark::State& state, const ObjectCullStats& sum, double frames) {
    state.counters["objects"] = double(sum.total) / frames;
    state.counters["plane_tests"] = double(sum.plane_tests) / frames;
    state.counters["plane_tests_per_object"] = double(sum.plane_tests) / double(sum.total);
    state.counters["bvh_nodes_visited"] = double(sum.bvh_nodes_visited) / frames;
    state.counters["frustum_culled"] = double(sum.frustum_culled) / frames;
    state.counters["backface_culled"] = double(sum.backface_culled) / frames;
    state.counters["meta_rejected"] = double(sum.meta_rejected) / frames;
    state.counters["cluster_tests"] = double(sum.cluster_tests) / frames;
    state.counters["triangle_tests"] = double(sum.triangle_tests) / frames;
    state.counters["patches_culled"] = double(sum.patches_culled) / frames;
    state.counters["triangles_culled"] = double(sum.triangles_culled) / frames;
}

void add(ObjectCullStats& sum, const ObjectCullStats& s) {
    sum.total += s.total;
    sum.plane_tests += s.plane_tests;
    sum.bvh_nodes_visited += s.bvh_nodes_visited;
    sum.frustum_culled += s.frustum_culled;
    sum.backface_culled += s.backface_culled;
    sum.meta_rejected += s.meta_rejected;
    sum.cluster_tests += s.cluster_tests;
    sum.triangle_tests += s.triangle_tests;
    sum.patches_culled += s.patches_culled;
    sum.triangles_culled += s.triangles_culled;
}

// SceneObjectLevel::cull: boxes from the pose + the culler.
void BM_Frame(benchmark::State& state, Variant v) {
    CityCase& c = city();
    const ObjectCullOptions o = options_of(v);
    ObjectCullStats sum;
    std::size_t k = 0;
    double frames = 0;
    for (auto _ : state) {
        const std::size_t f = k++ % c.poses.size();
        const ObjectCullResult& r =
            c.level->cull(c.poses[f], c.ranges, float(f + 1) * kSecondsPerFrame, c.cameras[f + 1], kHeight, o);
        benchmark::DoNotOptimize(r.culled_patches.data());
        add(sum, r.stats);
        frames += 1;
    }
    state.SetItemsProcessed(state.iterations());
    report(state, sum, frames);
}

// ObjectCuller::cull alone on the frames' boxes.
void BM_Cull(benchmark::State& state, Variant v) {
    CityCase& c = city();
    const ObjectCullOptions o = options_of(v);
    // The level is not const (city() owns it); culler() is its const view of the same object.
    ObjectCuller& culler = const_cast<ObjectCuller&>(c.level->culler());
    std::vector<ObjectFrame> frames(c.poses.size());
    for (std::size_t f = 0; f < frames.size(); ++f) {
        const Camera& cam = c.cameras[f + 1];
        frames[f].world_to_clip = cam.view_projection();
        frames[f].depth = ClipDepth::zero_to_one;
        frames[f].eye = cam.eye;
        frames[f].boxes = c.boxes[f].data();
        frames[f].world_to_cluster = c.world_to_object[f].data();
        frames[f].pixel_scale = projection_pixel_scale(cam.fovy_radians, float(kHeight));
    }
    ObjectCullStats sum;
    std::size_t k = 0;
    double n = 0;
    for (auto _ : state) {
        const ObjectCullResult& r = culler.cull(frames[k++ % frames.size()], o);
        benchmark::DoNotOptimize(r.culled_patches.data());
        add(sum, r.stats);
        n += 1;
    }
    state.SetItemsProcessed(state.iterations());
    report(state, sum, n);
}

void BM_Setup(benchmark::State& state) {
    const Scene base = make_city_scene(Scheme::acc);
    ObjectLevelSetup setup;
    setup.patches_one_sided = one_sided(base);
    std::size_t clustered = 0, patch_clustered = 0, objects = 0;
    for (auto _ : state) {
        state.PauseTiming();
        auto scene = std::make_unique<Scene>(base);
        state.ResumeTiming();
        SceneObjectLevel level(*scene, setup);
        clustered = level.clustered_objects();
        patch_clustered = level.patch_clustered_objects();
        objects = level.culler().object_count();
        benchmark::DoNotOptimize(&level);
        state.PauseTiming();
        scene.reset();
        state.ResumeTiming();
    }
    state.counters["objects"] = double(objects);
    state.counters["clustered_objects"] = double(clustered);
    state.counters["patch_clustered_objects"] = double(patch_clustered);
    state.counters["patches"] = double(base.patch_count());
    state.counters["triangles"] = double(base.occluder_indices.size() / 3);
}

void BM_Pose(benchmark::State& state) {
    CityCase& c = city();
    std::size_t k = 0;
    for (auto _ : state) {
        const std::vector<BezierPatch>& p = c.poser->pose(float(k++ % kFrames + 1) * kSecondsPerFrame);
        benchmark::DoNotOptimize(p.data());
    }
    state.SetItemsProcessed(state.iterations());
    state.counters["patches"] = double(c.scene.patch_count());
}

const bool registered = [] {
    benchmark::RegisterBenchmark("object_level/city/setup", BM_Setup)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("object_level/city/pose", BM_Pose)->Unit(benchmark::kMillisecond);
    for (const Variant& v : kVariants)
        benchmark::RegisterBenchmark((std::string("object_level/city/frame/") + v.name).c_str(), BM_Frame, v)
            ->Unit(benchmark::kMicrosecond);
    for (const Variant& v : kVariants)
        benchmark::RegisterBenchmark((std::string("object_level/city/cull/") + v.name).c_str(), BM_Cull, v)
            ->Unit(benchmark::kMicrosecond);
    return true;
}();

}  // namespace
