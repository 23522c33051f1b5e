// Model, scheme, split and displacement options shared by the CLI's commands.
#include <cmath>
#include <iostream>

#include <CLI/CLI.hpp>

#include "cli_options.h"
#include "commands.h"
#include "patchcull/core/error.h"
#include "patchcull/import/image.h"

namespace patchcull::cli {

void print_warnings(const std::vector<std::string>& warnings) {
    for (const std::string& w : warnings) std::cerr << printable_line("patchcull: warning: " + w) << "\n";
}

void add_model_options(CLI::App& command, ModelOptions& options, bool with_displacement) {
    add_text_option(
        command, "MODEL", options.model,
        "OBJ control mesh, 'teapot' (the built-in Utah teapot), or a shipped model: 'bigguy', 'monsterfrog'")
        ->required();
    add_choice_option(command, "--scheme", options.scheme, {"acc", "osd"}, "Catmull-Clark to Bezier scheme");
    add_int_option(command, "--split", options.split, 0, 4, "uniform 1-to-4 patch splits");
    if (with_displacement) {
        CLI::Option* displace =
            add_text_option(command, "--displace", options.displace, "displacement map: a PNG file or 'procedural'");
        // Without a map the scale would mean nothing: an error rather than silently ignored.
        add_float_option(command, "--displace-scale", options.displace_scale, 0, kMaxDisplaceScale,
                         "object-space displacement of a full height step (default: 2% of the model's size)")
            ->needs(displace);
    }
}

LoadedModel load_model_from_options(const ModelOptions& options) {
    Scheme scheme = Scheme::acc;
    if (!parse_scheme(options.scheme, scheme)) throw Error("--scheme: unknown scheme '" + options.scheme + "'");
    return load_model(options.model, scheme, options.split);
}

DisplacementMap displacement_from_options(const ModelOptions& options, const LoadedModel& model) {
    if (options.displace.empty()) return {};
    float scale = options.displace_scale;
    if (!std::isfinite(scale)) throw Error("--displace-scale: must be a finite number");
    if (scale < 0) {
        const Bounds b = patch_bounds(model.rest);
        scale = 0.02f * length(b.max - b.min);
    }
    if (options.displace == "procedural") return make_procedural_displacement(512, scale);
    return load_displacement_png(options.displace, scale);
}

}  // namespace patchcull::cli
