// The tessellation, displacement and compaction options of `render` and `view` (--tess-mode,
// --tess-distance, --displace, --displace-scale, --bound, --cone, --compact): registration, checks
// and what they set (tools/render_options.cpp).
#pragma once

#include <string>

#include "cli_fwd.h"
#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/thread_placement.h"
#include "patchcull/gl/gl_compaction.h"
#include "patchcull/gl/gl_renderer.h"
#include "patchcull/import/scene_model.h"

namespace CLI {
class App;
}

namespace patchcull::cli {

/// --tess-mode uniform|adaptive and --tess-distance D of `render` and `view` (as parsed).
struct TessOptions {
    std::string mode = "uniform";
    float distance = 0;  ///< 0: not given (add_tess_options refuses 0 itself)
};
/// Registers --tess-mode (uniform|adaptive) and --tess-distance (a finite number > 0, at most
/// 1e9; parse errors name the flag) on command.
void add_tess_options(CLI::App& command, TessOptions& options);

/// The tessellation of a run (Niessner & Loop §6.3's adaptive case): uniform (--tess everywhere), or
/// adaptive by distance (gl::RenderParams::adaptive_tess: level --tess at reference_distance from
/// the eye and nearer, proportionally less farther away, at least 1).
struct TessMode {
    bool adaptive = false;
    float reference_distance = 1;
};
/// Resolves the options for a scene seen along path: the reference distance is --tess-distance,
/// or by default the camera path's eye-to-target distance (camera_path_eye_distance), so that the
/// surface at the centre of the orbit gets the full level. Throws patchcull::Error naming
/// --tess-distance when it is given without --tess-mode adaptive.
TessMode resolve_tess_mode(const TessOptions& options, const CameraPath& path);
/// Sets params.adaptive_tess and params.tess_reference_distance from mode.
void apply_tess_mode(const TessMode& mode, gl::RenderParams& params);
/// Distance from every eye of path to its target: sqrt(distance^2 + height^2).
float camera_path_eye_distance(const CameraPath& path);

/// --compact scan|append|fused of `render` and `view` (target keeps the text, default "scan"):
/// how --draw indirect lists each draw pass's survivors (gl_compaction.h's CompactMethod). scan:
/// the prefix scan, the same list order every frame; append: atomic appends, the same set of
/// patches in an order that may change from frame to frame; fused: append, done by the flag
/// chain's last stage for the lists it decides (pass 2, the one-pass draw; gl_pipeline.h's
/// PipelineParams::compact). A bad value is one line naming the flag (exit 2).
CLI::Option* add_compact_option(CLI::App& command, std::string& target);
/// The CompactMethod of --compact's text (checked by add_compact_option): "append" is
/// atomic_append, "fused" fused_append, anything else prefix_scan.
gl::CompactMethod parse_compact_option(const std::string& text);
/// --compact's text of a method ("scan", "append", "fused"), e.g. for a JSON report.
const char* compact_option_name(gl::CompactMethod method);

/// --driver-threads spread|os of `render` (target keeps the text, default "spread"): on a
/// software rasterizer, each thread the driver starts pinned to a CPU of its own, or left to the
/// operating system (core/thread_placement.h's DriverThreads). A bad value is one line naming the
/// flag (exit 2).
CLI::Option* add_driver_threads_option(CLI::App& command, std::string& target);
/// The DriverThreads of --driver-threads' text: "os" is os, anything else spread.
DriverThreads driver_threads_option(const std::string& text);
/// --driver-threads' text of a choice ("spread", "os"), e.g. for a JSON report.
const char* driver_threads_name(DriverThreads threads);

/// --displace, --displace-scale, --bound and --cone of `render` and `view` (Niessner & Loop §4.2, §6):
/// displaced patches tested against the frustum and the running pipeline's Hi-Z with the chosen
/// bound (gl_passes.h's DisplacedPass inside CullPipeline::render_frame).
struct DisplaceOptions {
    std::string displace;  ///< "" (the scene's own), "none", "procedural" or a PNG path
    float scale = -1;      ///< world units (a character is 1 high); < 0: not given (0.02)
    std::string bound = "caf";
    std::string cone = "acon";
};
/// Registers the four options (--displace-scale needs --displace; parse errors name the flag).
void add_displace_options(CLI::App& command, DisplaceOptions& options);
/// Applies --displace to the scene: "none" removes its displacement, "procedural" or a PNG
/// displaces every instance with that map (make_procedural_displacement(512, scale) or
/// load_displacement_png), scale --displace-scale or 0.02; "" keeps the scene's own (the default
/// scene's MonsterFrogs). Throws patchcull::Error naming the flag or file.
void apply_displace_options(const DisplaceOptions& options, Scene& scene);
/// --bound and --cone as the pipeline's enums.
DisplacedBoundKind displace_bound(const DisplaceOptions& options);
NormalConeKind displace_cone(const DisplaceOptions& options);

}  // namespace patchcull::cli
