// The patchcull CLI's commands. Each registers a CLI11 subcommand and returns the callback that
// runs it after parsing. Commands use only the public headers (include/patchcull).
#pragma once

#include "cli_fwd.h"

#include <functional>
#include <string>
#include <vector>

#include "patchcull/core/displacement.h"
#include "patchcull/import/model_loader.h"

namespace patchcull::cli {

using Runner = std::function<int()>;

Runner add_info_command(CLI::App& app);
Runner add_cull_command(CLI::App& app);
/// `render`: the GPU pipeline over an animated camera path (tools/cmd_render.cpp).
Runner add_render_command(CLI::App& app);
/// `view`: the render pipeline shown in a window (GLFW), optionally saving a screenshot.
Runner add_view_command(CLI::App& app);
/// `eval occlusion`, `eval displaced`, `eval temporal`: Niessner & Loop's §6.2, Table 1 and Fig. 9 right
/// (tools/cmd_eval.cpp, eval/eval_displaced.cpp, eval/eval_temporal.cpp).
Runner add_eval_command(CLI::App& app);
/// The main job: renders the built-in default scene (also `patchcull demo`). The runner returned
/// here runs with the options given to `demo`, or with the defaults when there is no subcommand.
Runner add_demo_command(CLI::App& app);

/// Parses "WxH" (each in [1, 8192]) for the option named flag; throws patchcull::Error naming it.
void parse_size(const std::string& flag, const std::string& text, int& width, int& height);

/// Options shared by the commands that load a model.
struct ModelOptions {
    std::string model;
    std::string scheme = "acc";
    int split = 0;
    std::string displace;       ///< "", "procedural" or a PNG path
    float displace_scale = -1;  ///< object units; -1 (no flag gives < 0) means 2% of the bounding-box diagonal
};

/// The largest --displace-scale accepted (object units): large enough for any model, small
/// enough that products of a few such values stay finite in float.
inline constexpr double kMaxDisplaceScale = 1e9;

void add_model_options(CLI::App& command, ModelOptions& options, bool with_displacement);
/// Prints "patchcull: warning: W" on stderr for each of warnings, as one printable line each
/// (printable_line: a warning quotes a path, which may hold any bytes).
void print_warnings(const std::vector<std::string>& warnings);
/// Loads the model (throws patchcull::Error with file/flag in the message).
LoadedModel load_model_from_options(const ModelOptions& options);
/// Builds the displacement map the options ask for (empty map when none).
DisplacementMap displacement_from_options(const ModelOptions& options, const LoadedModel& model);

}  // namespace patchcull::cli
