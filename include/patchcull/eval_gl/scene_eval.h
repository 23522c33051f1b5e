// Object-level occlusion culling (hardware occlusion queries stop-and-wait and batched, CHC,
// CHC++, the occlusion horizon, cells and portals) side by side with patchcull's per-patch Hi-Z
// culling on one scene's camera path (the CLI's `patchcull eval scene`; the methods' papers in
// docs/METHODS.md).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "patchcull/eval_gl/run_progress.h"
#include "patchcull/import/scene_model.h"
#include "patchcull/import/scene_occlusion.h"

namespace patchcull::eval_gl {

struct SceneEvalOptions {
    int frames = 24;                         ///< of the scene's camera path, at least 1
    float seconds_per_frame = 1.0f / 12.0f;  ///< animation time between two frames
    int width = 640, height = 360;
    int tess = 8;  ///< uniform tessellation level
    /// Method names (rows) in the order asked; empty: every one the scene allows. "none" is
    /// always run, first; a repeated name runs once.
    std::vector<std::string> methods;
    int batch = 16;      ///< b: batched and CHC++'s I-queue
    float sigma = 1.4f;  ///< CHC++ tight bounding volumes' area factor
    int max_tight_boxes = static_cast<int>(kDefaultMaxTightBoxes);
    float c1 = 0.1f;           ///< CHC++ multiquery cost per object
    int visible_interval = 1;  ///< CHC++: previously visible objects queried every n frames
};

/// One method's row: per-frame means over the path, except wait_frames and false_culls (totals).
struct SceneEvalRow {
    std::string name;           ///< the object method's, + "+hiz" when followed by the patch passes
    std::string object_method;  ///< "none", a query method or a scene occlusion method
    bool patch_hiz = false;
    double objects_culled = 0, objects_hidden = 0, patches_hidden = 0, patches_culled = 0;
    double patches_object_culled = 0, patches_frustum_culled = 0, patches_occlusion_culled = 0;
    double queries = 0, multiqueries = 0, multiqueries_passed = 0, proxy_boxes = 0;
    std::size_t wait_frames = 0;
    double waits = 0;
    double ms_object_cpu = 0, ms_pass1 = 0, ms_hiz = 0, ms_cull = 0, ms_pass2 = 0, ms_frame = 0;
    double frame_ratio = 0;  ///< ms_frame over none's (0 before none ran)
    std::size_t false_culls = 0;
};

struct SceneEvalResult {
    std::string scene;           ///< Scene::name
    std::size_t objects = 0;     ///< the object level's objects (instances and environment)
    std::size_t characters = 0;  ///< instances
    std::size_t patches = 0;
    std::vector<SceneEvalRow> rows;  ///< in the order run, none first
    std::size_t false_culls = 0;     ///< over every row
};

/// Runs every method from a first frame along scene's camera path (frames 0..frames-1, the
/// animation at seconds_per_frame), comparing each frame with the unculled render of its view
/// (strict: a front patch not drawn, or a culled occluder triangle the reference shows). scene:
/// as loaded and placed (place_scene_at_first_camera). Throws patchcull::Error
/// "--methods: 'X' is not a method for scene 'S' (...)" for a name the scene does not allow.
/// Progress: one unit per method and frame. Needs an OpenGL 4.5 context (headless).
SceneEvalResult run_scene_eval(Scene scene, const SceneEvalOptions& options, const RunProgress& progress = {});

}  // namespace patchcull::eval_gl
