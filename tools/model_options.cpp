// Model, scheme, split and displacement options shared by the CLI's commands.
#include <cmath>

#include "commands.h"
#include "patchcull/error.h"
#include "patchcull/image.h"

namespace patchcull::cli {

void add_model_options(CLI::App& command, ModelOptions& options, bool with_displacement) {
    command.add_option("MODEL", options.model, "OBJ control mesh, or 'teapot' for the built-in Utah teapot")
        ->required();
    command.add_option("--scheme", options.scheme, "Catmull-Clark to Bezier scheme: acc or osd")
        ->check(CLI::IsMember({"acc", "osd"}));
    command.add_option("--split", options.split, "uniform 1-to-4 patch splits (0..4)")->check(CLI::Range(0, 4));
    if (with_displacement) {
        command.add_option("--displace", options.displace, "displacement map: a PNG file or 'procedural'");
        command.add_option("--displace-scale", options.displace_scale,
                           "object-space displacement of a full height step (default: 2% of the model's size)");
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
