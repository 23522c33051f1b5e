// `patchcull eval osd-cull` (tools/eval/eval_osd_cull.cpp): OpenSubdiv's own TCS frustum culling
// (OSD_ENABLE_PATCH_CULL) beside patchcull's passes on OpenSubdiv's patch table, registered by
// tools/cmd_eval.cpp.
#pragma once

#include <string>

namespace patchcull::cli {

struct OsdCullEvalOptions {
    std::string model;  ///< an OBJ path or a shipped model's name (not the teapot)
    int level = 2;      ///< the table's adaptive isolation level (1..4)
    int tess = 12;      ///< OpenSubdiv's uniform tessellation level (1..16)
    std::string size = "512x512";
    int rounds = 9;  ///< timed rounds per view, each one frame of every mode
    int warmup = 2;  ///< untimed rounds per view before them
};

/// Runs it and prints its tables; 1 when a culled frame's ids differ from the unculled frame's.
int run_osd_cull_eval(const OsdCullEvalOptions& options);

}  // namespace patchcull::cli
