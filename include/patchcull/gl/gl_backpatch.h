// patchcull/gl/gl_backpatch.h: GPU back-patch culling (library patchcull_gl): the back-patch passes of
// gl_passes.h (BackpatchConePass, BackpatchPtpPass), which mirror the CPU kernels of backpatch.h,
// tcone, ncone and ptp, decision for decision, run over buffers that BackpatchCuller owns, with
// read-backs of the decisions and diagnostics (tests, tools).
//
// Shaders: shaders/backpatch_cones.comp.glsl (tcone, and ncone with PATCHCULL_NCONE; one
// invocation per patch, the cone code in shaders/backpatch_cones.h mirrors
// src/core/cones_internal.h operation by operation) and shaders/backpatch_ptp.comp.glsl
// (Loop, Niessner & Eisenacher §6: 16 invocations per patch, 8 patches per
// work group; lane tau owns the 4 destinations of its 4x4 block, summed in the CPU schedule's
// order from shaders/ptp_schedule.h, generated from src/core/ptp_schedule.h; the signs are
// counted by a parallel reduction in shared memory).
//
// Buffers (std430 SSBOs, bindings of shaders/shared.h):
// - control points, kBindingControlPoints (0): vec4 cp[16 * patch_count], patch p's point k
//   (patch.h order) at 16p + k, the renderer's layout. Either uploaded by set_patches or an
//   existing buffer of that layout (use_patch_buffer, e.g. the renderer's).
// - flags, kBindingCullFlags (1), flag_buffer(): uint flags[patch_count], cleared and written by
//   every cull call: kCullBackPatch (2, gl_renderer.h) = back-facing (culled), 0 = kept.
// - ptp diagnostics, shared.h's kBindingPtpPlanes (13): float [128 * patch_count], per
//   patch the 64 clip-space control plane z values (at 128p + 8 jv + iu) and then their 64
//   rounding-error margins thr (at 128p + 64 + 8 jv + iu), written only when cull_ptp is asked
//   for them.
// - cone diagnostics, kBindingConeValues (14): float c[12 * patch_count], per patch (axis.xyz,
//   cos, sin, valid 1/0, sphere center.xyz, radius, 0, 0), written only when cull_tcone /
//   cull_ncone are asked for them.
// The bindings are the passes' (gl_passes.h's state contract).
//
// Equality with the CPU kernels (tests/gl/backpatch_gpu_test.cpp checks decisions on ~3000
// random patches per method and rule, and the 64 ptp values bit for bit):
// - Every std::fma of the CPU is pc_fma (shaders/exact_fma.h): exact in double precision on
//   software rasterizers and wherever GLSL fma() fails the start-up check (fma_via_double()),
//   native fma() on GPUs that round it once.
// - sqrt and division (cones only) are pc_sqrt / pc_div (shaders/backpatch_exact.h): the driver's
//   value corrected to the correctly rounded one by exact double-precision midpoint tests, so a
//   GPU's 2.5-ULP division or rsqrt-based sqrt gives the CPU's values too; the driver's own on a
//   software rasterizer whose / and sqrt pass the start-up check (PassContext::native_div_sqrt).
// - Other float operations (+, -, *) are correctly rounded in GLSL and written `precise`, in the
//   CPU's order; comparisons are written so that NaN fails them as on the CPU. Sums start from a
//   uniform u_zero = 0 rather than a literal: Mesa folds `x + 0.0` to x even in precise code,
//   which changed the sign of zero ptp values (-0 where the CPU's fma(w, -0, +0) gives +0).
// Measured on llvmpipe (tests/gl/backpatch_gpu_test.cpp): tcone, ncone, ptp-ncnt and ptp-pcnt
// decisions all equal the CPU's (0 differences in either direction), the cones, spheres and the
// 64 ptp values are bit-identical.
// Where a GPU (or llvmpipe) can still differ (none of this was observed on llvmpipe; no real GPU
// was available to test on):
// (1) Subnormal floats: llvmpipe (and GPUs by default) flush them to zero, the CPU does not. The
//     cone code treats a vector as zero only when its bits are zero (the CPU skips a vector whose
//     |v|^2 underflows to 0), so a flush can only invalidate a cone (keep the patch), never make
//     the GPU skip a vector the CPU uses; other flushes need values below ~1e-38, far under the
//     cone thresholds (|v|^2 >= 1e-30). ptp values that underflow (control points within ~1e-19
//     of each other in clip space) could differ in the last bits.
// (2) Double precision: pc_div, pc_sqrt and (with fma_via_double) pc_fma assume IEEE-rounded
//     double +, * (GLSL only requires single-precision accuracy for doubles; llvmpipe is IEEE).
// (3) Non-finite inputs (inf / NaN control points or eye) are outside the contract.
// Why a residual difference stays safe: for tcone / ncone a difference is a rounding-level change
// of values whose margins (kCosSlack, kSinSlack, kFacingSlack, the widened radius; see
// src/core/cones.cpp) are many ulps wide, so a GPU cull is still conservative in exact arithmetic
// (it may differ from the CPU only at the boundary). ptp has no margin on the CPU either (its
// float t decide as they come), so a GPU difference there, at a t within rounding of 0, is exactly
// as (un)conservative as the CPU kernel's own rounding.
//
// Threads and lifetime as gl_renderer.h: created, used and destroyed on the context's thread
// while the context lives. Errors throw patchcull::Error with one-line messages.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"
#include "patchcull/gl/gl_passes.h"
#include "patchcull/gl/gl_renderer.h"

namespace patchcull::gl {

class BackpatchCuller {
public:
    /// Makes ctx current; on drivers other than software rasterizers, checks GLSL fma() once with
    /// the probe (PATCHCULL_FMA_VIA_DOUBLE when it rounds twice; always on software rasterizers).
    /// Each cull program is compiled on its first use (llvmpipe takes seconds for ncone). Throws
    /// patchcull::Error when ctx lacks GL 4.5 core or the driver rejects a shader (at the call
    /// that compiles it).
    explicit BackpatchCuller(const GlContext& ctx);
    BackpatchCuller(BackpatchCuller&&) noexcept;
    BackpatchCuller& operator=(BackpatchCuller&&) noexcept;
    BackpatchCuller(const BackpatchCuller&) = delete;
    BackpatchCuller& operator=(const BackpatchCuller&) = delete;
    ~BackpatchCuller();

    /// Uploads the patches into the culler's own control-point buffer (16 vec4 per patch) and
    /// sizes the flag buffer (flags 0). Patch index p is patches[p].
    void set_patches(const std::vector<BezierPatch>& patches);
    void set_patches(const PatchBatchView& patches);
    /// Reads control points from an existing GL buffer `buffer` (the layout above, at least
    /// 16 * 16 * count bytes, owned and kept alive by the caller) instead of the culler's own.
    void use_patch_buffer(std::uint32_t buffer, std::size_t count);
    std::size_t patch_count() const;
    /// The control-point buffer the cull passes read (the culler's own, or use_patch_buffer's).
    std::uint32_t patch_buffer() const;

    /// cull_tcone_scalar / cull_ncone_scalar on the GPU: eye in object space. culled (optional):
    /// the decisions read back, 1 = culled. cones (optional, tests): kConeValues = 12 floats per
    /// patch, the cone and sphere the decision used (see kBindingConeValues above).
    void cull_tcone(Vec3 eye, std::vector<std::uint8_t>* culled = nullptr, std::vector<float>* cones = nullptr);
    void cull_ncone(Vec3 eye, std::vector<std::uint8_t>* culled = nullptr, std::vector<float>* cones = nullptr);
    /// cull_ptp_scalar on the GPU (object_to_clip = projection * view (* model), alpha =
    /// clip_space_eye_alpha(projection)). planes (optional): the 64 control plane z values per
    /// patch as ptp_control_planes_z computes them (times the orientation sign s of backpatch_ptp.cpp),
    /// t[64p + d]; margins (optional): their rounding-error margins thr[64p + d] as the CPU's
    /// ptp_rounding_margins computes them (a patch with a non-finite coordinate: unspecified);
    /// neither is written when nothing may be culled (alpha or det zero or not finite: all flags
    /// 0, as the CPU).
    void cull_ptp(const Mat4& object_to_clip, float alpha, PtpRule rule, std::vector<std::uint8_t>* culled = nullptr,
                  std::vector<float>* planes = nullptr, std::vector<float>* margins = nullptr);
    /// One of the above: tcone/ncone use eye, ptp uses object_to_clip, alpha and rule.
    void cull(BackpatchMethod method, const Mat4& object_to_clip, Vec3 eye, float alpha, PtpRule rule,
              std::vector<std::uint8_t>* culled = nullptr);
    /// Any registered method with a GPU pass (gl_backpatch_passes.h) on view, e.g. a method an
    /// engine registered; throws Error when the method has no pass.
    void cull(BackpatchMethod method, const CullView& view, const BackpatchOptions& options,
              std::vector<std::uint8_t>* culled = nullptr);

    /// The flag SSBO (GL name): uint per patch, kCullBackPatch = culled, written by each cull call.
    std::uint32_t flag_buffer() const;
    /// Reads the flag buffer back as it is (kCullBackPatch or 0 per patch).
    std::vector<std::uint32_t> read_flag_words() const;

    /// True when pc_fma is computed in double precision (software rasterizer, or GLSL fma() of
    /// this GPU rounds twice).
    bool fma_via_double() const;

    /// Evaluates the probe's operation on the GPU for each input (a, b, c) (tests: compare with
    /// std::fma, a / b, std::sqrt).
    std::vector<float> probe(BackpatchProbe op, const std::vector<Vec3>& abc);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace patchcull::gl
