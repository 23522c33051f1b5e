// The viewer's input handling (`patchcull view`): turns key presses, mouse drags, wheel steps and
// held movement keys, whether from the user or a --script, into settings and camera changes: the
// one path every source of input goes through. No GL: unit-tested without a window.
#pragma once

#include <set>

#include "viewer_camera.h"
#include "viewer_settings.h"

namespace patchcull::cli {

class ViewerControls {
public:
    /// Edits settings and camera (both outlive the controls).
    ViewerControls(ViewerSettings& settings, ViewerCamera& camera);

    /// Repositions the camera after the camera mode changed (panel, key or script): leaving the
    /// path it starts where the path camera (the path's camera of this frame) is; orbiting turns
    /// it to the centre. Every method below calls it; call it after the panel changed settings.
    void sync(const Camera& path_camera);
    /// A key press: movement keys are held for this frame (move), reset_camera, screenshot and
    /// quit are remembered, the others change settings (apply_settings_key).
    void key(ViewerKey key, const Camera& path_camera);
    /// Back to the start camera; on the path, orbiting from there.
    void reset();
    /// A drag of the left (orbit; fly: look) or right (look; orbit: orbit) button, in pixels. On
    /// the path, the left button starts orbiting, the right one flying.
    void drag(bool left, float dx_pixels, float dy_pixels, const Camera& path_camera);
    /// Wheel steps (positive: closer): orbit zoom, or fly a tenth of the start distance per step.
    /// On the path it starts orbiting.
    void wheel(float steps, const Camera& path_camera);
    /// A movement key held this frame (the user's, polled each frame).
    void hold(ViewerKey key) { held_.insert(key); }
    /// Applies the held movement keys for seconds, then forgets them: fly moves along the view
    /// (w s a d e q), orbit zooms (w s, 4 wheel steps per second) and turns (a d e q, 240 pixels
    /// per second). On the path they start orbiting.
    void move(float seconds, const Camera& path_camera);

    /// True once after a screenshot key or button.
    bool take_screenshot();
    bool quit() const { return quit_; }

private:
    void leave_path(ViewerCameraMode mode, const Camera& path_camera);

    ViewerSettings& s_;
    ViewerCamera& camera_;
    ViewerCameraMode mode_;
    std::set<ViewerKey> held_;
    bool screenshot_ = false, quit_ = false;
};

}  // namespace patchcull::cli
