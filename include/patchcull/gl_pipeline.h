// patchcull/gl_pipeline.h: the whole per-frame cull pipeline of one patch set on the GPU (library
// patchcull_gl): seed 000 §3's frame (PatchRenderer::render_frame: frustum, Hi-Z occlusion with
// temporal coherence, two passes) with seed 001's back-patch test (tcone, ncone or ptp) computed by
// a GPU compute pass (BackpatchCuller, gl_backpatch.h) and handed to the frame through the
// renderer's back-patch hook (FrameParams::backpatch_buffer). No decision is read back to the CPU.
//
// The culler reads the renderer's own control-point buffer (PatchRenderer::patch_buffer), so
// set_patches / update_patches upload each pose once.
//
// Order within a frame: the back-patch pass writes its flag buffer first; render_frame then draws
// pass 1, builds the Hi-Z and runs the combined cull pass, which reads those flags after a
// shader-storage barrier (a patch outside the frustum keeps the frustum reason, see
// gl_renderer.h). The back-patch pass's time is measured with the frame's timing method and added
// to FrameStats::cull_ms and total_ms (and reported alone as FrameStats::backpatch_ms).
//
// Threads, lifetime and errors as gl_renderer.h (patchcull::Error with one-line messages).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "patchcull/backpatch.h"
#include "patchcull/gl_backpatch.h"
#include "patchcull/gl_renderer.h"
#include "patchcull/patch.h"

namespace patchcull::gl {

/// Parameters of one pipeline frame.
struct PipelineParams {
    /// The frame (camera, size, tessellation, mode, aggressive, timing). Its back-patch hook fields
    /// (backpatch_culled, backpatch_buffer) are ignored: when the mode includes backpatch the GPU
    /// pass below supplies the decisions.
    FrameParams frame;
    BackpatchMethod backpatch = BackpatchMethod::tcone;  ///< the back-patch test (seed 001)
    PtpRule ptp_rule = PtpRule::ncnt;                    ///< rule of ptp (ignored by the cones)
};

/// A PatchRenderer and a BackpatchCuller sharing one uploaded patch set.
class CullPipeline {
public:
    /// Creates both on ctx (see their constructors; the back-patch programs compile on first use,
    /// which takes seconds for ncone and ptp on llvmpipe).
    explicit CullPipeline(const GlContext& ctx);
    CullPipeline(CullPipeline&&) noexcept;
    CullPipeline& operator=(CullPipeline&&) noexcept;
    CullPipeline(const CullPipeline&) = delete;
    CullPipeline& operator=(const CullPipeline&) = delete;
    ~CullPipeline();

    /// PatchRenderer::set_patches (statuses restart: the next frame is a first frame), and points
    /// the culler at the renderer's control points.
    void set_patches(const std::vector<BezierPatch>& patches, const PatchAttributes& attributes = {});
    /// PatchRenderer::update_patches: a new pose of the same patches, statuses kept.
    void update_patches(const std::vector<BezierPatch>& patches, const PatchAttributes& attributes = {});
    std::size_t patch_count() const;

    /// One frame: when params.frame.cull includes backpatch, the GPU back-patch pass (eye and
    /// object_to_clip from the frame's view and projection; patches are in world space), then
    /// PatchRenderer::render_frame with its flag buffer as the hook. Throws patchcull::Error when
    /// the view matrix is singular or a GL call fails.
    FrameStats render_frame(const PipelineParams& params);

    /// The parts, for read-backs (read_ids, read_depth, write_color_png, write_status_png),
    /// occluders (set_occluders), the unculled reference (render with use_cull_flags = false) and
    /// reset_visibility.
    PatchRenderer& renderer();
    const PatchRenderer& renderer() const;
    BackpatchCuller& culler();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// The eye position in world space of a view matrix (the inverse's translation). Throws
/// patchcull::Error when view is singular.
Vec3 eye_of_view(const Mat4& view);

}  // namespace patchcull::gl
