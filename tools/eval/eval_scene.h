// `patchcull eval scene` (tools/eval/eval_scene.cpp; the run: eval_gl/scene_eval.h): the
// object-level occlusion methods (hardware occlusion queries stop-and-wait and batched, CHC,
// CHC++, the occlusion horizon, cells and portals) side by side with patchcull's per-patch Hi-Z
// culling on one scene's camera path, registered by tools/cmd_eval.cpp.
#pragma once

#include <string>

#include "patchcull/import/scene_occlusion.h"

namespace patchcull::cli {

struct SceneEvalOptions {
    std::string scene;  ///< "city", "building", "default" or a scene file
    std::string scheme = "acc";
    int frames = 24;
    std::string size = "640x360";
    int tess = 8;
    std::string methods;  ///< comma list of method names; empty: every one the scene allows
    int batch = 16;       ///< b: batched and CHC++'s I-queue
    float sigma = 1.4f;   ///< CHC++ tight bounding volumes
    int max_tight_boxes = static_cast<int>(kDefaultMaxTightBoxes);
    float c1 = 0.1f;           ///< CHC++ multiquery cost per object
    int visible_interval = 1;  ///< CHC++: previously visible objects queried every n frames
    bool json = false;
};

/// Parses the options, loads and places the scene, runs eval_gl::run_scene_eval and prints its
/// table or JSON; 1 when a method culled what the unculled render shows.
int run_scene_eval(const SceneEvalOptions& options);

}  // namespace patchcull::cli
