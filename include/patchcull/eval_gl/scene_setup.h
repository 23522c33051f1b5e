// A scene as the evaluation runs draw it: whether it is one-sided, the renderer's attributes of a
// pose, its occluders, and its objects (one patch range per instance).
#pragma once

#include <string>
#include <vector>

#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/import/scene_model.h"
#include "patchcull/import/scene_poser.h"

namespace patchcull::eval_gl {

/// True when every model of the scene is a closed, outward-oriented surface (LoadedModel::closed):
/// the scene is drawn one-sided and back-patch culling is conservative on it.
bool scene_is_one_sided(const Scene& scene);

/// The renderer's attributes of the poser's last pose: its ACC tangent patches (shading normals),
/// refinement depths, and for a displaced scene the texcoords and displacement ranges. Pose first,
/// in a statement of its own: in `set_patches(poser.pose(t), pose_attributes(poser))` C++ may
/// evaluate the attributes first (GCC does), which gives the previous pose's.
gl::PatchAttributes pose_attributes(const ScenePoser& poser);

/// PatchRenderer::set_occluders with the scene's occluders, the one-sided environment objects
/// (EnvironmentObject::one_sided) drawn with back faces culled.
void upload_scene_occluders(gl::PatchRenderer& renderer, const Scene& scene);

/// One object of a scene: an instance's patches in the pose (ScenePoser's order: instance by
/// instance, each in its model's order).
struct SceneObject {
    /// SceneInstance::name; for an unnamed instance the model's file name without extension, '#',
    /// its number among that model's instances from 0.
    std::string name;
    gl::ObjectRange range;  ///< first patch, patch count; cull = true
};
/// The scene's objects, one per instance, in instance order (their ranges tile [0, patch_count())).
std::vector<SceneObject> scene_objects(const Scene& scene);

}  // namespace patchcull::eval_gl
