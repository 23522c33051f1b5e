// The tessellation, displacement and compaction options of `render` and `view` (render_options.h), and
// parse_size (commands.h).
#include <CLI/CLI.hpp>

#include "render_options.h"

#include <cmath>
#include <string>

#include "cli_options.h"
#include "commands.h"
#include "patchcull/core/error.h"
#include "patchcull/import/image.h"

namespace patchcull::cli {

void add_tess_options(CLI::App& command, TessOptions& options) {
    add_choice_option(command, "--tess-mode", options.mode, {"uniform", "adaptive"},
                      "uniform: --tess everywhere; adaptive: by distance (Niessner & Loop §6.3), --tess the maximum");
    CLI::Option* distance = command.add_option_function<std::string>(
        "--tess-distance",
        [&options](const std::string& text) {
            const float d = static_cast<float>(parse_real("--tess-distance", text, 0, 1e9));
            // > 0 after rounding to float as well (1e-50 parses but is 0 as a float).
            if (!(d > 0)) throw Error("--tess-distance: expected a distance > 0, got " + quote_input(text));
            options.distance = d;
        },
        "adaptive: distance from the eye that gets the full --tess level (default: the camera path's eye-to-target "
        "distance)");
    distance->type_name("REAL >0");
}

CLI::Option* add_compact_option(CLI::App& command, std::string& target) {
    return add_choice_option(command, "--compact", target, {"scan", "append", "fused"},
                             "how --draw indirect lists the survivors: scan (the default: a prefix scan, the same list "
                             "order every frame), append (atomic appends: the same set, the order may change) or fused "
                             "(the appends of pass 2 and of the one-pass draw done by the chain's last stage, the rest "
                             "as append)");
}

gl::CompactMethod parse_compact_option(const std::string& text) {
    if (text == "fused") return gl::CompactMethod::fused_append;
    return text == "append" ? gl::CompactMethod::atomic_append : gl::CompactMethod::prefix_scan;
}

const char* compact_option_name(gl::CompactMethod method) {
    if (method == gl::CompactMethod::fused_append) return "fused";
    return method == gl::CompactMethod::atomic_append ? "append" : "scan";
}

CLI::Option* add_driver_threads_option(CLI::App& command, std::string& target) {
    return add_choice_option(command, "--driver-threads", target, {"spread", "os"},
                             "on a software rasterizer (llvmpipe, lavapipe): pin each thread the driver starts to a "
                             "CPU of its own (spread, the default: the scheduler often puts two compute workers on "
                             "one CPU) or leave them to the operating system (os)");
}

DriverThreads driver_threads_option(const std::string& text) {
    return text == "os" ? DriverThreads::os : DriverThreads::spread;
}

const char* driver_threads_name(DriverThreads threads) { return threads == DriverThreads::os ? "os" : "spread"; }

void add_displace_options(CLI::App& command, DisplaceOptions& options) {
    CLI::Option* displace = add_text_option(
        command, "--displace", options.displace,
        "displacement map of every object: 'none', 'procedural' or a PNG height map (default: the scene's own; the "
        "default scene displaces its MonsterFrogs)");
    add_float_option(command, "--displace-scale", options.scale, 0, 1,
                     "displacement of a full height step, in character heights (default 0.02)")
        ->needs(displace);
    add_choice_option(command, "--bound", options.bound, {"caf", "oobb"},
                      "bound of displaced patches (Niessner & Loop §4.2: camera-aligned frustum, or "
                      "object-oriented box)");
    add_choice_option(command, "--cone", options.cone, {"full", "acon", "con"},
                      "normal cone of displaced patches' bounds (full, ACoN, CoN)");
}

void apply_displace_options(const DisplaceOptions& options, Scene& scene) {
    if (options.displace.empty()) return;
    if (options.displace == "none") {
        scene.displacement = {};
        scene.displacement_name = "none";
        for (SceneInstance& instance : scene.instances) instance.displaced = false;
        return;
    }
    const float scale = options.scale >= 0 ? options.scale : 0.02f;
    if (!(scale > 0)) throw Error("--displace-scale: must be > 0 with --displace " + quote_input(options.displace));
    scene.displacement = options.displace == "procedural" ? make_procedural_displacement(512, scale)
                                                          : load_displacement_png(options.displace, scale);
    scene.displacement_name = options.displace;
    for (SceneInstance& instance : scene.instances) instance.displaced = true;
}

DisplacedBoundKind displace_bound(const DisplaceOptions& options) {
    return options.bound == "oobb" ? DisplacedBoundKind::oobb : DisplacedBoundKind::caf;
}

NormalConeKind displace_cone(const DisplaceOptions& options) {
    if (options.cone == "full") return NormalConeKind::full;
    return options.cone == "con" ? NormalConeKind::con : NormalConeKind::acon;
}

float camera_path_eye_distance(const CameraPath& path) { return std::hypot(path.distance, path.height); }

TessMode resolve_tess_mode(const TessOptions& options, const CameraPath& path) {
    TessMode mode;
    mode.adaptive = options.mode == "adaptive";
    if (options.distance > 0 && !mode.adaptive)
        throw Error("--tess-distance: needs --tess-mode adaptive (uniform tessellation has no reference distance)");
    mode.reference_distance = options.distance > 0 ? options.distance : camera_path_eye_distance(path);
    return mode;
}

void apply_tess_mode(const TessMode& mode, gl::RenderParams& params) {
    params.adaptive_tess = mode.adaptive;
    params.tess_reference_distance = mode.reference_distance;
}

void parse_size(const std::string& flag, const std::string& text, int& width, int& height) {
    const std::size_t x = text.find('x');
    auto number = [&](const std::string& part, int& out) {
        if (part.empty() || part.size() > 5 || part.find_first_not_of("0123456789") != std::string::npos) return false;
        out = std::stoi(part);
        return out >= 1 && out <= 8192;
    };
    if (x == std::string::npos || !number(text.substr(0, x), width) || !number(text.substr(x + 1), height))
        throw Error(flag + ": expected WIDTHxHEIGHT with each in 1..8192, got '" + text + "'");
}

}  // namespace patchcull::cli
