// Helpers shared by the CLI's GPU commands (render, view, demo, the evaluations): the scene of a
// MODEL argument (its occluders, objects, one-sidedness and the cull tests conservative on it),
// render parameters from a camera, and the unculled reference frame and its comparison with a
// culled one (compare_frames). Posing: frame_poser.h; options: render_options.h, cull_mode_names.h.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "patchcull/core/camera.h"
#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/scene_poser.h"
#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/gl/gl_verification.h"

namespace patchcull::cli {

/// Seconds of animation between two frames of a sequence (frames are 1/12 s apart: a visible
/// motion per frame, as a character at 12 poses per second).
inline constexpr float kSecondsPerFrame = 1.0f / 12.0f;

/// one_sided: RenderParams::discard_back_facing (scene_is_one_sided for the scene drawn).
gl::RenderParams render_params(const Camera& camera, int width, int height, int tess_level, bool one_sided);

/// True when every model of the scene is a closed, outward-oriented surface (LoadedModel::closed):
/// the scene is drawn one-sided (README: "What contributes a pixel") and back-patch culling is
/// conservative on it.
bool scene_is_one_sided(const Scene& scene);

/// The unculled render of the current patches (every patch drawn, flags ignored, statuses kept),
/// its front set (PatchRenderer::mark_front_patches) and the wall-clock time of the render alone
/// (glFinish before and after; the front-set pass is not timed).
struct ReferenceFrame {
    gl::FrameCapture capture;
    double ms = 0;
};
ReferenceFrame render_reference(gl::PatchRenderer& renderer, const gl::RenderParams& params);

/// The renderer's last frame as compare_frames takes a culled frame: ids, depth, drawn patches.
gl::FrameCapture capture_culled_frame(const gl::PatchRenderer& renderer);

/// Compares the renderer's current framebuffer (a culled frame) with a reference.
gl::FrameComparison compare_with_reference(const gl::PatchRenderer& renderer, const ReferenceFrame& reference);

/// The renderer's attributes of the poser's last pose: its ACC tangent patches (shading normals),
/// refinement depths, and for a displaced scene the texcoords and displacement ranges.
gl::PatchAttributes pose_attributes(const ScenePoser& poser);

/// The scene of a MODEL argument: a built-in scene ("default", "city", "building";
/// make_builtin_scene with --scheme), a scene file (a path ending in .json: load_scene_file, whose
/// objects name their own schemes; --scheme is ignored), or a model (OBJ path or "teapot") as
/// make_model_scene places it. --split applies to a model only. Prints the models' loader
/// warnings. Throws patchcull::Error naming the flag or file.
Scene load_scene(const std::string& model, const std::string& scheme_text, int split);

/// PatchRenderer::set_occluders with the scene's occluders, the one-sided environment objects
/// (EnvironmentObject::one_sided) drawn with back faces culled.
void upload_scene_occluders(gl::PatchRenderer& renderer, const Scene& scene);

/// One object of a scene for PipelineParams::objects: an instance's patches in the pose
/// (ScenePoser's order: instance by instance, each in its model's order).
struct SceneObject {
    /// The instance's name (SceneInstance::name, unique: "bigguy#0", "monsterfrog#2",
    /// "teapot#0", a scene file's names); for an unnamed instance the model's file name without
    /// extension, '#', its number among that model's instances from 0.
    std::string name;
    gl::ObjectRange range;  ///< first patch, patch count; cull = true
};
/// The scene's objects, one per instance, in instance order (their ranges tile [0, patch_count())).
std::vector<SceneObject> scene_objects(const Scene& scene);

/// The tests of `requested` that are conservative on scene: back-patch culling only when every
/// model is a closed surface (LoadedModel::closed). For a scene with an open model, `all` drops
/// the back-patch test, and an explicit `backpatch` keeps it with a one-line warning on stderr
/// (prefixed with command).
gl::CullMode applicable_cull_mode(const Scene& scene, gl::CullMode requested, const std::string& command);

}  // namespace patchcull::cli
