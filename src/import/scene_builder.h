// Building blocks of the scene builders (not a public header): the transforms that place models
// and the environment objects they add (patchcull/import/scene_model.h), shared by the built-in
// scenes (builtin_scenes.cpp) and the scene file reader (scene_file.cpp); scene_builder.cpp.
#pragma once

#include <string>
#include <vector>

#include "patchcull/import/model_loader.h"
#include "patchcull/import/scene_model.h"

namespace patchcull::detail {

inline constexpr float kPi = 3.14159265358979f;

Mat4 translation(Vec3 t);
Mat4 scaling(float s);
/// Rotation about the world y axis by `degrees` (counter-clockwise seen from +y): +z goes to
/// (sin a, 0, cos a).
Mat4 rotation_y(float degrees);
/// The built-in teapot is z-up: (x, y, z) -> (x, z, -y) stands it on the y = 0 plane.
Mat4 teapot_to_y_up();

/// Bounds of the rest control points mapped by m.
Bounds transformed_bounds(const PatchFrame& frame, const Mat4& m);

/// Object space -> "standing" space: y-up, scaled to height `height`, centred on x = z = 0, feet
/// at y = 0 (from the control points at rest, which bound the surface). Throws Error when the
/// model has no height.
Mat4 standing_transform(const LoadedModel& model, float height);

/// Appends an environment object of the given triangles (world space, 3 indices each into
/// `vertices`) to the scene's occluders and environment.
void add_triangles(Scene& scene, std::string name, const std::vector<Vec3>& vertices,
                   const std::vector<std::uint32_t>& indices, bool one_sided);
/// An axis-aligned box [lo, hi] as 12 triangles, counter-clockwise seen from outside, one-sided.
void add_box(Scene& scene, std::string name, Vec3 lo, Vec3 hi);
/// A quad c0 c1 c2 c3 (counter-clockwise seen from its front) as triangles (c0 c1 c2) (c0 c2 c3).
void add_quad(Scene& scene, std::string name, const Vec3 corners[4], bool one_sided);
/// The ground: a square quad of half side half_size at y = -0.002 (feet resting on y = 0 are not
/// tied with it in depth), one-sided with its front +y, named "ground".
void add_ground(Scene& scene, float half_size);

/// Loads bigguy.obj and monsterfrog.obj (scheme) as models 0 and 1 of an empty scene.
void load_characters(Scene& scene, Scheme scheme);

/// The largest horizontal distance from the standing axis (x = z = 0) that the model's control
/// points reach, placed by `standing` and deformed by `animation` at `samples` times over one
/// period (the reach of a character at any yaw; rigid models: at rest).
float animated_reach(const LoadedModel& model, const Mat4& standing, const AnimationParams& animation, int samples);

}  // namespace patchcull::detail
