// Helpers shared by the CLI's GPU commands (render, view, demo, the evaluations): the scene of a
// MODEL argument, the cull tests conservative on it, and the time between animation frames.
// Render parameters, reference frames and the scene's occluders, objects and pose attributes:
// eval_gl/reference_frame.h, eval_gl/scene_setup.h. Posing: frame_poser.h; options:
// render_options.h, cull_mode_names.h.
#pragma once

#include <string>

#include "patchcull/gl/gl_cull_flags.h"
#include "patchcull/import/scene_model.h"

namespace patchcull::cli {

/// Seconds of animation between two frames of a sequence (frames are 1/12 s apart: a visible
/// motion per frame, as a character at 12 poses per second).
inline constexpr float kSecondsPerFrame = 1.0f / 12.0f;

/// The scene of a MODEL argument: a built-in scene ("default", "city", "building";
/// make_builtin_scene with --scheme), a scene file (a path ending in .json: load_scene_file, whose
/// objects name their own schemes; --scheme is ignored), or a model (OBJ path or "teapot") as
/// make_model_scene places it. --split applies to a model only. Prints the models' loader
/// warnings. Throws patchcull::Error naming the flag or file.
Scene load_scene(const std::string& model, const std::string& scheme_text, int split);

/// The tests of `requested` that are conservative on scene: back-patch culling only when every
/// model is a closed surface (LoadedModel::closed). For a scene with an open model, `all` drops
/// the back-patch test, and an explicit `backpatch` keeps it with a one-line warning on stderr
/// (prefixed with command).
gl::CullMode applicable_cull_mode(const Scene& scene, gl::CullMode requested, const std::string& command);

}  // namespace patchcull::cli
