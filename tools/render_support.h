// Helpers shared by the CLI's GPU commands (render, eval, the main job): render parameters from a
// camera, the unculled reference frame and its comparison with a culled one (compare_frames), and
// name parsing for cull modes and back-patch methods.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "patchcull/core/camera.h"
#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/scene_poser.h"
#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/gl/gl_posing.h"
#include "patchcull/gl/gl_verification.h"

namespace CLI {
class App;
}

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

/// --pose cpu|gpu of `render`: how each frame's animated patches reach the renderer.
/// - cpu: ScenePoser::pose evaluates every patch on the CPU and PatchRenderer::update_patches
///   uploads them with all their attributes (256 bytes of control points per patch, plus
///   texcoords, tangents, margins, ranges, scales).
/// - gpu: ScenePoser::gpu_meshes animates only the control meshes, and gl::StencilPoser
///   (gl_posing.h) applies the stencils into the renderer's own buffers: 12 bytes per control
///   vertex and 80 per instance uploaded, bit-identical patches (the per-patch attributes that
///   do not move, texcoords, ranges, depths, stay as frame 0 uploaded them). Whatever on the CPU
///   reads posed patches (the object level, --cull auto, --draw-bounds: FramePoser's
///   cpu_patches) still gets them from ScenePoser::pose, which then costs its CPU time but no
///   upload: the CPU side stays exactly as conservative as with cpu.
enum class PoseWhere { cpu, gpu };
/// "cpu" or "gpu"; else throws patchcull::Error("FLAG: unknown value 'TEXT' (cpu or gpu)").
PoseWhere parse_pose_where(const std::string& flag, const std::string& text);
const char* pose_where_name(PoseWhere where);

/// What posing one frame cost on the CPU.
struct PoseCost {
    PoseWhere where = PoseWhere::cpu;
    bool cpu_patches = false;  ///< the CPU posed patches too (gpu with a CPU reader, or cpu)
    double cpu_ms = 0;         ///< wall-clock CPU time of the posing and upload calls (no GPU wait)
    double done_ms = 0;        ///< cpu_ms plus glFinish: until the GPU has the pose (llvmpipe: its work)
    /// Of cpu_ms, gpu: animating the control meshes (ScenePoser::gpu_meshes), the CPU work a GPU
    /// driver leaves (llvmpipe runs the compute pass inside the dispatch call, so its cpu_ms holds
    /// the pass too); cpu: 0.
    double meshes_ms = 0;
    std::size_t bytes_uploaded = 0;  ///< bytes copied to GL for the pose
};

/// Poses a scene frame by frame into a renderer, on the CPU or on the GPU (PoseWhere).
class FramePoser {
public:
    /// cpu_patches: the caller reads pose()'s patches on the CPU (then they are posed on the CPU
    /// in gpu mode too). Throws patchcull::Error (gpu) when the scene cannot be posed by stencils
    /// (ScenePoser::gpu_tables) or the GL context cannot compile the posing pass.
    FramePoser(const gl::GlContext& context, ScenePoser& poser, gl::PatchRenderer& renderer, PoseWhere where,
               bool cpu_patches);
    ~FramePoser();
    /// Poses the frame at time_seconds into the renderer: the first call uploads the set
    /// (PatchRenderer::set_patches of the CPU pose, in both modes: the attributes that never
    /// change), later ones keep the flag words (update_patches, or the GPU pass). Returns the CPU
    /// pose, or nullptr when this frame made none (gpu without cpu_patches).
    const std::vector<BezierPatch>* pose(float time_seconds);
    const PoseCost& last() const { return cost_; }

private:
    struct Gpu;
    ScenePoser* poser_;
    gl::PatchRenderer* renderer_;
    PoseWhere where_;
    bool cpu_patches_;
    bool first_ = true;
    std::unique_ptr<Gpu> gpu_;
    std::vector<gl::PosingInstance> instances_;
    PoseCost cost_;
};

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

/// --tess-mode uniform|adaptive and --tess-distance D of `render` and `view` (as parsed).
struct TessOptions {
    std::string mode = "uniform";
    float distance = 0;  ///< 0: not given (add_tess_options refuses 0 itself)
};
/// Registers --tess-mode (uniform|adaptive) and --tess-distance (a finite number > 0, at most
/// 1e9; parse errors name the flag) on command.
void add_tess_options(CLI::App& command, TessOptions& options);

/// The tessellation of a run (Niessner & Loop §6.3's adaptive case): uniform (--tess everywhere), or
/// adaptive by distance (gl::RenderParams::adaptive_tess: level --tess at reference_distance from
/// the eye and nearer, proportionally less farther away, at least 1).
struct TessMode {
    bool adaptive = false;
    float reference_distance = 1;
};
/// Resolves the options for a scene seen along path: the reference distance is --tess-distance,
/// or by default the camera path's eye-to-target distance (camera_path_eye_distance), so that the
/// surface at the centre of the orbit gets the full level. Throws patchcull::Error naming
/// --tess-distance when it is given without --tess-mode adaptive.
TessMode resolve_tess_mode(const TessOptions& options, const CameraPath& path);
/// Sets params.adaptive_tess and params.tess_reference_distance from mode.
void apply_tess_mode(const TessMode& mode, gl::RenderParams& params);
/// Distance from every eye of path to its target: sqrt(distance^2 + height^2).
float camera_path_eye_distance(const CameraPath& path);

/// --displace, --displace-scale, --bound and --cone of `render` and `view` (Niessner & Loop §4.2, §6):
/// displaced patches tested against the frustum and the running pipeline's Hi-Z with the chosen
/// bound (gl_passes.h's DisplacedPass inside CullPipeline::render_frame).
struct DisplaceOptions {
    std::string displace;      ///< "" (the scene's own), "none", "procedural" or a PNG path
    float scale = -1;          ///< world units (a character is 1 high); < 0: not given (0.02)
    std::string bound = "caf";
    std::string cone = "acon";
};
/// Registers the four options (--displace-scale needs --displace; parse errors name the flag).
void add_displace_options(CLI::App& command, DisplaceOptions& options);
/// Applies --displace to the scene: "none" removes its displacement, "procedural" or a PNG
/// displaces every instance with that map (make_procedural_displacement(512, scale) or
/// load_displacement_png), scale --displace-scale or 0.02; "" keeps the scene's own (the default
/// scene's MonsterFrogs). Throws patchcull::Error naming the flag or file.
void apply_displace_options(const DisplaceOptions& options, Scene& scene);
/// Patches of the poser's scene with a nonzero displacement range.
std::size_t displaced_patch_count(const ScenePoser& poser);
/// --bound and --cone as the pipeline's enums.
DisplacedBoundKind displace_bound(const DisplaceOptions& options);
NormalConeKind displace_cone(const DisplaceOptions& options);

/// --cull's choices: the name of every gl::kCullModes mode, then "auto".
std::vector<std::string> cull_mode_choices();
/// --backpatch's choices: the name of every gl::kBackpatchMethods method.
std::vector<std::string> backpatch_method_choices();
/// "a, b or c": names as a message lists them.
std::string names_text(const std::vector<std::string>& names);
/// backpatch_method_choices()'s names -> method; throws patchcull::Error naming flag otherwise.
gl::BackpatchMethod parse_backpatch_method(const std::string& flag, const std::string& text);
/// cull_mode_name's names -> mode; throws patchcull::Error naming flag otherwise.
gl::CullMode parse_cull_mode_option(const std::string& flag, const std::string& text);

}  // namespace patchcull::cli
