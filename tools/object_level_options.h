// The object level in the CLI (`render`, `view`, `demo`; issue 11): --objects and --detail-cull,
// the per-frame run of SceneObjectLevel feeding CullPipeline, the object-level part of --verify,
// and the per-frame "objects" JSON.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "patchcull/gl_pipeline.h"
#include "patchcull/scene_object_level.h"

namespace CLI {
class App;
class Option;
}

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
    float cluster_cost = 1;          ///< tC/r of triangle clusters
    float patch_cluster_cost = 0.05f;  ///< tC/r of patch clusters
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
    void apply(const ScenePoser& poser, const std::vector<BezierPatch>& pose, float time_seconds,
               const Camera& camera, int viewport_height, gl::PipelineParams& params);
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

private:
    ObjectCullMethod method_ = ObjectCullMethod::none;
    ObjectCullOptions options_;
    std::unique_ptr<SceneObjectLevel> level_;
    ObjectCullResult empty_;
    std::vector<float> cpu_margins_;
    std::vector<std::uint8_t> cpu_culled_;
    std::size_t cpu_patch_tests_ = 0, cpu_frustum_culled_ = 0;
    double object_level_ms_ = 0, cpu_frustum_ms_ = 0;  // the CPU frustum kernel after the object level
    const ObjectCullResult* result_ = &empty_;
};

}  // namespace patchcull::cli
