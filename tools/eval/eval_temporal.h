// `patchcull eval temporal` (tools/eval/eval_temporal.cpp): Fig. 9 right of Niessner & Loop,
// "Patch-Based Occlusion Culling for Hardware Tessellation" (the run: eval_gl/temporal_eval.h),
// registered by tools/cmd_eval.cpp.
#pragma once

#include <string>
#include <vector>

namespace patchcull::cli {

struct TemporalEvalOptions {
    std::string model;
    std::string scheme = "acc";
    std::string speeds = "0,2,5,10";  ///< checked by parse_speeds when the option is parsed
    int frames = 36;                  ///< per speed: a full turn at 10 degrees per frame
    std::string size = "512x512";
    int tess = 8;
    bool json = false;
};

/// The most speeds one run takes.
inline constexpr std::size_t kMaxSpeeds = 16;

/// "0,2,5,10" -> {0, 2, 5, 10}: 1 to kMaxSpeeds comma-separated finite decimal numbers in
/// [0, 180] (degrees per frame; repeats allowed). Throws patchcull::Error naming flag otherwise
/// (empty list or item, not a number, negative, over 180, too many).
std::vector<double> parse_speeds(const std::string& flag, const std::string& text);

/// Parses the options, runs eval_gl::run_temporal_eval and prints its table or JSON; 1 when a
/// frame culled a patch the unculled render shows.
int run_temporal_eval(const TemporalEvalOptions& options);

}  // namespace patchcull::cli
