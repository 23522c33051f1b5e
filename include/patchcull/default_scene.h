// patchcull/default_scene.h: scenes for the renderer (the `render` command and the main job):
// placed, animated copies of subdivision models among triangle-mesh occluders, and a camera path.
//
// The built-in default scene follows seed 000 Fig. 1 (c): animated characters (BigGuy and
// MonsterFrog, ACC patches) standing on a ground plane among walls that act as triangle occluders,
// seen from a camera that moves along a path over a few frames, so that frustum, back-patch and
// occlusion culling (and the temporal statuses of seed 000 §3) all have work to do.
//
// Conventions: world space is y-up, the ground is y = 0, lengths are in character heights
// (every character is scaled to height 1 before it is placed). Patches are world-space (the
// renderer has no model matrix): each instance's control points are transformed by its affine
// object_to_world, which maps homogeneous points exactly (w is kept). OBJ models are taken as
// y-up, the built-in teapot as z-up.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "patchcull/animation.h"
#include "patchcull/camera.h"
#include "patchcull/displacement.h"
#include "patchcull/math.h"
#include "patchcull/mesh.h"
#include "patchcull/patch.h"
#include "patchcull/scene.h"

namespace patchcull {

/// One placed copy of a model.
struct SceneInstance {
    std::size_t model = 0;   ///< index into Scene::models
    Mat4 object_to_world;    ///< affine: the model's object space -> world
    float time_offset = 0;   ///< seconds added to the scene time, so copies move out of step
    bool displaced = false;  ///< displaced by Scene::displacement (when it is not empty)
};

/// A camera circling a target: at frame f the eye is at angle start + f * step (degrees, about
/// the world y axis, angle 0 on +z) at horizontal distance `distance` and height `height` above
/// the target, looking at the target.
struct CameraPath {
    Vec3 target{0, 0, 0};
    float distance = 5;
    float height = 1;
    float start_degrees = 0;
    float degrees_per_frame = 5;
    float fovy_radians = 1.0471976f;  ///< 60 degrees
    float z_near = 0.05f;
    float z_far = 50;
};

struct Scene {
    std::string name;
    std::vector<LoadedModel> models;
    std::vector<SceneInstance> instances;
    /// Triangle occluders (world space), for PatchRenderer::set_occluders.
    std::vector<Vec3> occluder_vertices;
    std::vector<std::uint32_t> occluder_indices;
    AnimationParams animation;  ///< applied to every subdivision model (the teapot stays rigid)
    /// The height map of the displaced instances (displacement.h: D = scale * (h - midlevel) along
    /// the unit normal, in world units), sampled at each patch's corner texcoords (PatchInfo::uv);
    /// empty: nothing is displaced. displacement_name says where it came from ("procedural", a
    /// PNG path, or "none").
    DisplacementMap displacement;
    std::string displacement_name = "none";
    CameraPath camera;

    /// Total patch count over the instances (the size of pose()'s output).
    std::size_t patch_count() const;
    /// Cameras of frames 0 .. frames-1 along `camera` (aspect = width / height).
    std::vector<Camera> camera_path(int frames, float aspect) const;
};

/// The built-in default scene: three BigGuys and three MonsterFrogs (`scheme`; ACC: 1450 and 1292 patches
/// each, 8226 in all) on a 12 x 12 ground quad with a long low wall in front of them and two
/// pillars between them (20 occluder triangles); the camera circles the group at 2.3 units, 5
/// degrees per frame from -20. The MonsterFrogs are displaced, as the characters of Niessner &
/// Loop's scenes are (seed 000 §6): by make_procedural_displacement(512, kDefaultSceneDisplaceScale),
/// a smooth bump field of +-1.5% of a BigGuy's height along the normal, at the frogs' own
/// texcoords; the BigGuys are not. Throws patchcull::Error when a shipped model cannot be read
/// (PATCHCULL_DATA_DIR as in shipped_model_path).
Scene make_default_scene(Scheme scheme = Scheme::acc);
/// The default scene's displacement scale (world units: a BigGuy is 1 high).
inline constexpr float kDefaultSceneDisplaceScale = 0.03f;

/// A scene of one model (as load_model returns it): scaled to height 1, standing on the ground
/// at the origin, with a ground quad as the only occluder, and a camera path like
/// orbit_sequence's (the whole model in view, 30 degrees above the horizon, `degrees_per_frame`
/// per frame).
Scene make_model_scene(LoadedModel model, float degrees_per_frame = 5.0f);

/// Evaluates a scene's patches at a time (animation, then each instance's transform), keeping
/// its storage between calls (no allocation after the first pose of the same scene).
class ScenePoser {
public:
    explicit ScenePoser(const Scene& scene);
    /// World-space patches of every instance at time_seconds, instance by instance (each
    /// instance's patches in its model's order). The reference stays valid until the next call.
    const std::vector<BezierPatch>& pose(float time_seconds);
    /// The ACC tangent patches of the last pose (PatchInfo::tangent_index semantics): the entry
    /// of each patch of pose(), -1 when it has none, indexing tangents(), whose vectors are mapped
    /// by the instances' linear parts. Empty before the first pose.
    const std::vector<std::int32_t>& tangent_index() const { return tangent_index_; }
    const std::vector<TangentPatches>& tangents() const { return tangents_; }
    /// PatchInfo::depth of each patch of the last pose (for gl::PatchAttributes::depth).
    const std::vector<std::uint8_t>& depth() const { return depth_; }
    /// Corner texcoords (PatchInfo::uv) and displacement range of each patch of pose(), fixed for
    /// the scene (computed at construction from Scene::displacement: (0, 0) for instances that are
    /// not displaced); both empty when the scene has no displacement.
    const std::vector<std::array<Vec2, 4>>& texcoords() const { return texcoords_; }
    const std::vector<DisplacementRange>& displacement_ranges() const { return ranges_; }

private:
    const Scene* scene_;
    std::vector<Vec3> positions_;
    PatchFrame frame_;
    std::vector<BezierPatch> patches_;
    std::vector<std::int32_t> tangent_index_;
    std::vector<TangentPatches> tangents_;
    std::vector<std::uint8_t> depth_;
    std::vector<std::array<Vec2, 4>> texcoords_;
    std::vector<DisplacementRange> ranges_;
};

}  // namespace patchcull
