// The viewer's camera (`patchcull view`): orbit around the scene's centre (left-drag, wheel) or
// fly (WASD/QE, right-drag to look), starting where `render`'s camera path starts. Units are
// pixels of mouse motion and seconds of key holding, so that a --script replays exactly. No GL.
#pragma once

#include "patchcull/core/camera.h"

namespace patchcull::cli {

class ViewerCamera {
public:
    /// Starts at start (eye, target, lens) orbiting centre; speed (world units per second of a
    /// held movement key) is a fraction of the start's distance to centre.
    ViewerCamera(const Camera& start, Vec3 centre);

    /// Orbit: turns the eye about the centre, 0.25 degrees per pixel, as if the scene were grabbed
    /// (dx > 0: the eye goes left around the vertical; dy > 0: the eye goes up, the elevation kept
    /// within +-89 degrees); the eye looks at the centre.
    void orbit(float dx_pixels, float dy_pixels);
    /// Orbit: moves the eye toward the centre (steps > 0) or away, 10% of the distance per step;
    /// the distance stays within 1/50 .. 20 times the start's.
    void zoom(float steps);
    /// Fly: turns the view direction, 0.15 degrees per pixel (pitch within +-89 degrees).
    void look(float dx_pixels, float dy_pixels);
    /// Fly: moves the eye along (right, up, forward) of the view, each in -1..1, for seconds.
    void move(float right, float up, float forward, float seconds);
    /// Orbit again after flying or following the path: the eye stays, the view turns to the centre.
    void look_at_centre();
    /// Takes another camera's eye and direction (leaving the path mode where the path was).
    void set_eye_and_target(Vec3 eye, Vec3 target);
    /// Back to the start camera.
    void reset();

    /// The camera (start's lens; the far plane grows as the eye moves away from the centre).
    Camera camera() const;
    Vec3 eye() const { return eye_; }
    Vec3 centre() const { return centre_; }
    /// Unit view direction.
    Vec3 forward() const;

private:
    Camera start_;
    Vec3 centre_;
    float start_distance_;
    Vec3 eye_;
    float yaw_ = 0, pitch_ = 0;  ///< view direction, radians (yaw about +y, 0 = -z)
};

/// The second camera of the status view: the camera turned 90 degrees about its target (the
/// centre the orbit keeps in view), 1.4 times as far and raised, with a 60 degree lens and twice
/// the far plane; the camera `demo` draws cull.png from, so that culled patches show.
Camera second_status_camera(const Camera& camera);

}  // namespace patchcull::cli
