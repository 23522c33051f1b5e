// The object level in the CLI (`render`, `view`, `demo`): --objects and --detail-cull,
// the per-frame run of SceneObjectLevel feeding CullPipeline, the object-level part of --verify,
// and the per-frame "objects" JSON.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_fwd.h"
#include "patchcull/gl/gl_object_queries.h"
#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/import/scene_object_level.h"
#include "patchcull/import/scene_occlusion.h"
#include "patchcull/import/scene_poser.h"

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace patchcull::cli {

/// --objects none|frustum|bvh|bvh+backface and --detail-cull PIXELS, as parsed.
struct ObjectLevelOptions {
    std::string method = "none";
    float detail_pixels = 0;  ///< 0: off
    std::string plane_masking = "on";
    std::string plane_coherence = "on";
    std::string meta_bv = "off";
    std::string volume = "aabb";
    std::string backface_triangles = "clusters";
    int mask_sectors = 1;
    float cluster_cost = 1;            ///< tC/r of triangle clusters
    float patch_cluster_cost = 0.05f;  ///< tC/r of patch clusters
    /// --object-occlusion: none, a query method (gl_object_queries.h) or horizon / portals
    /// (scene_occlusion.h), after the object level.
    std::string occlusion = "none";
    int query_batch = 16;      ///< batched and CHC++'s b
    int query_threshold = 0;   ///< aggressive approximate culling (not conservative)
    float tight_sigma = 1.4f;  ///< CHC++ tight bounding volumes
    /// The variant flags' options (add_object_level_options): given ones the method would ignore
    /// are errors.
    std::map<std::string, CLI::Option*> given;
};
void add_object_level_options(CLI::App& command, ObjectLevelOptions& options);

/// What --verify found at the object level in one frame.
struct ObjectVerification {
    std::size_t false_culled_triangles = 0;  ///< culled occluder triangles in the reference's id buffer
    std::size_t false_culled_objects = 0;    ///< objects (not detail-culled) with a falsely culled patch or triangle
    std::size_t detail_pixels = 0;           ///< reference pixels of detail-culled objects (not false culls)
    /// Reference pixels of objects an aggressive query left out (--query-threshold; not false culls).
    std::size_t aggressive_pixels = 0;
    std::vector<std::uint32_t> patch_false_culls;  ///< the frame's false culls without detail-culled patches
};

/// The object level of one run: builds SceneObjectLevel on the scene (before its occluders are
/// uploaded: one-sided environment objects are reordered into clusters), then per frame gives the
/// pipeline its culled spans.
class ObjectLevelRun {
public:
    /// patches_one_sided: the scene is drawn one-sided (scene_is_one_sided). Throws
    /// patchcull::Error naming --objects for an unknown method.
    ObjectLevelRun(const ObjectLevelOptions& options, Scene& scene, bool patches_one_sided);
    bool enabled() const { return method_ != ObjectCullMethod::none; }
    const char* method_name() const { return object_cull_method_name(method_); }

    /// Runs the object level for a frame and sets params.object_culled / culled_occluders.
    /// With --object-occlusion, runs that method too: horizon / portals add their culled spans,
    /// a query method sets params.objects (the instances) and params.object_pass (its queries
    /// then run inside render_frame, on the GL context current at the first apply).
    /// viewport_width 0: the camera's aspect times viewport_height.
    void apply(const ScenePoser& poser, const std::vector<BezierPatch>& pose, float time_seconds, const Camera& camera,
               int viewport_height, gl::PipelineParams& params, int viewport_width = 0);
    /// The --object-occlusion method's name ("none" without one).
    std::string occlusion_name() const;
    /// Deletes the query method's GL objects (made on the context current at the first apply);
    /// call while that context is alive, before it goes (GlReleaseGuard). The next apply makes
    /// them again.
    void release_gl() { queries_.reset(); }
    /// True with a query method: params.objects is set by apply (not with --cull auto).
    bool sets_objects() const { return query_method_.has_value(); }
    /// The last frame's result (all zero when disabled).
    const ObjectCullResult& result() const { return *result_; }
    /// Wall-clock milliseconds of the last apply: the object level (boxes + tests), and the CPU
    /// frustum kernel after it (its batch included); 0 when disabled.
    double object_level_ms() const { return object_level_ms_; }
    double cpu_frustum_ms() const { return cpu_frustum_ms_; }

    /// The object-level false culls of the last frame against the unculled reference's ids and
    /// the frame's patch false culls (compare_frames).
    ObjectVerification verify(const std::vector<std::uint32_t>& reference_ids,
                              const std::vector<std::uint32_t>& patch_false_culls) const;
    /// The per-frame "objects" JSON: {"total","frustum_culled","backface_culled","detail_culled",
    /// "plane_tests","bvh_nodes_visited","cluster_tests","patches_culled","triangles_culled",
    /// "backface_patches_culled","triangle_tests","meta_rejected","cpu_patch_tests",
    /// "cpu_frustum_culled"} (cpu_*: the CPU frustum kernel run on the patches the object level
    /// left, cull_frustum_after_objects: the patch tests it ran and the patches it culled).
    nlohmann::json frame_json() const;
    /// The --object-occlusion part of frame_json ("occlusion"): the method's counts of the frame.
    nlohmann::json occlusion_json() const;

private:
    ObjectCullMethod method_ = ObjectCullMethod::none;
    std::optional<gl::QueryMethod> query_method_;
    std::optional<SceneOcclusionMethod> scene_method_;
    gl::QueryOptions query_options_;
    float tight_sigma_ = 1.4f;
    const Scene* scene_ = nullptr;
    std::unique_ptr<SceneOcclusion> scene_occlusion_;
    std::unique_ptr<gl::ObjectQueries> queries_;
    std::unique_ptr<SceneTightBounds> tight_;
    std::vector<gl::ObjectRange> instance_ranges_;
    std::vector<std::uint32_t> instance_patches_;
    ObjectCullOptions options_;
    std::unique_ptr<SceneObjectLevel> level_;
    ObjectCullResult empty_;
    std::vector<float> cpu_margins_;
    std::vector<std::uint8_t> cpu_culled_;
    std::size_t cpu_patch_tests_ = 0, cpu_frustum_culled_ = 0;
    double object_level_ms_ = 0, cpu_frustum_ms_ = 0;  // the CPU frustum kernel after the object level
    const ObjectCullResult* result_ = &empty_;
};

/// Calls release_gl on scope exit: declared after the GL context, it runs before the context goes,
/// on every path out (an ObjectLevelRun built before the context outlives it).
class GlReleaseGuard {
public:
    explicit GlReleaseGuard(ObjectLevelRun& run) : run_(&run) {}
    GlReleaseGuard(const GlReleaseGuard&) = delete;
    GlReleaseGuard& operator=(const GlReleaseGuard&) = delete;
    ~GlReleaseGuard() { run_->release_gl(); }

private:
    ObjectLevelRun* run_;
};

}  // namespace patchcull::cli
