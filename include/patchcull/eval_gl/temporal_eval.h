// Fig. 9 right of Niessner & Loop, "Patch-Based Occlusion Culling for Hardware Tessellation"
// (§6.3, "Temporal Coherence"): the fraction of patches culled by occlusion against the camera's
// rotation speed, with the two-pass temporal-coherence pipeline (gl::CullPipeline, cull mode
// occlusion) running frame after frame on a static model seen from its orbit (the CLI's
// `patchcull eval temporal`; docs/METHODS.md).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "patchcull/eval_gl/run_progress.h"
#include "patchcull/import/model_loader.h"

namespace patchcull::eval_gl {

/// The most frames converge_frame runs per view for the converged fraction.
inline constexpr int kTemporalConvergeFrames = 8;

struct TemporalEvalOptions {
    int width = 512, height = 512;            ///< framebuffer size
    std::vector<double> speeds{0, 2, 5, 10};  ///< degrees per frame, each in [0, 180]
    int frames = 36;                          ///< per speed, at least 2 (frame 0 primes the statuses)
    int tess = 8;                             ///< uniform tessellation level
};

struct TemporalSpeedRow {
    double degrees_per_frame = 0;
    double occluded_fraction = 0;            ///< mean over frames 1..frames-1 of occlusion_culled / patches
    double converged_occluded_fraction = 0;  ///< the same views' converged pipeline (converge_frame)
    double frustum_fraction = 0;             ///< mean frustum-culled fraction over frames 1..frames-1
    std::size_t false_culls = 0;             ///< moving and converged frames against the unculled render
};

struct TemporalEvalResult {
    std::string model;   ///< LoadedModel::name
    std::string scheme;  ///< the model's scheme name, or "bezier"
    std::size_t patches = 0;
    std::vector<TemporalSpeedRow> speeds;  ///< one per options.speeds, in order
    std::size_t false_culls = 0;           ///< over every speed
    std::size_t unstable_views = 0;        ///< views without a stable visible set after kTemporalConvergeFrames
};

/// Places model as make_model_scene does (no ground quad: every cull is the model hiding itself)
/// and runs each speed from a first frame along the scene's orbit; every frame (moving and
/// converged, views with the same eye converged once) is compared with the unculled render.
/// Progress: one unit per frame (speeds x frames). Needs an OpenGL 4.5 context (headless).
TemporalEvalResult run_temporal_eval(LoadedModel model, const TemporalEvalOptions& options,
                                     const RunProgress& progress = {});

}  // namespace patchcull::eval_gl
