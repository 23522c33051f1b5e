// patchcull/vk/vk_renderer.h: the headless Vulkan tessellation renderer (library patchcull_vk)
// with Niessner & Loop's two-pass frame ("Patch-Based Occlusion Culling for Hardware
// Tessellation", §3) built from the Vulkan passes of vk_passes.h, on a HeadlessDevice
// (vk_device.h). It is the Vulkan twin of gl_pipeline.h's CullPipeline for one object (the whole
// patch set), for `patchcull render --api vulkan --verify` and the tests: the same draw shaders
// (shaders/patch.*.glsl, compiled to SPIR-V), the same flag chain, the same verification.
//
// A frame with occlusion: clear, occluders, the patches tagged visible (draw pass 1); HiZBuildPass
// from that depth image; CullStatusPass::begin, FrustumPass (or FrustumDispPass, or FusedCullPass
// for frustum, cone and Hi-Z), the back-patch pass, OcclusionPass, DisplacedPass,
// CullStatusPass::end; the newly visible patches (draw pass 2, skipped when aggressive). Without
// occlusion: the chain, then one draw of what passed. The first frame after set_patches tags the
// even-indexed patches visible. Draws issue every patch and the TCS drops the culled ones (flags),
// or CompactPass lists each pass's survivors and vkCmdDrawIndirectCount draws only those
// (indirect). Everything a frame does is one command buffer, submitted and waited for.
//
// Vulkan's conventions: depth 0..1 (RenderParams::depth zero_to_one, reversed or
// reversed_infinite; minus_one_to_one is an Error) and the y-down framebuffer. The renderer takes
// RenderParams::projection as OpenGL writes it and draws with its y row negated: the image then
// has OpenGL's orientation with row 0 at the top, and the passes get the y-negated matrix, whose
// planes are the same set (vk_passes.h's "Clip conventions"); the Hi-Z pyramid built from the
// depth image pairs with it (HiZBuildPass). Attachments: RGBA8 colour, R32_UINT patch id (0
// background, patch p writes p + 1, occluder triangle t kIdOccluderBit | t), D32_SFLOAT depth.
// The renderer splits its draws as gl_renderer.h's llvmpipe workaround 2 says (lavapipe shares
// llvmpipe's tessellator). Its buffers are host-visible: a test and tool renderer, not an engine's.
//
// Threads and errors as vk_device.h; Error names the call that failed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/cull_flags.h"
#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/displacement.h"
#include "patchcull/core/patch.h"
#include "patchcull/core/render_params.h"
#include "patchcull/vk/vk_device.h"
#include "patchcull/vk/vk_passes.h"

namespace patchcull::vk {

/// Parameters of one frame (gl_pipeline.h's PipelineParams for one object).
struct CullFrameParams {
    RenderParams render;  ///< camera (OpenGL's projection in render.depth), size, tessellation
    /// The tests: kCullFrustum, kCullBackPatch, kCullOcclusion (core/cull_flags.h); with
    /// occlusion the frame has two draw passes.
    std::uint32_t tests = kCullFrustum | kCullBackPatch | kCullOcclusion;
    bool aggressive = false;                             ///< skip draw pass 2 (Niessner & Loop §3.1; not conservative)
    BackpatchMethod backpatch = BackpatchMethod::tcone;  ///< tcone, ncone or ptp (else Error)
    PtpRule ptp_rule = PtpRule::ncnt;
    DisplacedBoundKind bound = DisplacedBoundKind::caf;
    NormalConeKind cone = NormalConeKind::acon;
    bool frustum_aabb = false;  ///< FrustumDispPass (Sathe's box) instead of FrustumPass
    /// FusedCullPass for frustum, back-patch (tcone, ncone) and Hi-Z, where the choices allow it
    /// (not with frustum_aabb or ptp), as gl_pipeline.h's PipelineParams::fused_pass.
    bool fused_pass = false;
    bool indirect = true;  ///< draw only the compacted survivors (false: every patch, flags)
    CompactMethod compact = CompactMethod::prefix_scan;
};

/// What one frame did (gl_pipeline.h's FrameStats' counts and times, read back after it).
struct CullFrameStats {
    std::size_t patches = 0;
    bool two_pass = false;
    bool fused_pass = false;  ///< FusedCullPass ran the tests
    std::size_t pass1_drawn = 0, pass2_drawn = 0;
    std::size_t frustum_culled = 0, backpatch_culled = 0, occlusion_culled = 0, displaced_occlusion_culled = 0;
    std::size_t visible = 0, newly_visible = 0;
    std::size_t pass1_submitted = 0, pass2_submitted = 0;  ///< patches each draw pass issued
    /// Milliseconds between timestamps (0 when the queue has none): pass1 (clear, occluders,
    /// patches tagged visible, with its compaction), hiz, cull (the chain), pass2; one pass: cull,
    /// then pass1.
    double pass1_ms = 0, hiz_ms = 0, cull_ms = 0, pass2_ms = 0, total_ms = 0;
};

/// One frame as a verification compares it (gl_verification.h's FrameCapture): ids and depth in
/// image order (row 0 = top) and one byte per patch (drawn set, or the reference's front set).
struct FrameImages {
    std::vector<std::uint32_t> ids;
    std::vector<float> depth;
    std::vector<std::uint8_t> patches;
};

/// A range of occluder triangles (set_occluders' one-sided spans).
struct TriangleRange {
    std::size_t first = 0, count = 0;
};

class CullRenderer {
public:
    /// Creates the passes (a PassContext with the exact fma) and the draw pipelines' layouts on
    /// device; pipelines are made on first use.
    explicit CullRenderer(HeadlessDevice& device);
    ~CullRenderer();
    CullRenderer(const CullRenderer&) = delete;
    CullRenderer& operator=(const CullRenderer&) = delete;

    /// Uploads the patches and attributes (gl_renderer.h's PatchRenderer::set_patches: each
    /// attribute empty or one per patch, else Error); the next frame is a first frame.
    void set_patches(const std::vector<BezierPatch>& patches, const PatchAttributes& attributes = {});
    /// A new pose of the same patches: the statuses carry over (Error for another count).
    void update_patches(const std::vector<BezierPatch>& patches, const PatchAttributes& attributes = {});
    std::size_t patch_count() const;
    /// The height map the TES samples (bilinear, repeat); empty: no displacement.
    void set_displacement_map(const DisplacementMap& map);
    /// Occluder triangles (PatchRenderer::set_occluders): drawn first in every frame, id
    /// kIdOccluderBit | t; one_sided ranges with back faces culled (counter-clockwise front as
    /// seen on screen), the others two-sided. Error for a bad index or range.
    void set_occluders(const std::vector<Vec3>& vertices, const std::vector<std::uint32_t>& indices,
                       const std::vector<TriangleRange>& one_sided = {});

    /// One frame (see the header).
    CullFrameStats render_frame(const CullFrameParams& params);
    /// The last frame's ids, depth and drawn set.
    FrameImages capture();
    /// The unculled reference of params (every patch, flags ignored and kept) and its front set:
    /// the patches with a fragment exactly at the front depth of some pixel (a second draw with
    /// depth test EQUAL), and every patch its id image shows. Replaces the images of the last
    /// frame.
    FrameImages render_reference(const RenderParams& params);
    /// The colour image of the last draw, RGBA8, row 0 = top.
    std::vector<std::uint8_t> read_color();

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace patchcull::vk
