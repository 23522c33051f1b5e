// The interactive viewer's state that the panel, the keys and a --script's `set` lines all edit
// (`patchcull view`): which cull tests run and how, the tessellation, the displacement,
// what the window shows and how the camera moves. No GL here: the script parser validates `set`
// lines against it before any window opens, and the unit tests use it without a context.
#pragma once

#include <string>
#include <vector>

#include "patchcull/core/displaced_bounds.h"
#include "patchcull/gl/gl_compaction.h"
#include "patchcull/gl/gl_passes.h"
#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/gl/gl_renderer.h"

namespace patchcull::cli {

/// What the window shows: the pipeline's colour image, or the patch statuses (cull.png's
/// colouring: PatchRenderer::render_status_image) seen from the current camera or from a second
/// camera beside and above it (so that the culled patches show).
enum class ViewerView { colour, status, status_second };
/// path: render's camera path (as `render`); orbit: around the scene's centre; fly: free.
enum class ViewerCameraMode { path, orbit, fly };

struct ViewerSettings {
    bool frustum = true, backpatch = true, occlusion = true;
    bool cull_auto = false;  ///< --cull auto: the tests only on the objects where they pay (gl/cull_auto_policy.h)
    gl::BackpatchMethod backpatch_method = gl::BackpatchMethod::tcone;
    DisplacedBoundKind bound = DisplacedBoundKind::caf;
    NormalConeKind cone = NormalConeKind::acon;
    bool aggressive = false;  ///< skip the second pass (not conservative, Niessner & Loop §3.1)
    int tess = 8;             ///< 1..64
    bool adaptive_tess = false;
    bool displace = false;         ///< the scene's (or --displace's) map applied; else none
    float displace_scale = 0.02f;  ///< world units of a full height step, (0, 1]
    std::string objects = "none";  ///< object level: none, frustum, bvh, bvh+backface
    /// How the draw passes issue patches (gl_pipeline.h's DrawMode; --draw): indirect draws of the
    /// compacted survivors, or every patch with the TCS dropping the culled. Same image.
    gl::DrawMode draw = gl::DrawMode::indirect;
    /// The compaction of indirect draws (--compact): scan (the same list order every frame) or
    /// append (the same set, the order may change).
    gl::CompactMethod compact = gl::CompactMethod::prefix_scan;
    ViewerView view = ViewerView::colour;
    ViewerCameraMode camera = ViewerCameraMode::orbit;
    bool paused = false;  ///< animation stopped (the pipeline still runs every frame)
    bool panel = true;    ///< the ImGui panel is drawn
};

/// Applies `set NAME VALUE` (the names README's viewer section lists: cull.frustum on|off,
/// cull.backpatch, cull.occlusion, cull.auto, backpatch tcone|ncone|ptp, bound caf|oobb,
/// cone full|acon|con, aggressive on|off, tess 1..64, tess.adaptive on|off, displace on|off,
/// displace.scale (0,1], objects none|frustum|bvh|bvh+backface, draw flags|indirect,
/// compact scan|append, view colour|status|status-second, camera path|orbit|fly, pause on|off,
/// panel on|off). Returns "" on success, else what is wrong
/// (one line, settings unchanged).
std::string apply_setting(ViewerSettings& settings, const std::string& name, const std::string& value);

/// The keys the viewer acts on (README lists them; the panel shows them too).
enum class ViewerKey {
    toggle_frustum,     ///< 1
    toggle_backpatch,   ///< 2
    toggle_occlusion,   ///< 3
    toggle_auto,        ///< 4
    next_backpatch,     ///< b: tcone -> ncone -> ptp
    toggle_aggressive,  ///< g
    next_view,          ///< v: colour -> status -> status from a second camera
    next_camera,        ///< c: orbit -> fly -> path
    reset_camera,       ///< r: back to the path's first camera, orbiting
    toggle_panel,       ///< h
    toggle_displace,    ///< x
    tess_up,            ///< plus (= or keypad +)
    tess_down,          ///< minus
    pause,              ///< space
    screenshot,         ///< p or f12
    quit,               ///< escape
    forward,
    back,
    left,
    right,
    up,
    down,  ///< w s a d e q (held: fly moves; orbit: zoom / turn)
};
/// Script and README names ("1", "b", "space", "plus", "f12", "w", ...); false when unknown.
bool parse_viewer_key(const std::string& name, ViewerKey& key);
/// The names parse_viewer_key takes, for error messages.
std::string viewer_key_names();
/// True for the held movement keys (forward .. down).
bool is_movement_key(ViewerKey key);
/// Applies a key that only changes settings (toggles, cycles, tess, pause, panel, camera mode);
/// returns false for the others (movement, reset_camera, screenshot, quit), which the viewer
/// handles itself.
bool apply_settings_key(ViewerSettings& settings, ViewerKey key);

/// The cull mode of the toggles (frustum | backpatch | occlusion bits).
gl::CullMode settings_cull_mode(const ViewerSettings& settings);
/// Sets the three toggles from a cull mode.
void set_cull_toggles(ViewerSettings& settings, gl::CullMode mode);

const char* viewer_view_name(ViewerView view);               ///< "colour", "status", "status-second"
const char* viewer_camera_mode_name(ViewerCameraMode mode);  ///< "path", "orbit", "fly"

}  // namespace patchcull::cli
