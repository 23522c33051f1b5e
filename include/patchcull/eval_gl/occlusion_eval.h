// Niessner & Loop §6.2, "Patch-Based Occlusion Culling for Hardware Tessellation", for
// non-displaced models (culling within one object): the occluded fraction of the converged
// pipeline over views that contain the whole object, beside the GPU tcone/ncone back-patch
// fractions of the same views (the CLI's `patchcull eval occlusion`).
#pragma once

#include <cstddef>
#include <cstdint>

#include "patchcull/eval_gl/run_progress.h"
#include "patchcull/import/model_loader.h"

namespace patchcull::eval_gl {

struct OcclusionEvalOptions {
    int views = 20;          ///< whole-object views (ViewGenerator, contain mode), at least 1
    std::uint64_t seed = 1;  ///< the view generator's
    int width = 512, height = 512;
    int tess = 8;        ///< uniform tessellation level
    int max_frames = 8;  ///< converge_frame's limit per view
};

/// Sums over the views (divide by the views for means), except min, max and the counts.
struct OcclusionEvalResult {
    std::size_t patches = 0;
    double occluded_sum = 0, occluded_min = 1, occluded_max = 0;  ///< occlusion_culled / patches
    double frustum_sum = 0;
    double tcone_sum = 0, ncone_sum = 0;  ///< gl::BackpatchCuller's culled fractions
    double frames_sum = 0;                ///< frames to a stable visible set
    std::size_t unstable_views = 0;
    std::size_t false_culls = 0;  ///< final frames against the unculled render
};

/// Per view: the pipeline (cull mode occlusion) on the static model from a first frame until its
/// visible set is stable (converge_frame), its last frame compared with the unculled render, and
/// the back-patch cones on the same patches. Progress: one unit per view. Needs an OpenGL 4.5
/// context (headless).
OcclusionEvalResult run_occlusion_eval(const LoadedModel& model, const OcclusionEvalOptions& options,
                                       const RunProgress& progress = {});

}  // namespace patchcull::eval_gl
