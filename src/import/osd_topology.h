// Internal: builds an OpenSubdiv Far::TopologyRefiner from a patchcull ControlMesh, shared by
// the osd scheme (src/import/osd.cpp) and the uniform refinement (src/import/refine.cpp).
//
// Source: OpenSubdiv 3.5 Far (Far::TopologyDescriptor + TopologyRefinerFactory), set up as in
// Niessner & Loop and Loop, Niessner & Eisenacher: Catmull-Clark, vertex boundary interpolation
// EDGE_AND_CORNER, creases and corners from the mesh, one face-varying channel for texture
// coordinates (linear everywhere); the mesh's SubdivisionOptions (boundary interpolation, crease
// method, triangle rule) and holes
// (Far skips hole faces when it builds patches) replace the defaults where an OBJ tagged them.
//
// Why a validation pass of our own: Far reports topology errors through a process-wide printf
// callback and returns nullptr, and it silently accepts non-manifold topology (it sharpens it).
// patchcull wants a one-line patchcull::Error naming mesh.name instead, and rejects
// non-manifold meshes (the culling bounds assume a 2-manifold surface, and OBJ files with
// non-manifold edges are nearly always broken exports).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <opensubdiv/far/topologyRefiner.h>

#include "patchcull/core/mesh.h"

namespace patchcull::osd_detail {

/// Feature-adaptive isolation level of the osd scheme (why 2: see src/import/osd.cpp). Tests
/// build their OpenSubdiv reference evaluation with the same level.
inline constexpr int kOsdIsolationLevel = 2;

struct RefinerDeleter {
    void operator()(OpenSubdiv::Far::TopologyRefiner* r) const;
};
using RefinerPtr = std::unique_ptr<OpenSubdiv::Far::TopologyRefiner, RefinerDeleter>;

/// Validates mesh and builds its level-0 refiner (not yet refined). Throws patchcull::Error
/// "<mesh.name>: <reason>" for out-of-range indices, faces with fewer than 3 corners or a
/// repeated vertex, bad crease/corner records, Far topology errors and non-manifold edges or
/// vertices (worded as the acc scheme words them: import/mesh_messages.h). Far warnings (if any)
/// are appended to warnings.
RefinerPtr create_refiner(const ControlMesh& mesh, std::vector<std::string>* warnings = nullptr);

}  // namespace patchcull::osd_detail
