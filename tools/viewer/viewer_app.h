// `patchcull view`'s window loop: each frame takes the input (mouse, keys, the panel, a
// --script's events of that frame: all through the same code), poses the scene, runs the cull
// pipeline from the camera, shows the colour image or the status colouring, draws the panel and
// writes the screenshots asked for.
#pragma once

#include <string>

#include "object_level_options.h"
#include "patchcull/import/scene_model.h"
#include "render_options.h"
#include "viewer_script.h"
#include "viewer_settings.h"

namespace patchcull::cli {

struct ViewerConfig {
    Scene scene;  ///< loaded, after --displace
    ObjectLevelOptions objects;
    int width = 960, height = 540;
    /// Frames to run (0: until the window closes, Escape, or a script's quit).
    int frames = 0;
    /// false: `view --frames N` non-interactively: render's camera path (one lap of N frames), no
    /// panel, a line per frame; the window then shows exactly `render --out`'s images.
    bool interactive = true;
    ViewerSettings settings;                          ///< the starting settings (from the flags)
    bool backpatch_requested = false;                 ///< --cull backpatch given: kept on an open scene, with a warning
    TessMode tess_mode;                               ///< reference distance of adaptive tessellation
    gl::FrustumTest frustum = gl::FrustumTest::hull;  ///< --frustum: the chain's frustum test
    ClipDepth clip_depth = ClipDepth::zero_to_one;    ///< --clip-depth: drawn and culled in it
    std::string final_screenshot;                     ///< --screenshot: after the last of --frames
    std::string screenshot_dir = "out";               ///< the screenshot key's numbered PNGs
    const ViewerScript* script = nullptr;             ///< events by frame; with one, time steps are fixed
};

/// Opens the window and runs the viewer; returns the exit status (0). Throws patchcull::Error
/// (one line) when there is no window or a file cannot be written.
int run_viewer(ViewerConfig& config);

}  // namespace patchcull::cli
