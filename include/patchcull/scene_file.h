// patchcull/scene_file.h: scene files, the JSON form of a Scene (patchcull/default_scene.h): placed,
// animated subdivision characters and triangle-mesh environment objects that are drawn and
// occlude, a displacement map, a camera path, and optional cells and portals (issue 11; the
// object-level scenes of G. Zachmann's lecture "Advanced Visibility Computations", seed 004, and
// of Niessner & Loop, "Patch-Based Occlusion Culling for Hardware Tessellation", seed 000).
// The format is documented, with a complete example, in docs/SCENE_FORMAT.md; data/scenes/ holds
// default.json (the built-in default scene), city_small.json and building.json.
//
// Strict by design, like the OBJ reader: every unknown or duplicate key, wrong type, missing
// required key, empty array where one is needed, number out of range (non-finite, beyond a
// float, negative or zero scale, a singular or non-affine matrix), unknown name, unreadable file
// or model is a patchcull::Error whose what() is one short line naming the file and the JSON path:
//   "scenes/a.json: objects[3].transform: expected 16 numbers"
//   "scenes/a.json:7:12: syntax error while parsing object key - ..." (JSON syntax: line, column)
// Input text in messages is quoted through quote_input (patchcull/error.h).
//
// Float rounding: numbers are read as double and must fit a float (|x| <= FLT_MAX, else an
// error); transforms are composed in float exactly as the built-in scenes compose them (so
// default.json reproduces make_default_scene bit for bit). Placed models and environment
// vertices must lie within kMaxMeshExtent of the origin and be at least kMinMeshDiagonal across
// (scene.h's load_model limits, applied in world space): beyond them the float kernels lose
// their guarantees, so the file is refused rather than culled wrongly.
#pragma once

#include <cstdint>
#include <string>

#include "patchcull/default_scene.h"

namespace patchcull {

/// The largest world coordinate a scene file may place anything at (objects' control points,
/// environment vertices, positions, cameras). A scene is drawn and culled in float world space
/// (no per-object local frame yet): at 2e4 from the origin a rigid BigGuy had visible patches
/// culled by the Hi-Z test (2 in 6 frames, tests/data/scenes/far_rigid_1e5.json moved there), at
/// 1e4 none; 8192 keeps a margin. Farther scenes are refused with one line (move them nearer
/// the origin), not culled wrongly.
inline constexpr double kMaxSceneCoordinate = 8192;

/// Checks what a scene's motion reaches before it is drawn: over frames 0 .. frames - 1 (frame f
/// at scene time f * seconds_per_frame), every instance's placed rest control points moved by its
/// velocity x (time + time_offset), and every camera's eye and target (a walk's start + f x step,
/// an orbit's eye at distance and height around its target), must stay within
/// kMaxSceneCoordinate of the origin. load_scene_file checks the placements at rest; this adds
/// the time, which only the caller knows (its frame count). Throws patchcull::Error, one line,
/// for the first frame that goes beyond: "SOURCE: PATH: ... at frame F ...", PATH the JSON path
/// of the cause in the scene-file form of the scene (instance i is objects[i]:
/// "objects[1].animation.velocity", "objects[0].animation.time_offset", "camera.walk.step",
/// "camera.orbit.distance"); source names the scene (its file, or a built-in scene's name).
void check_scene_motion(const Scene& scene, const std::string& source, int frames, double seconds_per_frame);

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
