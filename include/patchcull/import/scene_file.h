// patchcull/import/scene_file.h: scene files, the JSON form of a Scene (patchcull/import/scene_model.h): placed,
// animated subdivision characters and triangle-mesh environment objects that are drawn and
// occlude, a displacement map, a camera path, and optional cells and portals (the
// object-level scenes of G. Zachmann's lecture "Advanced Visibility Computations", and of
// Niessner & Loop, "Patch-Based Occlusion Culling for Hardware Tessellation").
// The format is documented, with a complete example, in docs/SCENE_FORMAT.md; data/scenes/ holds
// default.json (the built-in default scene), city_small.json and building.json.
//
// Strict by design, like the OBJ reader: every unknown or duplicate key, wrong type, missing
// required key, empty array where one is needed, number out of range (non-finite, beyond a
// float, negative or zero scale, a singular or non-affine matrix), unknown name, unreadable file
// or model is a patchcull::Error whose what() is one short line naming the file and the JSON path:
//   "scenes/a.json: objects[3].transform: expected 16 numbers"
//   "scenes/a.json:7:12: syntax error while parsing object key - ..." (JSON syntax: line, column)
// Input text in messages is quoted through quote_input (patchcull/core/error.h).
//
// Float rounding: numbers are read as double and must fit a float (|x| <= FLT_MAX, else an
// error). World positions (objects' positions and translations, environment corners, camera
// targets and walk starts) stay in double: each is split into a frame origin (scene_frame_near:
// SceneInstance::origin, CameraPath::origin) and a float rest within 8 of it; environment
// vertices are kept in double too (Scene::occluder_world). Within kSceneWorldFrame (1024) of the
// world's origin the origin is 0 and transforms are composed in float exactly as the built-in scenes compose them
// (so default.json reproduces make_default_scene bit for bit). Placed models and environment
// vertices must lie within kMaxSceneCoordinate of the origin and be at least kMinMeshDiagonal
// across (model_loader.h's load_model limit, applied in world space); cells and portals are world
// positions in double too (Scene::cell_world, Scene::portal_world).
#pragma once

#include <cstdint>
#include <string>

#include "patchcull/import/scene_model.h"

namespace patchcull {

/// The largest world coordinate a scene may place anything at or move anything to (objects'
/// control points, environment vertices, positions, cameras), 2^29. Scenes keep world positions
/// in double (SceneInstance::origin, CameraPath::origin, Scene::occluder_world, cell_world,
/// portal_world) and `render`
/// draws and culls each frame in a float frame near its camera (rebase_scene): what stays in
/// float is an object's own extent, the frame-relative offsets (the eye within 8 units of 0),
/// and each object's offset from the frame, composed in double and rounded once into its
/// matrix. The limit is where the doubles stop being finer than those floats: a double's
/// spacing at 2^29 is 2^29 x 2^-52 = 2^-23, the spacing of floats in [1, 2), the float data of a
/// character (1 unit high) next to the camera. Beyond it the world position itself would be
/// coarser than the floats it is rounded into, so a scene reaching farther is refused with one
/// line (docs/ENGINE.md, "Worlds of game size").
inline constexpr double kMaxSceneCoordinate = 536870912;
/// How far from their one float frame commands that draw a whole run in it (demo, eval, view)
/// take a scene: those commands move the scene's frame once, to their first camera's grid point
/// (scene_frame_near, rebase_scene), and everything the run reaches must stay within this
/// distance of it on every axis. Measured in float world coordinates: a rigid BigGuy 2e4 units
/// from the frame's 0 had visible patches culled by the Hi-Z test (2 in 6 frames), at 1e4 none;
/// 8192 keeps a margin. `render` moves its frame with the camera each frame and has no such limit.
inline constexpr double kMaxSingleFrameReach = 8192;

/// Checks what a scene reaches before it is drawn: over frames 0 .. frames - 1 (frame f at scene
/// time f * seconds_per_frame), every instance's placed rest control points moved by its
/// velocity x (time + time_offset), every camera's eye and target (a walk's start + f x step,
/// an orbit's eye at distance and height around its target), the environment, the cells and the
/// portals must stay within `limit` of `centre` on every axis (world coordinates): the world's
/// origin and kMaxSceneCoordinate for every command; the frame's origin and kMaxSingleFrameReach
/// for commands that draw in one frame (place_scene_at_first_camera). load_scene_file checks the
/// placements at rest against kMaxSceneCoordinate; this adds the time, which only the caller
/// knows (its frame count). Throws patchcull::Error, one line, for the first frame that goes
/// beyond: "SOURCE: PATH: ... at frame F ...", PATH the JSON path of the cause in the scene-file
/// form of the scene (instance i is objects[i]: "objects[1].animation.velocity",
/// "objects[0].animation.time_offset", "objects[2].transform", "environment[0]", "cells[1]",
/// "portals[0].corners[2]", "camera.walk.step", "camera.orbit.distance"); source names the scene
/// (its file, or a built-in scene's name).
void check_scene_motion(const Scene& scene, const std::string& source, int frames, double seconds_per_frame,
                        double limit = kMaxSceneCoordinate, DVec3 centre = {});

/// For commands that draw a whole run in one float frame (demo, eval, view): checks the scene's
/// motion over `frames` against kMaxSceneCoordinate, moves the scene's frame to its first
/// camera's grid point (scene_frame_near of frame 0's eye; the scene's models stay) and checks
/// that the run stays within kMaxSingleFrameReach of it. Throws patchcull::Error (one line, as
/// check_scene_motion) when it does not. A scene near the world's origin stays in the world frame.
void place_scene_at_first_camera(Scene& scene, const std::string& source, int frames, double seconds_per_frame);

/// Largest scene file load_scene_file reads (a regular file; devices and FIFOs are refused).
inline constexpr std::uintmax_t kMaxSceneFileBytes = std::uintmax_t{64} << 20;

/// Reads a scene file. Paths inside it (OBJ models and environment meshes, PNG maps) are relative
/// to the file's directory. Each (model file, scheme) pair is loaded once and shared by every
/// object naming it (Scene::models has one entry per pair, in first-use order). Returns the
/// scene with Scene::name from the file's "name" (default: the file name without extension),
/// instances in file order, environment objects tiling the occluders in file order.
/// Throws patchcull::Error (one line, file and JSON path) for any malformed input.
Scene load_scene_file(const std::string& path);

}  // namespace patchcull
