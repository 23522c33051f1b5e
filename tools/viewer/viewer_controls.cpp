// The viewer's input handling (viewer_controls.h).
#include "viewer_controls.h"

#include <utility>

namespace patchcull::cli {

ViewerControls::ViewerControls(ViewerSettings& settings, ViewerCamera& camera)
    : s_(settings), camera_(camera), mode_(settings.camera) {}

void ViewerControls::sync(const Camera& path_camera) {
    if (s_.camera == mode_) return;
    if (mode_ == ViewerCameraMode::path) camera_.set_eye_and_target(path_camera.eye, path_camera.target);
    if (s_.camera == ViewerCameraMode::orbit) camera_.look_at_centre();
    mode_ = s_.camera;
}

void ViewerControls::leave_path(ViewerCameraMode mode, const Camera& path_camera) {
    sync(path_camera);  // a mode change not yet applied first
    if (s_.camera != ViewerCameraMode::path) return;
    s_.camera = mode;
    sync(path_camera);
}

void ViewerControls::key(ViewerKey k, const Camera& path_camera) {
    if (is_movement_key(k))
        held_.insert(k);
    else if (k == ViewerKey::reset_camera)
        reset();
    else if (k == ViewerKey::screenshot)
        screenshot_ = true;
    else if (k == ViewerKey::quit)
        quit_ = true;
    else
        apply_settings_key(s_, k);
    sync(path_camera);
}

void ViewerControls::reset() {
    camera_.reset();
    if (s_.camera == ViewerCameraMode::path) s_.camera = mode_ = ViewerCameraMode::orbit;
}

void ViewerControls::drag(bool left, float dx, float dy, const Camera& path_camera) {
    leave_path(left ? ViewerCameraMode::orbit : ViewerCameraMode::fly, path_camera);
    if (s_.camera == ViewerCameraMode::orbit)
        camera_.orbit(dx, dy);
    else
        camera_.look(dx, dy);
}

void ViewerControls::wheel(float steps, const Camera& path_camera) {
    leave_path(ViewerCameraMode::orbit, path_camera);
    if (s_.camera == ViewerCameraMode::orbit)
        camera_.zoom(steps);
    else
        camera_.move(0, 0, steps * 0.2f, 1.0f);  // fly: a step is 0.2 s of a held key
}

void ViewerControls::move(float seconds, const Camera& path_camera) {
    if (held_.empty()) return;
    auto axis = [&](ViewerKey plus, ViewerKey minus) { return float(held_.count(plus)) - float(held_.count(minus)); };
    const float f = axis(ViewerKey::forward, ViewerKey::back), r = axis(ViewerKey::right, ViewerKey::left),
                u = axis(ViewerKey::up, ViewerKey::down);
    held_.clear();
    leave_path(ViewerCameraMode::orbit, path_camera);
    if (s_.camera == ViewerCameraMode::fly) {
        camera_.move(r, u, f, seconds);
    } else {
        camera_.zoom(f * 4 * seconds);
        camera_.orbit(-r * 240 * seconds, u * 240 * seconds);
    }
}

bool ViewerControls::take_screenshot() { return std::exchange(screenshot_, false); }

}  // namespace patchcull::cli
