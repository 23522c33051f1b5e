// patchcull/import/builtin_scenes.h: the built-in scenes (`default`, `city`, `building`), the
// one-model scene, and the environment builders they share with the scene file reader.
//
// Every character is scaled to height 1 (a MonsterFrog to 0.6 in the default scene) and stands
// on the ground y = 0; OBJ models are taken as y-up, the built-in teapot as z-up. The built-in
// scenes keep characters at least 0.1 (plus their animated reach) from walls and buildings.
// What each scene stands for (Niessner & Loop, Fig. 1 (c); G. Zachmann's "Advanced Visibility
// Computations") and how the placements are drawn: docs/SCENES.md.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "patchcull/core/math.h"
#include "patchcull/import/model_loader.h"
#include "patchcull/import/scene_model.h"

namespace patchcull {

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
    int blocks_x = 6, blocks_z = 6;         ///< blocks (one box building each), 1..64 per axis
    float block_size = 8;                   ///< side of a block's square footprint
    float street_width = 4;                 ///< streets run between the blocks and around the grid
    float min_height = 3, max_height = 14;  ///< building heights, uniform in between
    int characters = 220;                   ///< BigGuys and MonsterFrogs (alternating), 0..5000
    float rigid_fraction = 0.25f;           ///< share of characters that do not deform
    float walking_fraction = 0.35f;         ///< share that walk along their street (velocity)
    float walk_seconds = 10;                ///< walkers stay in their street and out of the camera's corridor this long
    int phases = 6;                         ///< distinct animation time offsets (1..64), k * 0.37 s
    unsigned seed = 11;                     ///< placement, heights and choices (std::mt19937)
    int camera_street = -1;                 ///< index of the z street the camera walks; -1: the middle one
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
/// start apart, a fifth of them in the camera's street. The camera walks down the middle of z street camera_street
/// (streets 0..blocks_x from -x) from the grid's +z edge towards -z at eye height 0.8 (a character is 1 high), 0.15
/// units per frame, looking down the street (60 degrees): buildings hide the parallel streets,
/// the characters behind the camera are outside the view. Names: "bigguy#k" / "monsterfrog#k"
/// (counted per model). The default makes 220 characters, about 300k ACC patches.
/// Throws patchcull::Error for parameters out of range, when the characters do not fit, or when
/// a shipped model cannot be read.
Scene make_city_scene(Scheme scheme = Scheme::acc, const CityParams& params = {});

/// Parameters of the `building` scene.
struct BuildingParams {
    int rooms_x = 3, rooms_z = 3;  ///< a grid of square rooms, 1..16 per axis
    float room_size = 6;           ///< inner side of a room (wall centre to wall centre)
    float wall_height = 2.5f;
    float wall_thickness = 0.2f;
    int characters_per_room = 10;  ///< 0..64, placed at random in each room (fewer where they do not fit)
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

}  // namespace patchcull
