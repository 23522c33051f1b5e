// Posing a scene into the renderer frame by frame, on the CPU or on the GPU (--pose of `render`;
// tools/frame_poser.cpp).
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "patchcull/gl/gl_posing.h"
#include "patchcull/gl/gl_renderer.h"
#include "patchcull/import/scene_poser.h"

namespace patchcull::cli {

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

/// Patches of the poser's scene with a nonzero displacement range.
std::size_t displaced_patch_count(const ScenePoser& poser);

}  // namespace patchcull::cli
