// patchcull/import/model_loader.h: loading a model by name for tools: an OBJ path, "teapot", or a
// shipped model's name ("bigguy", "monsterfrog").
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "patchcull/core/displacement.h"
#include "patchcull/import/subdivision.h"

namespace patchcull {

struct LoadedModel {
    std::string name;  ///< path or "teapot"
    /// World position of the local frame the patches live in (ControlMesh::origin; 0 for the
    /// teapot): a world-space camera must be moved into that frame (WorldCamera::local).
    DVec3 origin;
    std::optional<SubdivisionModel> subdiv;  ///< absent for the built-in teapot (already Bezier)
    int split_levels = 0;
    PatchFrame rest;  ///< patches at rest, after split_levels splits
    std::vector<std::string> warnings;
    /// A closed surface whose every shell faces out of the solid (orient_outward: inside-out
    /// shells were reversed at load, a flat or undecided one is not closed): drawn one-sided
    /// (RenderParams::discard_back_facing), and back-patch culling is conservative for it. False for open meshes and
    /// the teapot (its lid sits loose in the rim).
    bool closed = false;
};

/// The largest extent (bounding-box side, in the mesh's local frame) load_model accepts. The
/// kernels work in float: ptp's rounding margin grows with the fourth power of the size and
/// blocks every cull from about 2e12 units (measured on a box, free views), squared lengths
/// overflow near 1e19. Up to this limit every method culls as at unit size; a wider mesh is
/// refused with one line instead of silently culling less (or nothing, through infinities).
inline constexpr double kMaxMeshExtent = 2e11;
/// The smallest bounding-box diagonal load_model accepts: below it the cameras' float products
/// (near planes, squared radii) reach the subnormal range, and at 1e-10 every free view culled
/// everything (the views lost the object). A smaller mesh is refused with one line.
inline constexpr double kMinMeshDiagonal = 1e-6;

/// Loads spec ("teapot", an OBJ path, or a shipped model's name: resolve_model_path), builds
/// patches with scheme (ignored for the teapot) and applies split_levels 1-to-4 splits. Throws
/// patchcull::Error naming the file and line.
LoadedModel load_model(const std::string& spec, Scheme scheme, int split_levels);

/// Re-evaluates the model's patches for animated control-mesh positions (the teapot is static:
/// frame is rest). out keeps its storage between frames.
void evaluate_frame(const LoadedModel& model, const std::vector<Vec3>& positions, PatchFrame& out);

/// Per-patch displacement ranges [D_min, D_max] (Sathe's pre-processing), or all zero when
/// map is null or empty.
std::vector<DisplacementRange> displacement_ranges(const PatchFrame& frame, const DisplacementMap* map);

/// Bounds of the Cartesian control points of all patches (holds the whole surface).
Bounds patch_bounds(const PatchFrame& frame);

/// Path of a model shipped with patchcull (data/models/NAME), e.g. "bigguy.obj": under
/// $PATCHCULL_DATA_DIR when set and not empty; else under the installed package's data folder a
/// program was built against (find_package(patchcull) defines it for patchcull::import's
/// consumers, relative to where the package was found: see package_data_dir_registered below);
/// else the source tree's data/ while it exists; else share/patchcull/models beside the running
/// program's prefix (PREFIX/bin/.. of an installed CLI, wherever the prefix was moved); else the
/// data installed under the configured prefix. Does not check the file exists.
std::string shipped_model_path(const std::string& file_name);

namespace detail {
/// Makes dir (a package's share/patchcull) the data folder shipped_model_path prefers after
/// $PATCHCULL_DATA_DIR; returns true. Called at static initialisation by the line below.
bool register_package_data_dir(const char* dir);
#ifdef PATCHCULL_PACKAGE_DATA_DIR
/// Set by the installed package's patchcullConfig.cmake on patchcull::import (the package's own
/// share/patchcull, found relative to the config file): a program built against an installed
/// package finds that package's models wherever its prefix is, and not a source tree's. Calls
/// from other static initialisers may run before this one.
inline const bool package_data_dir_registered = register_package_data_dir(PATCHCULL_PACKAGE_DATA_DIR);
#endif
}  // namespace detail

/// The models shipped with patchcull, by name: data/models/NAME.obj.
inline constexpr const char* kShippedModels[] = {"bigguy", "monsterfrog"};
/// The OBJ path of spec: spec itself when a file of that name exists or it names no shipped model,
/// else shipped_model_path(spec + ".obj") ("bigguy" -> .../models/bigguy.obj).
std::string resolve_model_path(const std::string& spec);

}  // namespace patchcull
