// patchcull/import/default_scene.h: scenes for the renderer (the `render` command and the main job):
// placed, animated copies of subdivision models among triangle-mesh occluders, and a camera path.
//
// The built-in default scene follows Niessner & Loop, Fig. 1 (c): animated characters (BigGuy and
// MonsterFrog, ACC patches) standing on a ground plane among walls that act as triangle occluders,
// seen from a camera that moves along a path over a few frames, so that frustum, back-patch and
// occlusion culling (and the temporal statuses of Niessner & Loop §3) all have work to do.
//
// The `city` (a street grid of box buildings with 200+ characters, the camera walking a street)
// and `building` (rooms joined by doors and windows, with cells and portals) scenes are the
// object-level scenes, after G. Zachmann's lecture "Advanced Visibility
// Computations" (bounding-volume hierarchies for many objects, occlusion in cities,
// cells and portals in buildings). Scene files (patchcull/import/scene_file.h) describe the same Scene.
//
// Conventions: world space is y-up, the ground is y = 0, lengths are in character heights
// (every character is scaled to height 1 before it is placed). Patches are posed into the
// scene's frame (Scene::frame_origin; the world when it is 0; the renderer has no model
// matrix): each instance's control points are transformed by its affine instance_to_frame
// (object_to_world moved by the instance's origin and velocity, composed in double and rounded
// once), which maps homogeneous points exactly (w is kept). OBJ models are taken as y-up, the
// built-in teapot as z-up. Worlds of game size: world positions are doubles
// (SceneInstance::origin, CameraPath::origin, Scene::occluder_world) and `render` draws each
// frame in the frame of the grid point nearest its camera (scene_frame_near, rebase_scene), so
// the float data the kernels and the GPU see are small numbers near the eye wherever the scene
// is (scene_file.h's kMaxSceneCoordinate gives the limit and its derivation).
// Rounding: everything else is float. ScenePoser's output is exactly instance_to_frame times the
// (animated) control points, in float (tested bit for bit; for a mirroring transform the same
// products in transposed order, see ScenePoser); the built-in scenes keep characters
// at least 0.1 (plus their reach, measured on the float control points) from walls and buildings,
// far more than any rounding at their sizes (under 100 units from the origin).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "patchcull/import/animation.h"
#include "patchcull/core/camera.h"
#include "patchcull/core/displacement.h"
#include "patchcull/core/math.h"
#include "patchcull/core/mesh.h"
#include "patchcull/core/patch.h"
#include "patchcull/import/scene.h"

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
    Vec3 walk_start{0, 0, 0};      ///< eye at frame 0 (walk)
    Vec3 walk_step{0, 0, 0};       ///< eye movement per frame (walk)
    Vec3 walk_direction{0, 0, -1}; ///< look direction, any non-zero length (walk)
};

/// A cell of a cell-and-portal scene (a room of the `building` scene; read by the portal
/// traversal). The cells' boxes tile the interior: neighbouring rooms' boxes meet at the
/// mid-plane of the wall between them, so every eye inside the building (doorways included) is
/// in at least one box.
struct SceneCell {
    std::string name;
    Bounds box;                             ///< world-space box of the cell
    std::vector<std::size_t> instances;     ///< indices into Scene::instances standing in the cell
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

    /// Total patch count over the instances (the size of pose()'s output).
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
/// so that it lies within 8 units of its frame's 0, where the float kernels work at the
/// precision of the built-in scenes (their cameras are 2-15 units from the origin). A coarser
/// grid costs culling: with frames 1024 apart the eye sat up to 512 units from its frame's 0
/// and ptp's rounding margin (which grows with the coordinates) let no back-patch cull through.
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

/// The built-in default scene: three BigGuys and three MonsterFrogs (`scheme`; ACC: 1450 and 1292 patches
/// each, 8226 in all) on a 12 x 12 ground quad with a long low wall in front of them and two
/// pillars between them (20 occluder triangles); the camera circles the group at 2.3 units, 5
/// degrees per frame from -20. The MonsterFrogs are displaced, as the characters of Niessner &
/// Loop's scenes are (Niessner & Loop §6): by make_procedural_displacement(512, kDefaultSceneDisplaceScale),
/// a smooth bump field of +-1.5% of a BigGuy's height along the normal, at the frogs' own
/// texcoords; the BigGuys are not. Throws patchcull::Error when a shipped model cannot be read
/// (PATCHCULL_DATA_DIR as in shipped_model_path).
/// Names: instances "bigguy#0".."bigguy#2", "monsterfrog#0".."monsterfrog#2" (in placement
/// order, BigGuy first); environment "ground" (one-sided, front +y), "wall", "pillar#0",
/// "pillar#1" (boxes, one-sided, counter-clockwise outward). Every instance deforms, none moves.
Scene make_default_scene(Scheme scheme = Scheme::acc);
/// The default scene's displacement scale (world units: a BigGuy is 1 high).
inline constexpr float kDefaultSceneDisplaceScale = 0.03f;

/// A scene of one model (as load_model returns it): scaled to height 1, standing on the ground
/// at the origin, with a ground quad as the only occluder, and a camera path like
/// orbit_sequence's (the whole model in view, 30 degrees above the horizon, `degrees_per_frame`
/// per frame). Names: the instance is the model file's stem + "#0" ("teapot#0"), the
/// environment object "ground".
Scene make_model_scene(LoadedModel model, float degrees_per_frame = 5.0f);

/// Appends an environment object of `indices.size() / 3` triangles (3 indices each into
/// `vertices`, world space) to Scene::occluder_vertices / occluder_indices and Scene::environment,
/// keeping the tiling. one_sided: see EnvironmentObject (the caller vouches for the winding).
/// Throws patchcull::Error (naming `name`) when indices are not whole triangles or one is out of range.
void add_environment_object(Scene& scene, std::string name, const std::vector<Vec3>& vertices,
                            const std::vector<std::uint32_t>& indices, bool one_sided);
/// Appends an axis-aligned box [lo, hi] as a one-sided environment object: 12 triangles,
/// counter-clockwise seen from outside.
void add_environment_box(Scene& scene, std::string name, Vec3 lo, Vec3 hi);

/// Parameters of the `city` scene. Lengths in character heights (a BigGuy is 1 high).
struct CityParams {
    int blocks_x = 6, blocks_z = 6;  ///< blocks (one box building each), 1..64 per axis
    float block_size = 8;            ///< side of a block's square footprint
    float street_width = 4;          ///< streets run between the blocks and around the grid
    float min_height = 3, max_height = 14;  ///< building heights, uniform in between
    int characters = 220;            ///< BigGuys and MonsterFrogs (alternating), 0..5000
    float rigid_fraction = 0.25f;    ///< share of characters that do not deform
    float walking_fraction = 0.35f;  ///< share that walk along their street (velocity)
    float walk_seconds = 10;         ///< walkers stay in their street and out of the camera's corridor this long
    int phases = 6;                  ///< distinct animation time offsets (1..64), k * 0.37 s
    unsigned seed = 11;              ///< placement, heights and choices (std::mt19937)
    int camera_street = -1;          ///< index of the z street the camera walks; -1: the middle one
};

/// The built-in `city` scene: a blocks_x x blocks_z grid of box buildings (heights
/// uniform in [min_height, max_height], each one EnvironmentObject "building#i", one-sided,
/// counter-clockwise outward) separated by streets, on one ground quad ("ground", one-sided,
/// front +y) that covers the grid and its outer streets. `characters` BigGuys and MonsterFrogs
/// (alternating; `scheme`, ACC by default) stand in the streets at random yaw: a rigid_fraction
/// of them rigid, a walking_fraction walking along their street at 0.3-0.7 units per second,
/// facing their way; the MonsterFrogs displaced by the default scene's procedural map
/// (kDefaultSceneDisplaceScale); time offsets from `phases` values k * 0.37 s (so ScenePoser
/// shares one deformation per model and phase). Over [0, walk_seconds] no character comes within
/// its animated reach (over one animation period, any yaw) plus 0.1 of a building on x or z,
/// leaves the grid, or enters the camera's corridor (0.3 either side of its line); characters
/// start apart, a fifth of them in the camera's street. The camera walks down the middle of z street camera_street (streets 0..blocks_x
/// from -x) from the grid's +z edge towards -z at eye height 0.8 (a character is 1 high), 0.15
/// units per frame, looking down the street (60 degrees): buildings hide the parallel streets,
/// the characters behind the camera are outside the view. Names: "bigguy#k" / "monsterfrog#k"
/// (counted per model). The default makes 220 characters, about 300k ACC patches.
/// Throws patchcull::Error for parameters out of range, when the characters do not fit, or when
/// a shipped model cannot be read.
Scene make_city_scene(Scheme scheme = Scheme::acc, const CityParams& params = {});

/// Parameters of the `building` scene.
struct BuildingParams {
    int rooms_x = 3, rooms_z = 3;     ///< a grid of square rooms, 1..16 per axis
    float room_size = 6;              ///< inner side of a room (wall centre to wall centre)
    float wall_height = 2.5f;
    float wall_thickness = 0.2f;
    int characters_per_room = 10;     ///< 0..64, placed at random in each room (fewer where they do not fit)
    unsigned seed = 5;
};

/// The built-in `building` scene (read by the cell-and-portal culling): a
/// rooms_x x rooms_z grid of rooms under one ceiling. Every wall is built from closed boxes
/// around its openings (one EnvironmentObject per box: "wall#k", one-sided, counter-clockwise
/// outward); each room has a floor slab and a ceiling slab ("floor#i", "ceiling#i", boxes).
/// Neighbouring rooms are joined by a door (1 x 2, in the walls between rooms of one column, and
/// every second wall between columns) or a window (1.2 wide, 1.0-1.8 high, the other walls
/// between columns); the outer walls are closed. The cells are the rooms ("room#i" for the room
/// in column i % rooms_x counted from -x and row i / rooms_x counted from -z; boxes from wall
/// centre to wall centre, from the floor slab's bottom to the ceiling slab's top), the portals
/// the doors and windows; each cell lists its floor, ceiling, wall pieces and posts. Characters (BigGuys and
/// MonsterFrogs, `scheme`, the frogs displaced as in the default scene, every third one rigid)
/// stand in the rooms, away from the walls and from the camera's corridor. The camera walks from
/// the south room of the middle column (largest z) north through its doors at eye height 0.9,
/// crossing the middle column in 60 frames. The default makes 77 characters, about 106k ACC patches.
/// Throws patchcull::Error for parameters out of range, or when a shipped model cannot be read.
Scene make_building_scene(Scheme scheme = Scheme::acc, const BuildingParams& params = {});

/// A built-in scene by name: "default", "city" or "building" (default parameters). Throws
/// patchcull::Error("unknown scene '...' (default, city or building)") for any other name.
Scene make_builtin_scene(const std::string& name, Scheme scheme = Scheme::acc);

/// Evaluates a scene's patches at a time (animation, then each instance's transform), keeping
/// its storage between calls (no allocation after the first pose of the same scene).
/// Instances that share a model and an effective time (time_seconds + time_offset, compared as
/// floats; every rigid instance of a model shares its rest frame) share one deformation and one
/// patch evaluation per pose() call: a city of 220 characters in 6 phases evaluates 12 frames.
///
/// Mirrored instances (instance_mirrors): a mirror turns du x dv of the placed patches into the
/// solid (drawn one-sided, the instance would render inside out). ScenePoser transposes each patch
/// of such an instance, P'(u, v) = P(v, u) (world control point 4j + i is instance_to_world times
/// the model's control point 4i + j), which makes du x dv point outward again (the derivation is in
/// default_scene.cpp); the surface is the same point set, the transposition is exact (only the
/// order of the float products changes). Everything attached to the patch follows: its tangent
/// patches are the model's with du and dv swapped and transposed (du'[3j + i] = mapped dv[4i + j],
/// dv'[4j + i] = mapped du[3i + j]), its corner texcoords have corners (1,0) and (0,1) swapped;
/// its depth and displacement range are the model patch's. The eye-facing test of a transposed
/// world patch equals the model-space test of the model patch with the eye moved into model space
/// by the inverse transform, so model-space patch clusters stay valid for mirrored instances.
/// One model's stencil tables for posing on the GPU (ScenePoser::gpu_tables; gl_posing.h's
/// PosingModel is the same data as plain arrays: the import layer does not depend on GL).
struct PoseModelTables {
    const PointStencils* patch_points = nullptr;    ///< 16 rows per patch (patch.h order)
    const PointStencils* tangent_points = nullptr;  ///< 24 rows per tangent block (may have no rows)
    std::vector<std::int32_t> tangent_index;        ///< per patch: PatchInfo::tangent_index
    std::uint32_t vertex_count = 0;                 ///< vertices of the control mesh the rows index
};

/// The linear inputs of one pose (ScenePoser::gpu_meshes): the control meshes of every (model,
/// effective time) group, concatenated, and each instance's place in them and transform.
struct PoseMeshes {
    std::vector<Vec3> vertices;
    std::vector<std::size_t> first_vertex;  ///< per instance: its group's first vertex
    std::vector<Mat4> to_world;             ///< per instance: instance_to_frame at the pose's time (the scene's frame)
    std::vector<std::uint8_t> mirrored;     ///< per instance: instance_mirrors
};

class ScenePoser {
public:
    explicit ScenePoser(const Scene& scene);
    /// The scene posed (the constructor's; it must outlive the poser).
    const Scene& scene() const { return *scene_; }
    /// The patches of every instance at time_seconds in the scene's frame (world space when
    /// Scene::frame_origin is 0), instance by instance (each instance's patches in its model's
    /// order): instance_to_frame(instance, time_seconds, frame_origin) times the (animated) model
    /// patch, transposed for mirrored instances (see above). The reference stays valid until the
    /// next call.
    const std::vector<BezierPatch>& pose(float time_seconds);
    /// The ACC tangent patches of the last pose (PatchInfo::tangent_index semantics): the entry
    /// of each patch of pose(), -1 when it has none, indexing tangents(), whose vectors are mapped
    /// by the instances' linear parts (du and dv swapped and transposed for mirrored instances,
    /// so that they are the derivatives of pose()'s patch). Empty before the first pose.
    const std::vector<std::int32_t>& tangent_index() const { return tangent_index_; }
    const std::vector<TangentPatches>& tangents() const { return tangents_; }
    /// PatchInfo::depth of each patch of the last pose (for gl::PatchAttributes::depth).
    const std::vector<std::uint8_t>& depth() const { return depth_; }
    /// Corner texcoords (PatchInfo::uv, in the order of pose()'s patch: corners (1,0) and (0,1)
    /// swapped for instances that mirrored at construction) and displacement range (the model
    /// patch's, unchanged by the swap) of each patch of pose(), fixed for the scene (computed at
    /// construction from Scene::displacement: the range is zero for instances that are not
    /// displaced); both empty when the scene has no displacement.
    const std::vector<std::array<Vec2, 4>>& texcoords() const { return texcoords_; }
    const std::vector<DisplacementRange>& displacement_ranges() const { return ranges_; }

    // ---- posing on the GPU (gl_posing.h's StencilPoser) ------------------------------------
    /// The stencil tables whose rows, applied to gpu_meshes()'s vertices and mapped by each
    /// instance's transform (transposed for mirrored instances), give exactly pose()'s patches and
    /// tangents(), per model (Scene::models order). A subdivision model's own tables
    /// (SubdivisionModel::patch_points, tangent_points: pointers into the scene, valid while it
    /// lives); a model without a control mesh (the teapot) gets identity rows over its rest
    /// control points (one term of weight 1 each: exact), made once and kept here. Throws
    /// patchcull::Error naming the model when its patches were split (LoadedModel::split_levels
    /// > 0: splits are not stencil rows here) or a rest control point has w != 1.
    const std::vector<PoseModelTables>& gpu_tables();
    /// The control meshes of the pose at time_seconds, grouped as pose() groups them (one
    /// animate() per model and effective time; rigid instances share their model's rest mesh:
    /// the teapot's rest control points), plus each instance's group, transform and mirroring.
    /// Evaluates no patch. The reference stays valid until the next call; no allocation after
    /// the first call on the same scene.
    const PoseMeshes& gpu_meshes(float time_seconds);

private:
    // Instances sorted by (model, effective time) into order_, effective times into times_.
    void group_instances(float time_seconds);
    std::vector<PoseModelTables> gpu_tables_;
    std::vector<PointStencils> identity_tables_;  ///< per model: the teapot's identity rows
    PointStencils no_tangents_;
    PoseMeshes meshes_;

    const Scene* scene_;
    std::vector<Vec3> positions_;
    PatchFrame frame_;
    std::vector<std::size_t> first_patch_;    ///< per instance: its first patch in pose()'s output
    std::vector<std::size_t> first_tangent_;  ///< per instance: its first entry of tangents()
    std::vector<std::size_t> order_;          ///< instances sorted by (model, effective time)
    std::vector<float> times_;                ///< per instance: effective time (rest: -inf)
    std::vector<std::size_t> tangent_counts_; ///< per model: patches with tangent patches
    std::vector<BezierPatch> patches_;
    std::vector<std::int32_t> tangent_index_;
    std::vector<TangentPatches> tangents_;
    std::vector<std::uint8_t> depth_;
    std::vector<std::array<Vec2, 4>> texcoords_;
    std::vector<DisplacementRange> ranges_;
};

}  // namespace patchcull
