// patchcull/eval/cull_eval.h: runs the CPU cull kernels over random views and checks each decision
// against the dense-sample ground truth (the engine behind `patchcull cull`).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "patchcull/core/camera.h"
#include "patchcull/core/displacement.h"
#include "patchcull/core/patch.h"
#include "patchcull/import/subdivision.h"

namespace patchcull {

/// Names of the cull methods the CPU runs, in a stable order: "frustum", "frustum-disp" (view
/// frustum; judged by surface samples inside the view volume), "tcone", "ncone", "ptp",
/// "ptp-pcnt" (back-patch, Loop, Niessner & Eisenacher; judged by sampled tangent planes facing
/// the eye; they refuse displaced patches).
std::vector<std::string> cull_method_names();
bool is_cull_method(const std::string& name);

/// The "distance" view distribution (`cull --view-mode distance`), closer to Loop, Niessner &
/// Eisenacher's Table 1 whole-object views than ViewMode::contain: every view looks at the centre of the object's
/// bounding sphere with a fixed 45-degree field of view (narrower side), from a uniformly random
/// direction, at distance m * fit, where fit is the distance at which that sphere just touches the
/// sides of the view and m is uniform in [min, max]. m >= 1 keeps the whole object in view.
/// What moves the back-patch rates is the eye's distance in object radii, m * fit / radius
/// (= m / sin 22.5 deg, 2.6 to 7.8 for the default 1..3): a nearer eye sees a smaller part of
/// a closed surface (of a sphere, the cap (1 - r/d)/2), so more patches are wholly back-facing;
/// far away the rates fall toward their orthographic values. (ViewMode::contain draws the field
/// of view in 30..70 degrees and m in 1.05..2.55, so its eyes are 1.8 to 9.9 radii away: the
/// field of view moves the rates only through this distance.)
struct DistanceViews {
    float min = 1.0f;  ///< in [1, 1000], <= max
    float max = 3.0f;  ///< in [min, 1000]
    static constexpr float fovy_degrees = 45.0f;
};

struct CullEvalOptions {
    int views = 1000;
    std::uint64_t seed = 1;
    ViewMode mode = ViewMode::contain;
    /// Set: views come from this distribution instead of mode (seeded by seed, at aspect).
    /// evaluate_cull throws patchcull::Error naming the bound for a range outside its contract.
    std::optional<DistanceViews> distance;
    std::vector<std::string> methods{"frustum", "frustum-disp"};
    int ground_truth_grid = 17;  ///< samples per side for false-cull checks, 1..1024
    float aspect = 1.0f;
    /// Called on the calling thread after each block of views with the views done so far
    /// (increasing, the last call with views), between blocks, never inside a kernel or the
    /// ground-truth check; empty: nothing is called. Views are judged in blocks of 16 to 256
    /// (fewer for more patches; see evaluate_cull). For progress reports (the CLI's `cull` draws
    /// one on a terminal); it cannot change results.
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
    /// Mean over the views of the eye's distance from the centre of the object's bounding
    /// sphere, in sphere radii: the quantity that moves the back-patch rates (DistanceViews).
    double mean_eye_distance_radii = 0;
    std::vector<CullMethodResult> methods;
};

/// Runs options.methods over options.views views of frame (a static frame; displacement may be
/// null). Throws patchcull::Error for an unknown method name, a grid outside 1..1024, or a frame
/// whose info does not hold one PatchInfo per patch.
///
/// Memory does not grow with the patch count beyond the batch and a few bytes per patch (issue
/// 14): the dense samples of the ground truth (12.7 KB per patch at grid 17) are never held for
/// every patch. Views go in blocks (about 2^22 patch-views each, 16..256 views); each block is
/// judged chunk by chunk of 64 patches on all cores, a chunk's samples made in per-thread
/// scratch (PatchTruthWindow, ground_truth.h) when one of its patches is first culled in the
/// block, and dropped with the chunk. A patch culled in several blocks is sampled once per block;
/// the counts are those of judging every pair against samples made once.
CullEvalResult evaluate_cull(const PatchFrame& frame, const DisplacementMap* displacement,
                             const CullEvalOptions& options);

}  // namespace patchcull
