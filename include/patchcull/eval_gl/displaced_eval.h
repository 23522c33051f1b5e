// Niessner & Loop's Table 1 (§4.2, §6.2), "Patch-Based Occlusion Culling for Hardware
// Tessellation": cull rates of the six bounds of a displaced patch, {oobb, caf} x {full, acon,
// con} (core/displaced_bounds.h), by the frustum and by occlusion inside the object, over views
// that contain the whole object, against the converged depth and in the running pipeline (the
// CLI's `patchcull eval displaced`).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "patchcull/core/camera.h"
#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/displacement.h"
#include "patchcull/eval_gl/run_progress.h"
#include "patchcull/import/model_loader.h"

namespace patchcull::eval_gl {

struct DisplacedEvalOptions {
    int views = 100;         ///< whole-object views (ViewGenerator, contain mode), at least 1
    std::uint64_t seed = 1;  ///< the view generator's
    int width = 512, height = 512;
    int tess = 8;                                   ///< uniform tessellation level
    ClipDepth clip_depth = ClipDepth::zero_to_one;  ///< drawn and culled in it
};

/// One bound and cone over every view: sums over views (divide by the views for means).
struct DisplacedEvalRow {
    DisplacedBoundKind bound = DisplacedBoundKind::oobb;
    NormalConeKind cone = NormalConeKind::full;
    double rate_sum = 0;             ///< culled fraction against the converged depth's Hi-Z
    std::size_t false_culls = 0;     ///< culled although in the unculled id buffer
    double pipeline_rate_sum = 0;    ///< the running pipeline's culled fraction (frustum + occlusion)
    double pipeline_frames_sum = 0;  ///< frames converge_frame ran
    std::size_t pipeline_false_culls = 0;
};

struct DisplacedEvalResult {
    std::size_t patches = 0;
    std::vector<DisplacedEvalRow> rows;  ///< oobb then caf, each with full, acon, con
    /// Every row's false culls, both kinds.
    std::size_t false_culls() const;
};

/// Per view: the displaced model (model's rest patches, map) rendered unculled; its depth gives
/// the CPU Hi-Z pyramid each bound is tested against (cull_displaced_occlusion); then, per bound,
/// the running pipeline from a first frame until its visible set is stable (converge_frame, at
/// most 8 frames), compared with the unculled render. Progress: one unit per view and bound.
/// Needs an OpenGL 4.5 context (headless).
DisplacedEvalResult run_displaced_eval(const LoadedModel& model, const DisplacementMap& map,
                                       const DisplacedEvalOptions& options, const RunProgress& progress = {});

}  // namespace patchcull::eval_gl
