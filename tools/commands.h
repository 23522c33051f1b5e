// The patchcull CLI's commands. Each registers a CLI11 subcommand and returns the callback that
// runs it after parsing. Commands use only the public headers (include/patchcull).
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <string>

#include "patchcull/displacement.h"
#include "patchcull/scene.h"

namespace patchcull::cli {

using Runner = std::function<int()>;

Runner add_info_command(CLI::App& app);
Runner add_cull_command(CLI::App& app);
/// The main job: runs on the built-in default scene (also `patchcull demo`).
Runner add_demo_command(CLI::App& app);
int run_demo();

/// Options shared by the commands that load a model.
struct ModelOptions {
    std::string model;
    std::string scheme = "acc";
    int split = 0;
    std::string displace;        ///< "", "procedural" or a PNG path
    float displace_scale = -1;   ///< object units; < 0 means 2% of the model's bounding-box diagonal
};

void add_model_options(CLI::App& command, ModelOptions& options, bool with_displacement);
/// Loads the model (throws patchcull::Error with file/flag in the message).
LoadedModel load_model_from_options(const ModelOptions& options);
/// Builds the displacement map the options ask for (empty map when none).
DisplacementMap displacement_from_options(const ModelOptions& options, const LoadedModel& model);

}  // namespace patchcull::cli
