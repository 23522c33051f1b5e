// A measurement of the fused CPU cull kernel (core/fused_cull.h) and of the cost model that picks
// its plan per object and frame (core/fused_cost_model.h) on a scene's camera path, each culled
// patch checked against the unculled frame's id buffer (the CLI's `patchcull eval fused`).
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "patchcull/core/camera.h"
#include "patchcull/core/fused_cull.h"
#include "patchcull/eval_gl/run_progress.h"
#include "patchcull/import/scene_model.h"

namespace patchcull::eval_gl {

struct FusedEvalOptions {
    int frames = 24;                         ///< of the scene's camera path, at least 1
    float seconds_per_frame = 1.0f / 12.0f;  ///< animation time between two frames
    int width = 640, height = 360;           ///< the depth that feeds the Hi-Z pyramid
    int tess = 4;                            ///< of the unculled render whose id buffer checks the decisions
    int repeats = 5;                         ///< timed runs per object, plan and frame (the minimum is kept)
    int profile_interval = 16;               ///< FusedCostModel::Config::profile_interval
    BackPatchCone cone = BackPatchCone::tcone;
    ClipDepth clip_depth = ClipDepth::zero_to_one;  ///< drawn and culled in it
};

/// A culled patch that the unculled frame shows, with what the Hi-Z test saw.
struct FusedFalseCull {
    int frame = 0;
    std::size_t patch = 0;      ///< in the pose
    std::size_t object = 0;     ///< among the fused objects
    std::uint8_t decision = 0;  ///< kFusedFrustumCulled, kFusedBackPatchCulled or kFusedOccluded
    float zmin = -1;            ///< the patch's screen-bounds zmin (-1: not projectable)
    float pyramid_max = -1;     ///< the Hi-Z pyramid's max over its rectangle (-1: not projectable)
    float own_depth = 2;        ///< its own nearest depth in the unculled frame
};

/// Times in seconds summed over the frames (divide by frames for a mean).
struct FusedEvalResult {
    std::string scene;              ///< Scene::name
    std::size_t objects = 0;        ///< instances
    std::size_t fused_objects = 0;  ///< those the kernel culls (displaced instances are left out)
    std::size_t patches = 0, fused_patches = 0;
    std::size_t culled[4] = {};           ///< plan FBH's decisions, indexed by kFused* value
    std::vector<std::string> plan_names;  ///< the fixed plans with all three tests, FBH first
    std::vector<double> plan_seconds;     ///< per fixed plan
    double model_seconds = 0, profile_seconds = 0, oracle_seconds = 0, separate_seconds = 0;
    std::size_t agreements = 0;  ///< object-frames where the model ran a plan within 3% of the fastest
    std::size_t object_frames = 0;
    std::size_t profiled = 0;                    ///< the model's profiling runs
    std::map<std::string, std::size_t> choices;  ///< the model's plans by name
    std::size_t false_culls = 0;
    std::vector<FusedFalseCull> first_false_culls;  ///< the first 10
};

/// Per frame: scene posed (seconds_per_frame), its occluders alone drawn on the GPU at width x
/// height for the CPU Hi-Z pyramid (patches are not in it: a patch could be culled by its own
/// fragments), the frame drawn unculled for the id buffer; then per fused object on one core,
/// each the minimum of repeats runs: every fixed plan, the cost model's choice (its profiling
/// runs included), the fastest plan (oracle) and the separate SIMD kernels. scene: as loaded and
/// placed (place_scene_at_first_camera). Progress: one unit per frame. Needs an OpenGL 4.5 context.
FusedEvalResult run_fused_eval(const Scene& scene, const FusedEvalOptions& options, const RunProgress& progress = {});

}  // namespace patchcull::eval_gl
