// patchcull/import/scene_model.h: the Scene the renderer draws (the `render` command and the main
// job): placed, animated copies of subdivision models (SceneInstance), triangle-mesh occluders
// (EnvironmentObject), a camera path, and for cell-and-portal scenes cells and portals.
// Built by builtin_scenes.h or read from a scene file (scene_file.h); posed by scene_poser.h.
//
// Conventions: world space is y-up, the ground is y = 0, lengths are in character heights.
// Everything the kernels and the GPU see is float in the scene's frame (Scene::frame_origin, the
// world when it is 0); world positions are doubles (SceneInstance::origin, CameraPath::origin,
// Scene::occluder_world, cell_world, portal_world), and rebase_scene moves the float frame next to
// a camera, rounding once. Why the frames are 16 units apart and how far a scene may reach:
// docs/SCENES.md.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "patchcull/core/camera.h"
#include "patchcull/core/displacement.h"
#include "patchcull/core/math.h"
#include "patchcull/core/mesh.h"
#include "patchcull/core/patch.h"
#include "patchcull/import/animation.h"
#include "patchcull/import/model_loader.h"

namespace patchcull {

/// One placed copy of a model.
struct SceneInstance {
    std::size_t model = 0;   ///< index into Scene::models
    Mat4 object_to_world;    ///< affine: the model's object space -> world (moved by velocity: instance_to_world)
    float time_offset = 0;   ///< seconds added to the scene time, so copies move out of step
    bool displaced = false;  ///< displaced by Scene::displacement (when it is not empty)
    /// Unique among the scene's instances, e.g. "bigguy#3" (every scene builder and the scene
    /// file reader set it; per-object statistics and scene cells name instances by it).
    std::string name;
    /// True: Scene::animation deforms the control mesh (at scene time t + time_offset). False:
    /// rigid, the model's rest patches every frame (the teapot is always rigid).
    bool deforms = true;
    /// Rigid motion in world units per second (see instance_to_world); zero: it stays in place.
    Vec3 velocity{0, 0, 0};
    /// World position (double) of the instance's own frame: the instance is placed by
    /// translation(origin) * object_to_world, and object_to_world's translation stays small (the
    /// scene file reader keeps it within half a kSceneFrameGrid of 0: scene_frame_near).
    /// Composed in double with the motion and the scene's frame (instance_to_frame). 0 for the
    /// built-in scenes.
    DVec3 origin;
    // A mirroring object_to_world (instance_mirrors: det of the linear part < 0) is allowed:
    // ScenePoser poses such an instance with its patches' parameterisation reversed (u and v
    // swapped), so that du x dv of the world patches points out of the mirrored solid.
};

/// True when the instance's transform mirrors: the determinant of object_to_world's linear part
/// (upper-left 3x3, computed in double from the float entries) is < 0. Singular (det == 0) and
/// proper transforms: false. The velocity does not change it (instance_to_world's linear part is
/// object_to_world's).
bool instance_mirrors(const SceneInstance& instance);

/// The instance's transform at scene time t into the frame whose 0 is the world point
/// frame_origin: translation(origin - frame_origin + velocity * (t + time_offset)) *
/// object_to_world. Affine (the w row is kept, so homogeneous control points map exactly as by
/// object_to_world); the linear part is object_to_world's. The translation is composed in
/// double (object_to_world's column 3, origin - frame_origin, velocity x time) and rounded once
/// to float into column 3: an instance 1e6 units out, seen from a camera beside it, gets a
/// small, exact translation.
Mat4 instance_to_frame(const SceneInstance& instance, float time_seconds, DVec3 frame_origin);
/// instance_to_frame into the world frame (frame_origin 0).
Mat4 instance_to_world(const SceneInstance& instance, float time_seconds);

/// A triangle-mesh object of the environment: triangles [first_triangle, first_triangle +
/// triangle_count) of Scene::occluder_indices (3 indices each). Drawn and occluding.
struct EnvironmentObject {
    std::string name;  ///< unique among the scene's environment objects, e.g. "ground", "wall"
    std::uint32_t first_triangle = 0, triangle_count = 0;
    /// Drawn with back faces culled: every triangle is counter-clockwise seen from its front, and
    /// nothing is visible from behind (closed outward solids: boxes, buildings; the ground seen
    /// from above). False: drawn two-sided.
    bool one_sided = false;
};

/// The camera path of a scene: an orbit (walk == false) or a straight walk (walk == true).
/// Orbit: at frame f the eye is at angle start + f * step (degrees, about the world y axis,
/// angle 0 on +z) at horizontal distance `distance` and height `height` above the target,
/// looking at the target.
/// Walk: at frame f the eye is at walk_start + f * walk_step, looking along walk_direction
/// (target = eye + walk_direction; the up vector is +y, so walk_direction must not be vertical).
/// distance and height are not used by a walk's cameras; the walk scenes set them to a typical
/// viewing distance (hypot(distance, height) is the CLI's default adaptive-tessellation distance).
struct CameraPath {
    /// World position (double) that target and walk_start are relative to (0 for the built-in
    /// scenes; the scene file reader keeps them within half a kSceneFrameGrid of it: scene_frame_near).
    DVec3 origin;
    Vec3 target{0, 0, 0};
    float distance = 5;
    float height = 1;
    float start_degrees = 0;
    float degrees_per_frame = 5;
    float fovy_radians = 1.0471976f;  ///< 60 degrees
    float z_near = 0.05f;
    float z_far = 50;
    bool walk = false;
    Vec3 walk_start{0, 0, 0};       ///< eye at frame 0 (walk)
    Vec3 walk_step{0, 0, 0};        ///< eye movement per frame (walk)
    Vec3 walk_direction{0, 0, -1};  ///< look direction, any non-zero length (walk)
};

/// A cell of a cell-and-portal scene (a room of the `building` scene; read by the portal
/// traversal). The cells' boxes tile the interior: neighbouring rooms' boxes meet at the
/// mid-plane of the wall between them, so every eye inside the building (doorways included) is
/// in at least one box.
struct SceneCell {
    std::string name;
    Bounds box;                          ///< world-space box of the cell
    std::vector<std::size_t> instances;  ///< indices into Scene::instances standing in the cell
    /// Indices into Scene::environment of the objects that bound or fill the cell: its floor,
    /// ceiling and wall pieces (a wall between two cells is listed in both).
    std::vector<std::size_t> environment;
};

/// An opening between two cells (a door or window rectangle), in the mid-plane of its wall.
struct ScenePortal {
    std::size_t cell_a = 0, cell_b = 0;  ///< indices into Scene::cells, different
    /// The rectangle's corners, in order around it, counter-clockwise seen from cell_a (its
    /// normal by the right-hand rule points into cell_a).
    Vec3 corners[4];
};

struct Scene {
    std::string name;
    std::vector<LoadedModel> models;
    std::vector<SceneInstance> instances;
    /// The world position (double) of the scene's float frame: occluder_vertices, cells, portals,
    /// the patches ScenePoser poses and the cameras camera_path gives are relative to it (they
    /// hold small numbers near the camera when it is near the camera: rebase_scene). 0 as built
    /// and as read from a file (the world frame).
    DVec3 frame_origin;
    /// Triangle occluders (in the scene's frame), for PatchRenderer::set_occluders.
    std::vector<Vec3> occluder_vertices;
    /// The occluder vertices in world coordinates (double), as the scene file reader places them:
    /// empty (then occluder_vertices + frame_origin are the world vertices), or one per
    /// occluder vertex. rebase_scene rounds them into a new frame once.
    std::vector<DVec3> occluder_world;
    std::vector<std::uint32_t> occluder_indices;
    /// The occluder triangles grouped into objects: their ranges tile occluder_indices exactly,
    /// in order (object k starts where object k-1 ends; the first starts at triangle 0).
    std::vector<EnvironmentObject> environment;
    AnimationParams animation;  ///< applied to every deforming subdivision instance
    /// The height map of the displaced instances (displacement.h: D = scale * (h - midlevel) along
    /// the unit normal, in world units), sampled at each patch's corner texcoords (PatchInfo::uv);
    /// empty: nothing is displaced. displacement_name says where it came from ("procedural", a
    /// PNG path, or "none").
    DisplacementMap displacement;
    std::string displacement_name = "none";
    CameraPath camera;
    /// Cells and portals (the `building` scene, scene files with "cells"); both empty elsewhere.
    std::vector<SceneCell> cells;
    std::vector<ScenePortal> portals;
    /// The cells' boxes (min, max) and the portals' corners in world coordinates (double), as the
    /// scene file reader places them: empty (then the floats + frame_origin are the world's), or
    /// one per cell and one per portal. rebase_scene rounds them into a new frame once.
    std::vector<std::array<DVec3, 2>> cell_world;
    std::vector<std::array<DVec3, 4>> portal_world;

    /// Total patch count over the instances (the size of ScenePoser::pose()'s output).
    std::size_t patch_count() const;
    /// Cameras of frames 0 .. frames-1 along `camera` (aspect = width / height), orbit or walk,
    /// in the scene's frame. Where the path's origin is the frame's (the built-in scenes, files
    /// near the origin), computed in float as always; else eye and target are composed in
    /// double (world_camera_path) and moved into the frame (WorldCamera::local).
    std::vector<Camera> camera_path(int frames, float aspect) const;
    /// The same cameras in world coordinates (double): eye = origin + walk_start + f x walk_step,
    /// or the orbit's eye around origin + target.
    std::vector<WorldCamera> world_camera_path(int frames, float aspect) const;
};

/// The frames scenes are drawn in (rebase_scene) and the scene file reader's world origins
/// (SceneInstance::origin, CameraPath::origin): a point within kSceneWorldFrame of the world's
/// origin on every axis stays in the world frame (0: scenes near the origin are drawn as they
/// always were); a point farther out gets the nearest multiple of kSceneFrameGrid on each axis,
/// so that it lies within 8 units of its frame's 0 (why 16: docs/SCENES.md).
inline constexpr double kSceneFrameGrid = 16;
inline constexpr double kSceneWorldFrame = 1024;

/// The frame origin for a camera at world point eye, or for a position the scene file reader
/// places (see kSceneFrameGrid): 0 within kSceneWorldFrame of the origin, else the nearest
/// multiple of kSceneFrameGrid on each axis.
DVec3 scene_frame_near(DVec3 eye);

/// Moves a scene's float frame to the world point origin: `frame` gets world's instances,
/// environment, camera path, cells and portals, with every float that is relative to the frame
/// (occluder vertices, cells, portals) rounded once from world coordinates composed in double;
/// instances and the camera path keep their world origins (ScenePoser and camera_path subtract
/// frame_origin in double). frame.models are left as they are (the caller's: usually the same
/// models as world's, moved or shared). world is not changed; its own frame may be any. Object
/// levels and uploads built on `frame` must be made again after a rebase (occluder indices come
/// back in world's order).
void rebase_scene(const Scene& world, DVec3 origin, Scene& frame);

/// rebase_scene of a scene onto itself: moves `scene`'s frame to origin, keeping its models, and
/// returns the placements it had (a copy without the models) for later rebase_scene calls.
Scene rebase_scene_in_place(Scene& scene, DVec3 origin);

}  // namespace patchcull
