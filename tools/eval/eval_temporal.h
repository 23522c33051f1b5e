// `patchcull eval temporal` (tools/eval_temporal.cpp): Fig. 9 right of Niessner & Loop,
// "Patch-Based Occlusion Culling for Hardware Tessellation", registered by
// tools/cmd_eval.cpp; and the convergence loop it shares with `eval occlusion`.
#pragma once

#include <string>
#include <vector>

#include "patchcull/gl/gl_pipeline.h"

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

int run_temporal_eval(const TemporalEvalOptions& options);

/// A frame of the pipeline repeated from a first frame until its visible set is stable.
struct ConvergedFrame {
    gl::FrameStats stats;  ///< of the last frame run
    int frames = 0;        ///< frames run
    bool stable = false;   ///< the last two frames tagged the same patches visible
};

/// Niessner & Loop §3's pipeline on a static view as `eval occlusion` runs it: reset_visibility (the
/// next frame is a first frame, half the patches tagged visible), then params' frame again and
/// again until two consecutive frames tag the same patches visible (kStatusVisible), at most
/// max_frames frames. The renderer's framebuffer then holds the last frame.
ConvergedFrame converge_frame(gl::CullPipeline& pipeline, const gl::PipelineParams& params, int max_frames);

}  // namespace patchcull::cli
