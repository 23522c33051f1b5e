// patchcull/gl/gl_displaced.h: GPU culling of displaced patches (library patchcull_gl): the bounds of
// displaced_bounds.h (Niessner & Loop §4.2's camera-aligned frustum `caf`, Munkberg et al.'s `oobb`, each
// with the cone `full`, `acon` or `con`) and their frustum and Hi-Z occlusion decisions, in a
// compute shader that mirrors src/core/displaced_bounds.cpp operation by operation: gl_passes.h's
// DisplacedPass over buffers and a Hi-Z texture that DisplacedCuller owns, with read-backs (tests,
// tools). In a frame, CullPipeline runs the same pass on the renderer's buffers.
//
// Shaders: shaders/displaced.comp.glsl (one invocation per patch; one program per cone kind,
// compiled on first use: on llvmpipe without a warm shader cache, with the exact double-precision
// fma, about 3 s for `full`, 5 s for `acon` and 10 s for `con`, mostly the cone code),
// shaders/displaced_bounds.h (the bound arithmetic), the cones of shaders/backpatch_cones.h (the
// mirror of src/core/cones_internal.h that BackpatchCuller's tcone / ncone use) and the Hi-Z
// steps 5-9 of occlusion.comp.glsl (shaders/hiz_box_test.h).
//
// Buffers and textures (bindings and layouts of shaders/shared.h):
// - control points, kBindingControlPoints (0): vec4 cp[16 * patch_count], patch p's point k at
//   16p + k (the renderer's layout): uploaded by set_patches, or a caller's buffer of that layout
//   (use_patch_buffer, e.g. PatchRenderer::patch_buffer()).
// - displacement ranges, kBindingDisplacementRanges (8): vec2 (d_min, d_max) per patch, uploaded by
//   set_ranges; without ranges every patch is undisplaced (the CPU kernels' ranges = null).
// - flags, kBindingCullFlags (1), flag_buffer(): uint per patch, cleared and written by every
//   cull call: kCullFrustum (1) = outside the view volume, kCullOcclusion (4) = behind the Hi-Z
//   pyramid (cull_occlusion only), 0 = kept; status bits 8-9 are 0 (the reason bits of the flag
//   word, gl_renderer.h).
// - Hi-Z pyramid: an R32F texture on kTextureUnitHiZ (2) of create_hiz_texture's layout (mip
//   level l holds hiz.h's level l in its lower-left W_l x H_l texels); set_hiz uploads a CPU
//   HiZPyramid into the culler's own texture of that layout.
// - diagnostics, kBindingDisplacedBounds (9): float [8 * patch_count], per patch the bound
//   (ndc_xmin, ndc_xmax, ndc_ymin, ndc_ymax, depth_near, depth_far, status, 0), written only when
//   a cull call is asked for the bounds.
// The culler binds these only around its own dispatches and restores nothing.
//
// Equality with the CPU (tests/gl/displaced_gpu_test.cpp: decisions of all 6 combinations, frustum
// and occlusion, on a few thousand patches and several views, and the bound values bit for bit):
// the same arithmetic as displaced_bounds.cpp in the same order; std::fma is pc_fma (exact on
// llvmpipe, whose GLSL fma() rounds twice), division and sqrt are correctly rounded (pc_div,
// pc_sqrt of shaders/backpatch_exact.h), other operations are `precise` single float operations;
// the constants kDisplaced* are passed from the C++ values as uniforms; the per-view constants are
// make_displaced_cull_view's own (computed once on the CPU). So the bounds, not only the
// decisions, are bit-identical. Measured on llvmpipe (Mesa 22.3.6): 12,096 patch-view pairs per
// combination (2,016 patches, 6 views), 0 differences in frustum decisions, occlusion decisions or
// bound bits, for each of the 6 combinations. Where they can still differ (not observed on llvmpipe): subnormal
// intermediate values (llvmpipe flushes them to zero, the CPU does not; they need coordinates or
// quotients below ~1e-38, or cone vectors below the cones' thresholds, see gl_backpatch.h (1)), and
// drivers whose double arithmetic is not IEEE (gl_backpatch.h (2)). The decisions keep their
// margins either way: a rounding-level difference moves a bound by ulps that its slack covers.
//
// Threads and lifetime as gl_renderer.h: created, used and destroyed on the context's thread while
// the context lives. Errors throw patchcull::Error with one-line messages (a GL error, a shader the
// driver rejects, a buffer too small, a ranges vector of the wrong size).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/displacement.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/patch.h"
#include "patchcull/gl/gl_renderer.h"

namespace patchcull::gl {

class DisplacedCuller {
public:
    /// Makes ctx current; decides once how pc_fma is computed (as BackpatchCuller: in double on
    /// software rasterizers and on GPUs whose GLSL fma() fails the probe). Programs are compiled
    /// on first use. Throws patchcull::Error when ctx lacks GL 4.5 core.
    explicit DisplacedCuller(const GlContext& ctx);
    DisplacedCuller(DisplacedCuller&&) noexcept;
    DisplacedCuller& operator=(DisplacedCuller&&) noexcept;
    DisplacedCuller(const DisplacedCuller&) = delete;
    DisplacedCuller& operator=(const DisplacedCuller&) = delete;
    ~DisplacedCuller();

    /// Uploads the patches (16 vec4 per patch) into the culler's own buffer, sizes the flag buffer
    /// (flags 0) and drops the ranges (undisplaced) unless ranges is given: then ranges.size() must
    /// equal the patch count (else throws) and ranges[p] is patch p's (DisplacementRange).
    void set_patches(const std::vector<BezierPatch>& patches, const std::vector<DisplacementRange>& ranges = {});
    /// Same from a structure-of-arrays batch; ranges: null or patches.count entries (as the CPU kernels).
    void set_patches(const PatchBatchView& patches, const DisplacementRange* ranges = nullptr);
    /// Reads control points from an existing GL buffer (the layout above, at least 256 * count
    /// bytes, owned and kept alive by the caller); drops the ranges. Throws when it is no buffer or
    /// too small.
    void use_patch_buffer(std::uint32_t buffer, std::size_t count);
    /// Replaces the ranges: patch_count() entries (else throws), or empty = no displacement.
    void set_ranges(const std::vector<DisplacementRange>& ranges);
    std::size_t patch_count() const;

    /// Uploads a built pyramid for cull_occlusion (its depth buffer is the screen: viewport
    /// (0, 0, W, H)). Replaces the previous one.
    void set_hiz(const HiZPyramid& hiz);

    /// cull_displaced_frustum on the GPU: flag words kCullFrustum / 0. culled (optional): the
    /// decisions read back (1 = culled, as the CPU's bytes). bounds (optional): each patch's bound
    /// (compute_displaced_bounds), read back. A view with valid == false culls nothing (as the CPU).
    void cull_frustum(DisplacedBoundKind bound, NormalConeKind cone, const DisplacedCullView& view,
                      std::vector<std::uint8_t>* culled = nullptr, std::vector<DisplacedBound>* bounds = nullptr);
    /// cull_displaced_occlusion on the GPU against the pyramid of set_hiz (throws without one):
    /// flag words kCullFrustum / kCullOcclusion / 0. decisions (optional): HiZDecision bytes
    /// (kHiZVisible, kHiZFrustumCulled, kHiZOccluded) as the CPU writes them. bounds as above.
    void cull_occlusion(DisplacedBoundKind bound, NormalConeKind cone, const DisplacedCullView& view,
                        std::vector<std::uint8_t>* decisions = nullptr, std::vector<DisplacedBound>* bounds = nullptr);

    /// The flag SSBO (GL name), written by each cull call.
    std::uint32_t flag_buffer() const;
    /// Reads the flag words back (patch_count() values). Waits for the GPU.
    std::vector<std::uint32_t> read_flag_words() const;

    /// True when pc_fma is computed in double precision (see the constructor).
    bool fma_via_double() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace patchcull::gl
