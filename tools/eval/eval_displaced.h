// `patchcull eval displaced` (tools/eval_displaced.cpp): Niessner & Loop's Table 1, registered by
// tools/cmd_eval.cpp.
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

int run_displaced_eval(const DisplacedEvalOptions& options);

}  // namespace patchcull::cli
