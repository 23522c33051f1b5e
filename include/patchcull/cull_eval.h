// patchcull/cull_eval.h: runs the CPU cull kernels over random views and checks each decision
// against the dense-sample ground truth (the engine behind `patchcull cull`).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "patchcull/camera.h"
#include "patchcull/displacement.h"
#include "patchcull/patch.h"
#include "patchcull/subdivision.h"

namespace patchcull {

/// Names of the cull methods the CPU runs, in a stable order: "frustum", "frustum-disp" (view
/// frustum; judged by surface samples inside the view volume), "tcone", "ncone", "ptp",
/// "ptp-pcnt" (back-patch, seed 001; judged by sampled tangent planes facing the eye; they
/// refuse displaced patches).
std::vector<std::string> cull_method_names();
bool is_cull_method(const std::string& name);

struct CullEvalOptions {
    int views = 1000;
    std::uint64_t seed = 1;
    ViewMode mode = ViewMode::contain;
    std::vector<std::string> methods{"frustum", "frustum-disp"};
    int ground_truth_grid = 17;   ///< samples per side for false-cull checks
    float aspect = 1.0f;
    /// Called on the calling thread after each view with the views done so far (1..views),
    /// between views, never inside a kernel or the ground-truth check; empty: nothing is called.
    /// For progress reports (the CLI's `cull` draws one on a terminal); it cannot change results.
    std::function<void(int views_done)> on_view_done;
};

struct CullMethodResult {
    std::string name;
    std::uint64_t culled = 0;       ///< culled patch-view pairs
    std::uint64_t false_culls = 0;  ///< culled pairs the ground truth shows visible
    double cull_rate = 0;           ///< culled / (patches * views)
    double ns_per_patch = 0;        ///< kernel wall time (SIMD, all cores) per patch and view
};

struct CullEvalResult {
    std::size_t patches = 0;
    int views = 0;
    std::vector<CullMethodResult> methods;
};

/// Runs options.methods over options.views views of frame (a static frame; displacement may be
/// null). Throws patchcull::Error for an unknown method name.
CullEvalResult evaluate_cull(const PatchFrame& frame, const DisplacementMap* displacement,
                             const CullEvalOptions& options);

}  // namespace patchcull
