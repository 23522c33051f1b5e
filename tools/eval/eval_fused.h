// `patchcull eval fused` (tools/eval/eval_fused.cpp; the run: eval_gl/fused_eval.h): a
// comparison of the fused CPU cull kernel's plans (fused_cull.h) and of its cost model
// (fused_cost_model.h) on a scene's camera path, registered by tools/cmd_eval.cpp.
#pragma once

#include <string>

namespace patchcull::cli {

struct FusedEvalOptions {
    std::string scene;  ///< "city", "building", "default", a scene file or a model
    std::string scheme = "acc";
    int frames = 24;
    std::string size = "640x360";
    int tess = 4;               ///< of the unculled render whose id buffer checks the decisions
    int repeats = 5;            ///< timed runs per object, plan and frame (the minimum is kept)
    int profile_interval = 16;  ///< FusedCostModel::Config::profile_interval
    std::string cone = "tcone";
    std::string clip_depth = "zero-to-one";  ///< --clip-depth: drawn and culled in it
    bool json = false;
};

/// Parses the options, loads and places the scene, runs eval_gl::run_fused_eval and prints its
/// false culls (stderr, up to 10), table or JSON; 1 on any false cull.
int run_fused_eval(const FusedEvalOptions& options);

}  // namespace patchcull::cli
