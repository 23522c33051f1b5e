// `patchcull eval displaced` (tools/eval/eval_displaced.cpp): Niessner & Loop's Table 1 (the run:
// eval_gl/displaced_eval.h), registered by tools/cmd_eval.cpp.
#pragma once

#include <cstdint>
#include <string>

namespace patchcull::cli {

struct DisplacedEvalOptions {
    std::string model;
    std::string scheme = "acc";
    int split = 0;
    int views = 100;
    std::uint64_t seed = 1;
    std::string displace = "procedural";
    float displace_scale = -1;  ///< < 0: 2% of the model's bounding-box diagonal
    std::string size = "512x512";
    int tess = 8;
    std::string clip_depth = "zero-to-one";  ///< --clip-depth: drawn and culled in it
    bool json = false;
};

/// Parses the options, loads the model and its map, runs eval_gl::run_displaced_eval and prints its
/// table or JSON; 1 when a bound or the pipeline culled a patch the unculled render shows.
int run_displaced_eval(const DisplacedEvalOptions& options);

}  // namespace patchcull::cli
