// The object level in the CLI (object_level_options.h).
#include "object_level_options.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "cli_options.h"
#include "patchcull/core/error.h"
#include "patchcull/eval_gl/scene_setup.h"

namespace patchcull::cli {

void add_object_level_options(CLI::App& command, ObjectLevelOptions& options) {
    add_choice_option(command, "--objects", options.method, {"none", "frustum", "bvh", "bvh+backface"},
                      "object level before the patch passes: AABB frustum test (flat), through a BVH, and "
                      "clustered back-face culling (Zachmann's lecture)");
    add_float_option(command, "--detail-cull", options.detail_pixels, 0, 1e6,
                     "detail culling: cull objects whose bounding sphere covers fewer pixels (not conservative; "
                     "0 = off; needs --objects)");
    options.given["--plane-masking"] =
        add_choice_option(command, "--plane-masking", options.plane_masking, {"on", "off"},
                          "bvh: children test only the planes their parent straddles");
    options.given["--plane-coherence"] =
        add_choice_option(command, "--plane-coherence", options.plane_coherence, {"on", "off"},
                          "the plane that rejected a volume last frame is tried first");
    options.given["--meta-bv"] =
        add_choice_option(command, "--meta-bv", options.meta_bv, {"on", "off"},
                          "test object boxes against the frustum's bounding sphere and box too");
    options.given["--object-volume"] =
        add_choice_option(command, "--object-volume", options.volume, {"aabb", "sphere", "obb"},
                          "after the AABB test (flat or BVH), also test each object's sphere or PCA OBB");
    options.given["--backface-triangles"] = add_choice_option(
        command, "--backface-triangles", options.backface_triangles, {"clusters", "masks", "triangles"},
        "bvh+backface on one-sided environment objects: cluster hierarchy, normal masks, or per triangle");
    options.given["--mask-sectors"] =
        add_int_option(command, "--mask-sectors", options.mask_sectors, 1, 8,
                       "normal masks: screen sectors per side (an object inside one uses that sector's mask)");
    options.given["--cluster-cost"] =
        add_float_option(command, "--cluster-cost", options.cluster_cost, 0, 1e6,
                         "tC/r of the triangle cluster hierarchy: a cluster test's cost in triangles drawn");
    add_choice_option(command, "--object-occlusion", options.occlusion,
                      {"none", "stop-and-wait", "batched", "chc", "chc++", "horizon", "portals"},
                      "object-level occlusion after --objects: hardware occlusion queries (stop-and-wait, batched, "
                      "CHC, CHC++), the occlusion horizon (box occluders) or cells and portals (scenes with cells)");
    options.given["--query-batch"] = add_int_option(command, "--query-batch", options.query_batch, 1, 1024,
                                                    "batched and chc++: queries issued b at a time (CHC++'s I-queue)");
    options.given["--query-threshold"] =
        add_int_option(command, "--query-threshold", options.query_threshold, 0, 1 << 24,
                       "aggressive approximate culling: an object is drawn only when its query passes more samples "
                       "(not conservative; --verify reports the pixels it changes)");
    options.given["--tight-sigma"] = add_float_option(
        command, "--tight-sigma", options.tight_sigma, 1, 16,
        "chc++ tight bounding volumes: refine while the boxes' area stays below sigma times the parent's");
    options.given["--patch-cluster-cost"] =
        add_float_option(command, "--patch-cluster-cost", options.patch_cluster_cost, 0, 1e6,
                         "tC/r of the patch cluster hierarchy: a cluster test's cost in patches drawn");
}

ObjectLevelRun::ObjectLevelRun(const ObjectLevelOptions& options, Scene& scene, bool patches_one_sided) {
    if (!parse_object_cull_method(options.method, method_))
        throw Error("--objects: unknown method '" + options.method + "'");
    if (options.detail_pixels > 0 && method_ == ObjectCullMethod::none)
        throw Error("--detail-cull: needs --objects frustum, bvh or bvh+backface");
    // A variant flag the chosen method would ignore is an error, not a silent no-op.
    auto given = [&](const char* flag) {
        const auto it = options.given.find(flag);
        return it != options.given.end() && it->second && it->second->count() > 0;
    };
    const bool bvh = method_ == ObjectCullMethod::bvh || method_ == ObjectCullMethod::bvh_backface;
    const bool backface = method_ == ObjectCullMethod::bvh_backface;
    for (const char* flag : {"--plane-coherence", "--meta-bv", "--object-volume"})
        if (given(flag) && method_ == ObjectCullMethod::none)
            throw Error(std::string(flag) + ": needs --objects frustum, bvh or bvh+backface");
    if (given("--plane-masking") && !bvh) throw Error("--plane-masking: needs --objects bvh or bvh+backface");
    for (const char* flag : {"--backface-triangles", "--mask-sectors", "--cluster-cost", "--patch-cluster-cost"})
        if (given(flag) && !backface) throw Error(std::string(flag) + ": needs --objects bvh+backface");
    if (given("--mask-sectors") && options.backface_triangles != "masks")
        throw Error("--mask-sectors: needs --backface-triangles masks");
    options_.method = method_;
    options_.detail_min_pixels = options.detail_pixels;
    options_.plane_masking = options.plane_masking == "on";
    options_.coherence = options.plane_coherence == "on";
    options_.meta_bvs = options.meta_bv == "on";
    if (!parse_object_volume(options.volume, options_.volume))
        throw Error("--object-volume: unknown volume '" + options.volume + "'");
    if (!parse_triangle_backface(options.backface_triangles, options_.triangle_backface))
        throw Error("--backface-triangles: unknown variant '" + options.backface_triangles + "'");
    options_.mask_sectors = options.mask_sectors;
    if (options.occlusion != "none") {
        gl::QueryMethod q{};
        SceneOcclusionMethod m{};
        if (gl::parse_query_method(options.occlusion, q))
            query_method_ = q;
        else if (parse_scene_occlusion_method(options.occlusion, m))
            scene_method_ = m;
        else
            throw Error("--object-occlusion: unknown method '" + options.occlusion + "'");
        if (method_ == ObjectCullMethod::none)
            throw Error(
                "--object-occlusion: needs --objects frustum, bvh or bvh+backface (the objects' boxes come from "
                "the object level)");
    }
    if (given("--query-threshold") && !query_method_)
        throw Error("--query-threshold: needs --object-occlusion stop-and-wait, batched, chc or chc++");
    if (given("--query-batch") &&
        !(query_method_ == gl::QueryMethod::batched || query_method_ == gl::QueryMethod::chcpp))
        throw Error("--query-batch: needs --object-occlusion batched or chc++");
    if (given("--tight-sigma") && query_method_ != gl::QueryMethod::chcpp)
        throw Error("--tight-sigma: needs --object-occlusion chc++");
    if (query_method_) query_options_.method = *query_method_;
    query_options_.batch_size = static_cast<unsigned>(options.query_batch);
    query_options_.pixel_threshold = static_cast<std::uint32_t>(options.query_threshold);
    tight_sigma_ = options.tight_sigma;
    scene_ = &scene;
    empty_.stats.total = scene.instances.size() + scene.environment.size();  // --objects none: nothing culled
    if (!enabled()) return;
    ObjectLevelSetup setup;
    setup.patches_one_sided = patches_one_sided;
    setup.clusters = method_ == ObjectCullMethod::bvh_backface;  // the only method that tests them
    setup.tc_over_r = options.cluster_cost;
    setup.patch_tc_over_r = options.patch_cluster_cost;
    level_ = std::make_unique<SceneObjectLevel>(scene, setup);
    if (scene_method_) {
        try {
            scene_occlusion_ = std::make_unique<SceneOcclusion>(scene, *level_, *scene_method_);
        } catch (const Error& e) {
            throw Error(std::string("--object-occlusion: ") + e.what());
        }
    }
    for (const eval_gl::SceneObject& o : eval_gl::scene_objects(scene)) {
        instance_ranges_.push_back(o.range);
        instance_patches_.push_back(static_cast<std::uint32_t>(o.range.count));
    }
}

std::string ObjectLevelRun::occlusion_name() const {
    if (query_method_) return gl::query_method_name(*query_method_);
    if (scene_method_) return scene_occlusion_method_name(*scene_method_);
    return "none";
}

void ObjectLevelRun::apply(const ScenePoser& poser, const std::vector<BezierPatch>& pose, float time_seconds,
                           const Camera& camera, int viewport_height, gl::PipelineParams& params, int viewport_width) {
    params.object_culled.clear();
    params.culled_occluders.clear();
    if (!enabled()) return;
    const auto start = std::chrono::steady_clock::now();
    result_ = &level_->cull(pose, poser.displacement_ranges(), time_seconds, camera, viewport_height, options_);
    if (viewport_width <= 0)
        viewport_width = std::max(1, static_cast<int>(std::lround(camera.aspect * float(viewport_height))));
    if (scene_occlusion_) result_ = &scene_occlusion_->cull(*result_, camera, viewport_width, viewport_height);
    // One pipeline object per instance: an instance culled whole is then never dispatched (with
    // the whole set as one object, a span culled inside it still costs its dispatch).
    params.objects = instance_ranges_;
    if (query_method_) {
        if (!queries_) queries_ = std::make_unique<gl::ObjectQueries>();  // on the current context
        gl::FrameObjects objects;
        objects.world_to_clip = camera.view_projection();
        objects.depth = camera.depth;
        objects.eye = camera.eye;
        objects.boxes = level_->boxes().data();
        objects.count = instance_ranges_.size();
        objects.patches = instance_patches_.data();
        if (*query_method_ == gl::QueryMethod::chcpp && query_options_.tight_bounds) {
            if (!tight_) tight_ = std::make_unique<SceneTightBounds>(*scene_, pose, poser.displacement_ranges());
            tight_->update(pose, poser.displacement_ranges(), tight_sigma_, kDefaultMaxTightBoxes);
            objects.tight = tight_->boxes().data();
            objects.tight_first = tight_->first().data();
        }
        queries_->set_frame(objects, query_options_);
        params.object_pass = queries_.get();
    }
    const auto culled = std::chrono::steady_clock::now();
    object_level_ms_ = std::chrono::duration<double, std::milli>(culled - start).count();
    for (const IndexSpan& s : result_->culled_patches) params.object_culled.push_back({s.first, s.count});
    // The CPU path after the object level (object_culling.h): the frustum kernel on the patches
    // left, to report the patch tests an object cull saves there too.
    const PatchBatch batch = make_batch(pose);
    const std::vector<DisplacementRange>& ranges = poser.displacement_ranges();
    cpu_margins_.assign(ranges.empty() ? 0 : pose.size(), 0.0f);
    for (std::size_t i = 0; i < cpu_margins_.size(); ++i)
        cpu_margins_[i] = std::max(std::fabs(ranges[i].d_min), std::fabs(ranges[i].d_max));
    cpu_culled_.assign(pose.size(), 0);
    cpu_patch_tests_ =
        cull_frustum_after_objects(*result_, batch.view(), cpu_margins_.empty() ? nullptr : cpu_margins_.data(),
                                   make_frustum_planes(camera.view_projection(), camera.depth), cpu_culled_.data());
    cpu_frustum_culled_ = 0;
    for (std::uint8_t c : cpu_culled_) cpu_frustum_culled_ += c;
    cpu_frustum_culled_ -= result_->stats.patches_culled;
    cpu_frustum_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - culled).count();
    for (const IndexSpan& s : result_->culled_triangles) params.culled_occluders.push_back({s.first, s.count});
}

ObjectVerification ObjectLevelRun::verify(const std::vector<std::uint32_t>& reference_ids,
                                          const std::vector<std::uint32_t>& patch_false_culls) const {
    ObjectVerification v;
    if (!enabled()) {
        v.patch_false_culls = patch_false_culls;
        return v;
    }
    const ObjectCuller& culler = level_->culler();
    // Object of each patch / triangle index, by binary search over the object spans.
    std::vector<std::pair<std::size_t, std::size_t>> patch_objects, triangle_objects;  // (first, object)
    for (std::size_t i = 0; i < culler.object_count(); ++i)
        (culler.object(i).triangles ? triangle_objects : patch_objects).push_back({culler.object(i).span.first, i});
    std::sort(patch_objects.begin(), patch_objects.end());
    std::sort(triangle_objects.begin(), triangle_objects.end());
    auto object_of = [&](const std::vector<std::pair<std::size_t, std::size_t>>& table,
                         std::size_t index) -> std::size_t {
        auto it = std::upper_bound(table.begin(), table.end(), std::make_pair(index, ~std::size_t{0}));
        if (it == table.begin()) return ~std::size_t{0};
        const std::size_t object = std::prev(it)->second;
        const IndexSpan& s = culler.object(object).span;
        return index < s.first + s.count ? object : ~std::size_t{0};
    };
    auto culled = [](const std::vector<IndexSpan>& spans, std::size_t index) {
        auto it = std::upper_bound(spans.begin(), spans.end(), index,
                                   [](std::size_t i, const IndexSpan& s) { return i < s.first; });
        return it != spans.begin() && index < std::prev(it)->first + std::prev(it)->count;
    };
    // An instance an aggressive query left out (--query-threshold > 0): its pixels are what the
    // approximation changes, not false culls. Instances come first in the object order.
    auto left_out_aggressively = [&](std::size_t object) {
        return queries_ && query_options_.pixel_threshold > 0 && object < queries_->drawn().size() &&
               !queries_->drawn()[object];
    };
    std::vector<std::uint8_t> false_object(culler.object_count(), 0);
    std::vector<std::uint8_t> triangle_counted;  // per triangle index: already counted
    const ObjectCullResult& r = *result_;
    for (std::uint32_t id : reference_ids) {
        if (id == 0) continue;
        const bool triangle = (id & gl::kIdOccluderBit) != 0;
        const std::size_t index = triangle ? (id & ~gl::kIdOccluderBit) : id - 1;
        const std::size_t object = object_of(triangle ? triangle_objects : patch_objects, index);
        if (object == ~std::size_t{0}) continue;
        if (r.verdicts[object] == ObjectVerdict::detail) {
            ++v.detail_pixels;
            continue;
        }
        if (left_out_aggressively(object)) {
            ++v.aggressive_pixels;
            continue;
        }
        if (!triangle || !culled(r.culled_triangles, index)) continue;
        false_object[object] = 1;
        if (index >= triangle_counted.size()) triangle_counted.resize(index + 1, 0);
        if (!triangle_counted[index]) ++v.false_culled_triangles;
        triangle_counted[index] = 1;
    }
    for (std::uint32_t p : patch_false_culls) {
        const std::size_t object = object_of(patch_objects, p);
        if (object != ~std::size_t{0} && (r.verdicts[object] == ObjectVerdict::detail || left_out_aggressively(object)))
            continue;
        v.patch_false_culls.push_back(p);
        if (object != ~std::size_t{0} && culled(r.culled_patches, p)) false_object[object] = 1;
    }
    for (std::uint8_t f : false_object) v.false_culled_objects += f;
    return v;
}

nlohmann::json ObjectLevelRun::frame_json() const {
    const ObjectCullStats& s = result_->stats;
    return {{"total", s.total},
            {"frustum_culled", s.frustum_culled},
            {"backface_culled", s.backface_culled},
            {"detail_culled", s.detail_culled},
            {"plane_tests", s.plane_tests},
            {"bvh_nodes_visited", s.bvh_nodes_visited},
            {"cluster_tests", s.cluster_tests},
            {"patches_culled", s.patches_culled},
            {"triangles_culled", s.triangles_culled},
            {"backface_patches_culled", s.backface_patches_culled},
            {"triangle_tests", s.triangle_tests},
            {"meta_rejected", s.meta_rejected},
            {"volume_rejected", s.volume_rejected},
            {"cpu_patch_tests", cpu_patch_tests_},
            {"cpu_frustum_culled", cpu_frustum_culled_},
            {"occlusion", occlusion_json()}};
}

nlohmann::json ObjectLevelRun::occlusion_json() const {
    if (queries_ && query_method_) {
        const gl::QueryStats& q = queries_->stats();
        return {{"method", occlusion_name()},
                {"objects", q.objects},
                {"frustum_culled", q.frustum_culled},
                {"occlusion_culled", q.occlusion_culled},
                {"drawn", q.drawn},
                {"queries", q.queries},
                {"multiqueries", q.multiqueries},
                {"multiqueries_passed", q.multiquery_passed},
                {"proxy_boxes", q.proxy_boxes},
                {"waits", q.waits},
                {"unqueryable", q.unqueryable},
                {"aggressive", query_options_.pixel_threshold > 0}};
    }
    if (scene_occlusion_) {
        const SceneOcclusionStats& st = scene_occlusion_->stats();
        return {{"method", occlusion_name()},
                {"objects_tested", st.objects_tested},
                {"objects_culled", st.objects_culled},
                {"patches_culled", st.patches_culled},
                {"triangles_culled", st.triangles_culled},
                {"eye_in_cell", st.eye_in_cell},
                {"near_geometry", st.near_geometry},
                {"cells_reached", st.portals.cells_reached},
                {"portals_passed", st.portals.portals_passed},
                {"occluders_inserted", st.horizon.occluders_inserted}};
    }
    return {{"method", "none"}};
}

}  // namespace patchcull::cli
