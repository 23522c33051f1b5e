// patchcull/vk/vk_passes.h: the GPU cull passes on Vulkan (library patchcull_vk, CMake option
// PATCHCULL_WITH_VULKAN), recorded into the CALLER's VkCommandBuffer, on the caller's VkDevice and
// VkBuffers. Each makes the same decisions as its CPU scalar kernel and its OpenGL twin
// (gl/gl_passes.h) on the same inputs, flag word for flag word: they compile the same GLSL
// source (shaders/*.comp.glsl, to SPIR-V at build time; the API differences are shaders/api.h).
//
//   test                   CPU kernel (scalar)            pass               shader
//   frustum                cull_frustum_scalar            FrustumPass        frustum.comp.glsl
//   frustum-disp (AABB)    cull_frustum_disp_scalar       FrustumDispPass    frustum_disp.comp.glsl
//   back-patch tcone/ncone cull_tcone/ncone_scalar        BackpatchConePass  backpatch_cones.comp.glsl
//   back-patch ptp         cull_ptp_scalar                BackpatchPtpPass   backpatch_ptp.comp.glsl
//   (ends of the chain)    -                              CullStatusPass     cull_status.comp.glsl
//   (after the chain)      -                              CompactPass        compact.comp.glsl
//   Hi-Z pyramid           HiZPyramid::build              HiZBuildPass       hiz_build.comp.glsl
//   Hi-Z occlusion         cull_occlusion_scalar          OcclusionPass      occlusion.comp.glsl
//   frustum + cone + Hi-Z  (the three above, in one)      FusedCullPass      fused_cull.comp.glsl
//   displaced bounds       cull_displaced_frustum/_occlusion DisplacedPass   displaced.comp.glsl
// The passes over a GpuPatchSource have no Vulkan twin yet (docs/ENGINE.md, "Vulkan").
//
// Buffers: the layouts of gl_passes.h (control points 16 vec4 per patch in patch.h order, 256
// bytes; the flag word, core/cull_flags.h, one uint per patch; margins one float per patch;
// counters kCounterCount uints, shaders/shared.h), each given as a BufferRange whose bytes the
// shader indexes from the range's start: patch p's data at offset + p * (its size). Every range
// holds patches [0, first + count), lies within maxStorageBufferRange, starts at a multiple of
// minStorageBufferOffsetAlignment and is in a buffer made with VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
// the passes check the sizes, alignments and limits they can see (Error) and trust the rest.
//
// What a pass records (its run, begin or end), in this order:
//   vkCmdBindPipeline(VK_PIPELINE_BIND_POINT_COMPUTE, its pipeline)
//   vkCmdPushDescriptorSetKHR(set 0): the caller's ranges as storage-buffer descriptors at the
//     binding numbers of shaders/shared.h (kBindingControlPoints 0, kBindingCullFlags 1,
//     kBindingMaxDisplacement 2, kBindingPlaneValues 4, kBindingCullCounters 6,
//     kBindingPtpPlanes 13, kBindingConeValues 14; BackpatchPtpPass also its context's ptp tables
//     at kBindingPtpTables 31, shaders/ptp_tables.h; CompactPass: kBindingDrawList 26,
//     kBindingDrawCommands 27, kBindingDrawCount 28, kBindingCompactSums 29; DisplacedPass:
//     kBindingDisplacementRanges 8, kBindingDisplacedBounds 9); an optional range left empty is
//     replaced by a small buffer of the PassContext (never read); the Hi-Z passes' images and
//     the uniform buffer as their classes say
//   per dispatch: vkCmdPushConstants (its pass_params.h block, std140, at offset 0) and
//     vkCmdDispatch; ranges of more than 65535 work groups are split into several (CompactPass:
//     its steps, with a compute-to-compute VkMemoryBarrier between them; HiZBuildPass: one per
//     level, an image barrier between them). The blocks over 128 bytes (OcclusionPass,
//     FusedCullPass, DisplacedPass) go instead to the PassContext's uniform buffer by
//     vkCmdUpdateBuffer, between an execution barrier (compute -> transfer) and a transfer-write
//     -> uniform-read barrier
//   vkCmdPipelineBarrier: one VkMemoryBarrier from VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT /
//     VK_ACCESS_SHADER_WRITE_BIT to PassContextOptions::after_stages / after_access (default:
//     every stage and access), so the next pass of the chain, a draw's tessellation control
//     shader, an indirect draw or a copy back sees the writes.
// It leaves the command buffer's compute pipeline, compute push descriptors (set 0) and push
// constants as it set them (rebind yours after), changes no graphics state, records no render
// pass, and must be recorded outside a render pass instance. Record the passes of one PassContext
// on one queue (the uniform buffer is shared by its passes, ordered by those barriers). It
// creates no Vulkan object after the pipeline of its shader exists (first use per PassContext)
// and allocates nothing on the host per call.
// Before a pass, the caller orders its own earlier work on the ranges: writes (uploads, copies,
// its shaders) made available and visible to VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT with
// VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT, and earlier reads of the buffers the
// pass writes (flags, counters, diagnostics; e.g. the previous frame's draw) finished before
// COMPUTE_SHADER (an execution dependency). A pass after another patchcull pass needs nothing:
// the barrier the first left covers it.
//
// The device: the caller's, created with VK_KHR_push_descriptor enabled, and with the
// shaderFloat64 feature enabled when PassContext chooses the exact fma (below). Pipelines are
// cached per PassContext, one per shader and variant, created on first use (with the caller's
// VkPipelineCache when given); make one PassContext per VkDevice.
//
// The flag chain, the reasons and the statuses are gl_passes.h's: CullStatusPass::begin clears
// the reasons, each test pass skips the patches already culled and writes its reason into the
// ones it culls, CullStatusPass::end turns reasons into statuses (+ counts).
//
// Clip conventions: Vulkan draws in ClipDepth::zero_to_one or, reversed, ClipDepth::reversed /
// reversed_infinite (clip_space.h); the passes take the convention wherever a decision depends on
// depth (FrustumPlanes is made with one). Vulkan's y-down clip space (a projection whose y row is
// negated) needs nothing in the frustum and back-patch tests: the frustum planes w + y >= 0 and
// w - y >= 0 are the same pair and ptp takes the flip from the determinant, so every decision is
// the same for the flipped and the unflipped projection of one camera. The Hi-Z tests read the
// pyramid's row r as the depth image's row r (HiZBuildPass).
//
// Threads and lifetime: a PassContext and its passes are used from one thread at a time; command
// buffers recorded with them must have finished executing before the PassContext is destroyed.
// Errors: patchcull::Error with one line starting with "Vulkan: " (a missing extension or
// feature, a range too small or misaligned, a Vulkan call that failed, with its VkResult).
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/clip_space.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/displacement.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/math.h"

namespace patchcull::vk {

/// A byte range of one of the caller's buffers: [offset, offset + size). size 0 with buffer
/// VK_NULL_HANDLE: none (optional ranges); VK_WHOLE_SIZE is not accepted (the pass checks sizes).
struct BufferRange {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceSize offset = 0;
    VkDeviceSize size = 0;
};

/// A range of patches in the caller's buffers (see the header for the layouts).
struct PatchBuffers {
    BufferRange control_points;  ///< required by the test passes (not by CullStatusPass): 256 bytes per patch
    BufferRange flags;           ///< required: 4 bytes per patch
    BufferRange margins;         ///< optional (none: no patch displaced): 4 bytes per patch
    std::size_t first = 0;       ///< the patches [first, first + count) of those ranges
    std::size_t count = 0;
};

/// How PassContext compiles and synchronizes.
struct PassContextOptions {
    /// The multiply-adds of the decisions (shaders/exact_fma.h). exact_double: pc_fma computed
    /// exactly in double precision, bit-identical to std::fma (needs shaderFloat64 enabled on the
    /// device); hardware: GLSL fma(), which Vulkan does not require to round once (use it on a
    /// device whose fma is fused, e.g. a desktop GPU's FFMA, for speed; decisions may then differ
    /// from the CPU kernels' in the last bit of a plane value); automatic: exact_double where the
    /// physical device supports shaderFloat64, else Error (choose hardware explicitly).
    enum class Fma { automatic, exact_double, hardware };
    Fma fma = Fma::automatic;
    /// Optional: the caller's pipeline cache, used when the passes create their pipelines.
    VkPipelineCache pipeline_cache = VK_NULL_HANDLE;
    /// Optional: the device's vkGetDeviceProcAddr (e.g. from the caller's own loader); default the
    /// Vulkan loader's. Every device command of the passes is fetched through it once.
    PFN_vkGetDeviceProcAddr get_device_proc_addr = nullptr;
    /// The second scope of the barrier each pass records after its dispatches.
    VkPipelineStageFlags after_stages = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    VkAccessFlags after_access = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
};

/// What the passes share on one VkDevice: the device commands, the pipeline cache (one compute
/// pipeline per shader and variant, with its push-descriptor set layout and pipeline layout,
/// created on first use), the fma choice, a 256-byte device buffer bound in place of an
/// optional range the caller leaves empty, and (on BackpatchPtpPass's first run) a host-visible
/// buffer of the ptp schedule's tables.
class PassContext {
public:
    /// physical_device and device: the caller's (device made from physical_device with
    /// VK_KHR_push_descriptor enabled). Throws Error when the physical device lacks the
    /// extension, when options.fma is automatic and shaderFloat64 is not supported, or when a
    /// Vulkan call fails. Creates the 256-byte buffer and its memory (device-local when offered).
    PassContext(VkPhysicalDevice physical_device, VkDevice device, const PassContextOptions& options = {});
    PassContext(PassContext&&) noexcept;
    PassContext& operator=(PassContext&&) noexcept;
    /// Destroys its pipelines, layouts, modules and buffer (the caller's work using them must be done).
    ~PassContext();
    /// True when the passes use the exact double-precision fma.
    bool fma_via_double() const;

    struct Impl;
    Impl& impl();

private:
    std::unique_ptr<Impl> impl_;
};

/// The two ends of the flag chain (see the header).
class CullStatusPass {
public:
    explicit CullStatusPass(PassContext& context);
    /// Records the clearing of the reason bits of the range (statuses kept). The control points
    /// are not read (patches.control_points may be empty).
    void begin(VkCommandBuffer cmd, const PatchBuffers& patches);
    /// Records reasons -> statuses: a patch with no reason gets kStatusVisible (plus
    /// kStatusNewlyVisible when it lacked kStatusVisible), a culled one its reason alone; adds
    /// the counts (shared.h's kCounter*; kCounterDisplacedOcclusion needs the margins) to
    /// counters (kCounterCount uints from its offset; empty: not counted).
    void end(VkCommandBuffer cmd, const PatchBuffers& patches, const BufferRange& counters = {});

private:
    PassContext::Impl* context_;
};

/// cull_frustum_scalar on the GPU: reason kCullFrustum for a patch whose control points (moved
/// out by its margin) lie outside one plane of planes (make_frustum_planes of object_to_clip).
class FrustumPass {
public:
    explicit FrustumPass(PassContext& context);
    /// Records the test of the range. plane_values (optional, diagnostics): >= 6 floats per patch
    /// of the ranges; a tested patch p gets the six maxima the decision compares with 0 at 6p
    /// (bit-identical to the CPU kernel's with the exact fma).
    void run(VkCommandBuffer cmd, const PatchBuffers& patches, const FrustumPlanes& planes,
             const BufferRange& plane_values = {});
    /// The same on one view's CullView (view.planes).
    void run(VkCommandBuffer cmd, const PatchBuffers& patches, const CullView& view,
             const BufferRange& plane_values = {});

private:
    PassContext::Impl* context_;
};

/// cull_frustum_disp_scalar on the GPU (Sathe, "View Frustum Culling of Catmull-Clark Patches in
/// DirectX 11", Game Programming Gems 8): reason kCullFrustum for a patch whose Cartesian
/// control-point AABB, grown by its margin on every side, has all 8 corners outside one clip
/// plane of object_to_clip; gl_passes.h's FrustumDispPass, the same shader. A drop-in for
/// FrustumPass in the chain that tests displaced patches too.
class FrustumDispPass {
public:
    explicit FrustumDispPass(PassContext& context);
    /// depth: the convention of object_to_clip (converted with to_zero_to_one, as the CPU kernel
    /// does; a matrix contradicting it: Error). plane_values (optional, diagnostics): >= 6 floats
    /// per patch; a tested patch p gets the six maxima over the corners at 6p.
    void run(VkCommandBuffer cmd, const PatchBuffers& patches, const Mat4& object_to_clip, ClipDepth depth,
             const BufferRange& plane_values = {});
    /// The same on one view's CullView (view.object_to_clip in view.depth).
    void run(VkCommandBuffer cmd, const PatchBuffers& patches, const CullView& view,
             const BufferRange& plane_values = {});

private:
    PassContext::Impl* context_;
};

/// cull_tcone_scalar / cull_ncone_scalar on the GPU (eye in object space): reason kCullBackPatch.
/// Displaced patches (margin > 0) are skipped, as in the GL chain.
class BackpatchConePass {
public:
    explicit BackpatchConePass(PassContext& context);
    /// method: tcone or ncone (any other: Error). cone_values (optional, diagnostics): >= 12
    /// floats per patch; a tested patch p gets (axis.xyz, cos, sin, valid 1/0, sphere centre.xyz,
    /// radius, 0, 0) at 12p.
    void run(VkCommandBuffer cmd, const PatchBuffers& patches, BackpatchMethod method, Vec3 eye,
             const BufferRange& cone_values = {});

private:
    PassContext::Impl* context_;
};

/// cull_ptp_scalar on the GPU (Loop, Niessner & Eisenacher, "Effective Back-Patch Culling for
/// Hardware Tessellation", §6: 16 invocations per patch): reason kCullBackPatch. object_to_clip =
/// projection * view (* model), alpha = clip_space_eye_alpha(projection); a y-down projection
/// (y row negated) flips det and so the orientation sign the pass folds into the rows: the same
/// decisions. Displaced patches are skipped, as in the GL chain.
class BackpatchPtpPass {
public:
    explicit BackpatchPtpPass(PassContext& context);
    /// plane_values (optional, diagnostics): >= 128 floats per patch; a tested patch p gets its 64
    /// control plane z values and their 64 rounding-error margins at 128p. Returns false and
    /// records nothing when alpha or det(object_to_clip) is zero or not finite (nothing may be
    /// culled).
    bool run(VkCommandBuffer cmd, const PatchBuffers& patches, const Mat4& object_to_clip, float alpha, PtpRule rule,
             const BufferRange& plane_values = {});

private:
    PassContext::Impl* context_;
};

/// How CompactPass builds the list; both give the same set of patches (gl_compaction.h's).
enum class CompactMethod {
    atomic_append,  ///< one atomicAdd per work group: the list's order may change from run to run
    prefix_scan,    ///< a prefix scan over work-group sums: ascending patch index, every run
};

/// The commands CompactPass writes for a range of count patches with at most patches_per_command
/// patches each (0: no limit): max(1, ceil(count / patches_per_command)); the maxDrawCount of the
/// range's vkCmdDrawIndirectCount.
std::size_t compact_command_count(std::size_t count, std::size_t patches_per_command);
/// The bytes of CompactPass's scratch range for a range of count patches: 4 for the append; for the
/// scan 4 per 2048 patches (a work group's) plus 4.
std::size_t compact_scratch_bytes(std::size_t count, CompactMethod method);

/// Where CompactPass writes (the caller's ranges, each bound from its offset).
struct DrawListRanges {
    BufferRange list;            ///< required: uint entries, at least list_first + count of them
    std::size_t list_first = 0;  ///< the range's first entry of the list
    /// required: compact_command_count(count, patches_per_command) VkDrawIndirectCommands (16
    /// bytes each; the buffer also needs VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT to be drawn from)
    BufferRange command;
    BufferRange draw_count;               ///< optional: one uint, the draw count (vkCmdDrawIndirectCount's countBuffer)
    BufferRange scratch;                  ///< required: compact_scratch_bytes(count, method) bytes the pass overwrites
    std::size_t patches_per_command = 0;  ///< K: at most this many patches per command (0: one command)
};

/// gl_compaction.h's CompactPass on Vulkan: the patches of a range whose flag word satisfies
/// (flag & mask) == value, as a list of patch indices and indirect draw commands over it, for a
/// draw of only the survivors (vkCmdDrawIndirectCount, or vkCmdDrawIndirect over all C commands:
/// those past the survivors draw 0 vertices). Command c is {16 m, 1, 16 (list_first + c K), 0}
/// with m = min(K, n - c K) where positive, else 0 (VkDrawIndirectCommand's vertexCount,
/// instanceCount, firstVertex, firstInstance); the draw count is ceil(n / K) (one command without a
/// limit: 1 when n > 0, else 0). The vertex shader pulls point gl_VertexIndex % 16 of patch
/// list[gl_VertexIndex / 16]. The pass creates nothing per call: the scan's sums live in the
/// caller's scratch range.
class CompactPass {
public:
    explicit CompactPass(PassContext& context);
    /// Records the steps; a range of 0 patches writes the one command {0, 1, 16 list_first, 0} and
    /// draw count 0. Error (one line) for a range too small or misaligned, or list_first + count
    /// past 2^28.
    void run(VkCommandBuffer cmd, const PatchBuffers& patches, std::uint32_t mask, std::uint32_t value,
             const DrawListRanges& out, CompactMethod method = CompactMethod::prefix_scan);

private:
    PassContext::Impl* context_;
};

/// The caller's depth attachment as HiZBuildPass reads it: a 2D view of its depth aspect alone,
/// the layout it is in while the pass runs (VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
/// VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL or VK_IMAGE_LAYOUT_GENERAL) and its format
/// (VK_FORMAT_D32_SFLOAT or VK_FORMAT_D32_SFLOAT_S8_UINT; the 24-bit formats are not taken yet).
struct DepthImage {
    VkImageView view = VK_NULL_HANDLE;
    VkImageLayout layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    VkFormat format = VK_FORMAT_D32_SFLOAT;
};

/// The Hi-Z pyramid of a width x height depth buffer in the caller's image, made from
/// hiz_image_create_info(width, height): VK_FORMAT_R32_SFLOAT, HiZPyramid::level_count(width,
/// height) mip levels, level l holding hiz.h's level l in its first W_l x H_l texels (texel (x,
/// y) at image row y). all_levels: a 2D view of every level (sampled); level_views[l]: a 2D view
/// of level l alone (storage), one per level. The image is in VK_IMAGE_LAYOUT_GENERAL while the
/// passes use it.
struct HiZImage {
    VkImage image = VK_NULL_HANDLE;
    VkImageView all_levels = VK_NULL_HANDLE;
    std::array<VkImageView, HiZPyramid::kMaxLevels> level_views{};
    int width = 0, height = 0;  ///< the depth buffer's size
    bool reversed = false;      ///< set by HiZBuildPass::run: texels are minus the depths (hiz.h's keys)
};

/// The VkImageCreateInfo of the pyramid of a width x height depth buffer (each in [1, 8192], else
/// Error): R32_SFLOAT, extent bit_ceil(ceil(width / 2)) x bit_ceil(ceil(height / 2)),
/// HiZPyramid::level_count(width, height) levels, usage storage | sampled | transfer source,
/// optimal tiling. The caller creates the image, its memory and views.
VkImageCreateInfo hiz_image_create_info(int width, int height);

/// Niessner & Loop §4.1's pyramid: level 0 = max over 2x2 texels of the depth image, level l = max
/// over 2x2 texels of level l-1; bit-identical to HiZPyramid::build on the same depths, image row
/// r read as the depth array's row r. With Vulkan's y-down projection (its y row negated) image
/// row 0 is NDC y = -1 of that projection, as the depth array's row 0 is GL's, so a pyramid built
/// here and the flipped projection go together.
class HiZBuildPass {
public:
    explicit HiZBuildPass(PassContext& context);
    /// Records the build of hiz from depth, written in convention (its keys: -depth for the
    /// reversed ones), and sets hiz.reversed. Binds (push descriptors, set 0) the level written
    /// as a storage image at binding 0, the depth view and hiz.all_levels as combined image
    /// samplers (the context's nearest sampler) at bindings 1 and 2 (shared.h's units);
    /// one dispatch per level, an image barrier (compute write -> compute read, GENERAL) after
    /// each but the last, then the barrier of the header. The caller orders the depth writes
    /// (fragment tests) before the compute shader and leaves depth in depth.layout. Error for
    /// another depth format or a missing view.
    void run(VkCommandBuffer cmd, const DepthImage& depth, HiZImage& hiz, ClipDepth convention);

private:
    PassContext::Impl* context_;
};

/// cull_occlusion_scalar on the GPU against a pyramid of HiZBuildPass: with_frustum, the frustum
/// test first (reason kCullFrustum, with the margins); then, for patches with margin 0, hiz.h's
/// test (reason kCullOcclusion). Without margins the decisions equal the CPU kernel's on the same
/// matrix and pyramid (kHiZFrustumCulled <-> kCullFrustum, kHiZOccluded <-> kCullOcclusion).
/// The screen is the pyramid's depth buffer (viewport 0, 0, W, H), its row r the depth image's
/// row r: with a y-down projection, image row 0 is NDC y = -1, as HiZBuildPass says.
class OcclusionPass {
public:
    explicit OcclusionPass(PassContext& context);
    /// Records the test of the range. depth: the convention of object_to_clip; the pyramid must
    /// have been built in a convention of the same direction (else Error), and a matrix
    /// contradicting depth is an Error (check_clip_depth). Its 144-byte parameter block goes to
    /// the PassContext's uniform buffer (binding 4 of set 0) by vkCmdUpdateBuffer before each
    /// dispatch, between an execution barrier (the compute shaders recorded before finish first)
    /// and a transfer-to-uniform-read barrier: record the runs of one PassContext on one queue.
    /// The pyramid is bound as a combined image sampler (binding 3, GENERAL layout).
    void run(VkCommandBuffer cmd, const PatchBuffers& patches, const Mat4& object_to_clip, ClipDepth depth,
             const HiZImage& hiz, bool with_frustum = true);
    /// The same on one view's CullView (view.object_to_clip in view.depth).
    void run(VkCommandBuffer cmd, const PatchBuffers& patches, const CullView& view, const HiZImage& hiz,
             bool with_frustum = true);

private:
    PassContext::Impl* context_;
};

/// gl_passes.h's FusedCullPass on Vulkan: FrustumPass, BackpatchConePass and OcclusionPass
/// (with_frustum = false) in one dispatch, one invocation per patch, the tests of `tests` in the
/// chain's order, stopping at the first that culls: each patch gets the reason that chain gives
/// it (displaced patches: the frustum test with their margin only). Its 160-byte parameter block
/// goes to the PassContext's uniform buffer as OcclusionPass's does.
class FusedCullPass {
public:
    explicit FusedCullPass(PassContext& context);
    /// tests: a mask of kCullFrustum, kCullBackPatch, kCullOcclusion (0 records nothing). method:
    /// tcone or ncone, used with kCullBackPatch (ptp: Error). eye: object space. hiz: a built
    /// pyramid in GENERAL layout, bound in every run (the shader declares it) and read with
    /// kCullOcclusion, then built in depth's direction (else Error). depth: the convention of
    /// object_to_clip.
    void run(VkCommandBuffer cmd, const PatchBuffers& patches, std::uint32_t tests, const Mat4& object_to_clip,
             ClipDepth depth, BackpatchMethod method, Vec3 eye, const HiZImage& hiz);

private:
    PassContext::Impl* context_;
};

/// gl_passes.h's DisplacedPass on Vulkan: cull_displaced_frustum / cull_displaced_occlusion
/// (Niessner & Loop §4.2): the bound (caf or oobb) of each displaced patch from its range and cone,
/// tested against the frustum and, with occlusion, the pyramid: reasons kCullFrustum,
/// kCullOcclusion. Its 336-byte parameter block goes to the PassContext's uniform buffer as
/// OcclusionPass's does; one pipeline per cone kind.
class DisplacedPass {
public:
    explicit DisplacedPass(PassContext& context);
    /// ranges: the DisplacementRange (vec2) per patch (empty: every patch undisplaced). hiz: a
    /// pyramid in GENERAL layout, bound in every run (the shader declares it) and read with
    /// occlusion, then built in view.depth's direction (else Error). only_displaced: patches whose
    /// range is (0, 0) are left to the other passes; false: every patch of the range is tested, as
    /// the CPU kernels do. bounds (optional, diagnostics): >= 8 floats per patch (gl_passes.h's
    /// layout).
    void run(VkCommandBuffer cmd, const PatchBuffers& patches, const BufferRange& ranges, DisplacedBoundKind bound,
             NormalConeKind cone, const DisplacedCullView& view, const HiZImage& hiz, bool occlusion,
             bool only_displaced, const BufferRange& bounds = {});

private:
    PassContext::Impl* context_;
};

}  // namespace patchcull::vk
