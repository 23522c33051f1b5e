// patchcull/gl/gl_passes.h: the GPU cull passes (library patchcull_gl), one per cull test, each the
// twin of a CPU kernel, that run on the CALLER's OpenGL 4.5 context and the caller's GL objects.
// An engine keeps its own context, patch buffer and draw call, and adds the passes before its draw
// and shaders/patchcull_tcs.h to its tessellation control shader (examples/ shows both).
//
//   test                   CPU kernel (scalar)            pass               shader
//   frustum                cull_frustum_scalar            FrustumPass        frustum.comp.glsl
//   frustum-disp (AABB)    cull_frustum_disp_scalar       FrustumDispPass    frustum_disp.comp.glsl
//   Hi-Z pyramid           HiZPyramid::build              HiZBuildPass       hiz_build.comp.glsl
//   Hi-Z occlusion         cull_occlusion_scalar          OcclusionPass      occlusion.comp.glsl
//   back-patch tcone/ncone cull_tcone/ncone_scalar        BackpatchConePass  backpatch_cones.comp.glsl
//   back-patch ptp         cull_ptp_scalar                BackpatchPtpPass   backpatch_ptp.comp.glsl
//   displaced bounds       cull_displaced_frustum/_occlusion DisplacedPass   displaced.comp.glsl
//   frustum + cone + Hi-Z  (the three above, in one)      FusedCullPass      fused_cull.comp.glsl
//   (ends of the chain)    -                              CullStatusPass     cull_status.comp.glsl
//   (after the chain)      -                              CompactPass        compact.comp.glsl (gl_compaction.h)
//   (or fused into the end: CullStatusPass::end with a DrawListBuffers, cull_status.comp.glsl's PC_STATUS_APPEND)
// Each makes the same decisions as its CPU kernel on the same inputs (the arithmetic notes are
// in gl_backpatch.h, gl_displaced.h and the shaders; tests/gl/*_gpu_test.cpp check it).
//
// Buffers (std430 shader storage, the caller's, bindings of shaders/shared.h):
// - control points, kBindingControlPoints: vec4 cp[16 * n], patch p's point k (patch.h order:
//   k = 4j + i, u index i) at 16p + k, homogeneous (x, y, z, w), w > 0. BezierPatch's memory
//   layout, so a std::vector<BezierPatch> uploads as is.
// - flags, kBindingCullFlags: uint flags[n], the flag word of each patch (below). The caller's TCS
//   reads it (shaders/patchcull_tcs.h).
// - margins (optional), kBindingMaxDisplacement: float margin[n] >= 0, a bound on |D| of the
//   patch's displacement (DisplacementRange::max_abs()); a patch with margin > 0 is displaced.
// - displacement ranges (DisplacedPass), shared.h's kBindingDisplacementRanges:
//   vec2 range[n] = (d_min, d_max).
// - counters (CullStatusPass::end), kBindingCullCounters: uint c[kCounterCount] (shared.h).
// - or, instead of the control points, your own vertex buffer, index buffer and B-spline boundary
//   masks (GpuPatchSource below: Bezier, B-spline and Gregory patches, e.g. an OpenSubdiv patch
//   table in place), read at kBindingSourceVertices, kBindingSourceIndices, kBindingSourceMasks
//   by FrustumPass, FrustumDispPass, OcclusionPass, the back-patch passes and FusedCullPass.
// Textures: a depth texture (HiZBuildPass input: the caller's depth attachment, no compare mode:
// GL_DEPTH_COMPONENT32F, GL_DEPTH32F_STENCIL8, GL_DEPTH_COMPONENT24 or GL_DEPTH24_STENCIL8), and
// the Hi-Z pyramid, an R32F mipmapped texture made by create_hiz_texture, holding hiz.h's depth
// keys (-depth for the reversed conventions). Texture row 0 is the bottom row, as in HiZPyramid.
//
// The flag word (core/cull_flags.h, inlined into shared.h): bits 0-7 the cull reason of this frame
// (kCullFrustum 1, kCullBackPatch 2, kCullOcclusion 4, kCullObject 8; 0 = not culled), bits 8-9
// the temporal status of Niessner & Loop's two-pass pipeline (kStatusVisible, kStatusNewlyVisible).
//
// The flag chain: a frame's passes run in sequence on one flag buffer.
//   CullStatusPass::begin   clears the reasons (keeps the statuses)
//   test passes             each skips the patches an earlier pass culled and writes its own
//                           reason into the ones it culls (cheapest first: frustum, back-patch,
//                           occlusion / displaced)
//   CullStatusPass::end     reasons -> statuses (+ counts)
// so each patch keeps the reason of the first test that culled it. Displaced patches (margin > 0)
// are tested by FrustumPass with their margin and by DisplacedPass; OcclusionPass and the
// back-patch passes skip them (the base patch bounds neither a displaced surface's depth nor its
// normals). A pass may also run alone on a cleared flag buffer (its reason or 0 per patch).
// Each pass covers a range [first, first + count) of the buffers, e.g. one object of a scene.
//
// State contract of every run(): it binds its program, its parameter block (a uniform buffer it
// owns) at kUniformPassParams, the buffers it reads at the bindings above, and for the Hi-Z passes
// textures at kTextureUnitDepth / kTextureUnitHiZ and an image at kImageUnitHiZOut; it leaves those
// bindings pointing at what it bound, no program in use (glUseProgram(0)), and issues
// glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
// GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT) after its dispatches, so a
// following pass, draw (TCS reads) or read-back sees its writes. It changes no other state (no
// framebuffer, viewport, depth or VAO state; HiZBuildPass binds its own sampler at
// kTextureUnitDepth while it reads the depth texture and leaves sampler 0 bound there), does not
// wait for the GPU and allocates no GL objects after its first run (programs are compiled on first
// use and cached in the PassContext).
// Large ranges are split into dispatches of at most 65535 work groups (dispatch_patches).
// A run over a GpuPatchSource also binds the source's buffers and a second parameter block at
// kUniformPatchSource, issues glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT) before its dispatches
// (shader writes to your vertices just before are seen), and reads
// GL_MAX_SHADER_STORAGE_BLOCK_SIZE once per PassContext.
// GL errors: a run first checks that no GL error is pending (one left by the caller is reported
// as "GL: error 0x.... pending before <pass> (left by an earlier GL call)", not blamed on the
// pass) and checks again after its work ("GL: error 0x.... after <pass>"); glGetError is the
// only query it makes besides buffer sizes (glGetNamedBufferParameteri64v) and names (glIs*).
// The PassContext constructor runs the probe once, of fma on a GPU and of division and square
// root on a software rasterizer: it binds shader storage bindings 15 and 16 (shared.h's
// kBindingProbeIn/Out) and a program, reads small buffers back (a wait), and leaves
// glUseProgram(0).
// Depth conventions: any of clip_space.h's four (zero-to-one, -1..1, reversed, reversed with an
// infinite far plane), named wherever a decision depends on depth: FrustumPlanes and
// DisplacedCullView are built with one; HiZBuildPass, OcclusionPass, FrustumDispPass and
// FusedCullPass take one. The depth texture holds window depths in [0, 1] (glDepthRange(0, 1),
// GL_LOWER_LEFT) written in that convention; the pyramid holds depth keys (hiz.h).
//
// Threads and lifetime: a PassContext and its passes belong to the GL context current when the
// PassContext was made; use and destroy them on that thread with that context current.
// Errors: patchcull::Error with one line ("GL: ...": a shader the driver rejects, a buffer too
// small, a GL error after a pass).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/clip_space.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/math.h"
#include "patchcull/core/patch_source.h"

namespace patchcull::gl {

/// Back-patch methods are registered in core/backpatch_methods.h (their GPU passes in
/// gl_backpatch_passes.h); these names are the same entities, for code written against gl::.
using patchcull::backpatch_method_name;
using patchcull::BackpatchMethod;
using patchcull::parse_backpatch_method;

/// The text of a GLSL header shipped for an engine's own shaders, embedded in the library:
/// "shared.h" (the constants shared by C++ and GLSL: bindings, flag bits, draw selections,
/// counters; C++ code includes the same file from shaders/, on patchcull_gl's public include
/// path), "patchcull_tcs.h" (the TCS include, shaders/patchcull_tcs.h) and "patchcull_draw_list.h"
/// (the vertex shader of a compacted draw, gl_compaction.h). Paste it in place of
/// the #include line (or register it with your include mechanism). Empty for any other name.
std::string_view shipped_glsl(std::string_view name);

/// The arithmetic the probe evaluates (tests, start-up check): pc_fma(a, b, c), pc_div(a, b),
/// pc_sqrt(a), and the correction steps alone from a given guess: pc_div_from(a, b, guess = c),
/// pc_sqrt_from(a, guess = b) (shaders/backpatch_exact.h).
enum class BackpatchProbe { fma, div, sqrt, div_from, sqrt_from };

/// What the passes share on one GL context: the program cache (one program per shader and set of
/// defines, compiled on first use: on llvmpipe ncone and the displaced programs take seconds) and
/// the once-per-context check of GLSL fma().
class PassContext {
public:
    /// Binds to the GL context current on the calling thread (made by patchcull's GlContext, GLFW,
    /// SDL or an engine: any OpenGL 4.5 core context; functions are loaded through libepoxy).
    /// On a GPU it checks once that GLSL fma() rounds once (the probe shader); on software
    /// rasterizers, and on a GPU whose fma() fails, the passes compute it exactly in double
    /// (shaders/exact_fma.h). On software rasterizers it checks / and sqrt the same way
    /// (native_div_sqrt()). Throws patchcull::Error when no 4.5 context is current.
    PassContext();
    PassContext(PassContext&&) noexcept;
    PassContext& operator=(PassContext&&) noexcept;
    PassContext(const PassContext&) = delete;
    PassContext& operator=(const PassContext&) = delete;
    ~PassContext();

    /// True when pc_fma is computed in double (software rasterizer, or GLSL fma() rounds twice).
    bool fma_via_double() const;
    /// True when pc_div and pc_sqrt are the driver's own / and sqrt: on a software rasterizer whose
    /// division and square root round correctly on the start-up check's cases (llvmpipe: LLVM's
    /// fdiv and sqrt); else the shaders correct the driver's values (shaders/backpatch_exact.h).
    bool native_div_sqrt() const;
    /// True for a software rasterizer (llvmpipe, softpipe, swrast).
    bool is_software() const;
    /// Evaluates the probe's operation on the GPU for each input (a, b, c) (tests: compare with
    /// std::fma, a / b, std::sqrt).
    std::vector<float> probe(BackpatchProbe op, const std::vector<Vec3>& abc);

    struct Impl;
    Impl& impl();

private:
    std::unique_ptr<Impl> impl_;
};

/// A range of patches in the caller's buffers (GL names; see the header for the layouts).
struct PatchBuffers {
    std::uint32_t control_points = 0;  ///< required: 16 vec4 per patch
    std::uint32_t flags = 0;           ///< required: uint per patch
    std::uint32_t margins = 0;         ///< optional (0 = none, no patch displaced): float per patch
    std::size_t first = 0;             ///< the range [first, first + count) of those buffers
    std::size_t count = 0;
};

/// The caller's own control points in GL buffers, culled in place: the GPU twin of
/// core/patch_source.h's PatchSourceView (its rules for points, index lists, the bases, B-spline
/// boundary masks and Gregory patches hold here), with the flag range the passes write. Patches
/// of one basis; an OpenSubdiv Far::PatchTable is one source per patch array (docs/ENGINE.md).
///
/// Buffers (the caller's; read as std430 shader storage from byte 0, so every byte offset and the
/// stride are multiples of 4, and each buffer must fit GL_MAX_SHADER_STORAGE_BLOCK_SIZE):
/// - vertices (required), bound at shared.h's kBindingSourceVertices and read as float[]: point
///   i's x, y, z (and w) at byte offset_bytes + i * stride_bytes; 3 components (w = 1) or 4
///   (homogeneous, w > 0). The buffer holds point_count points.
/// - indices (optional), kBindingSourceIndices: uint per slot, source patch s's n slots (n = 16,
///   20 for gregory) from byte indices_offset_bytes + 4 n s; 0: patch s reads points n s ..
///   n s + n - 1. An index >= point_count is never read: the passes leave that patch unculled
///   (they do not read indices back to check them; check_patch_source does on the CPU).
/// - boundary_masks (optional, bspline only), kBindingSourceMasks: one byte per patch, OpenSubdiv's
///   PatchParam::GetBoundary() (the low 4 bits are used), source patch s's at byte
///   masks_offset_bytes + s; read as uint words, so the buffer holds whole words.
/// Flag range: flags[first + i] and margins[first + i] (PatchBuffers' layouts) belong to source
/// patch source_first + i, i < count. Decisions equal the CPU entries' (cull_frustum,
/// cull_frustum_disp, cull_backpatch, cull_occlusion, cull_fused over the same PatchSourceView)
/// bit for bit: the shaders gather
/// each patch as gather_bezier does (shaders/patch_source.h) and run the passes' own tests on it
/// (subnormal coordinates excepted: GPUs and llvmpipe flush them to zero, gl_backpatch.h (1)).
/// Gregory sources: the frustum, frustum-disp and occlusion tests take all 20 points; the cone
/// tests (BackpatchConePass, FusedCullPass's cone stage) take the Gregory tangent cone of
/// core/patch_source.h's cull_backpatch, whichever cone method; BackpatchPtpPass never culls them
/// (it runs nothing and leaves the flags as they are).
/// Not an aggregate (a braced list names a PatchBuffers): set the members by name.
struct GpuPatchSource {
    GpuPatchSource() = default;
    std::uint32_t vertices = 0;    ///< required: the vertex buffer
    std::size_t stride_bytes = 0;  ///< >= offset_bytes + 4 * components; a multiple of 4
    std::size_t offset_bytes = 0;  ///< of x inside each vertex; a multiple of 4
    int components = 3;            ///< 3: (x, y, z), w = 1; 4: homogeneous (w x, w y, w z, w)
    std::size_t point_count = 0;   ///< points the vertex buffer holds (checked against its size)
    PatchBasis basis = PatchBasis::bezier;
    std::uint32_t indices = 0;             ///< optional: uint per slot (0: consecutive points)
    std::size_t indices_offset_bytes = 0;  ///< where source patch 0's slots start; a multiple of 4
    std::uint32_t boundary_masks = 0;      ///< optional, bspline only: a byte per patch (0: all interior)
    std::size_t masks_offset_bytes = 0;    ///< where source patch 0's mask byte is
    std::uint32_t flags = 0;               ///< required: uint per patch (PatchBuffers::flags)
    std::uint32_t margins = 0;             ///< optional: float per patch (PatchBuffers::margins)
    std::size_t first = 0;                 ///< the range [first, first + count) of flags and margins
    std::size_t count = 0;
    std::size_t source_first = 0;  ///< the source patch of flags[first]
    /// The flag range as PatchBuffers without control points, for CullStatusPass::begin / end.
    PatchBuffers flag_buffers() const { return {0, flags, margins, first, count}; }
};

/// A Hi-Z pyramid texture (create_hiz_texture) of a width x height depth buffer whose viewport
/// was (0, 0, width, height).
struct HiZTexture {
    std::uint32_t texture = 0;
    int width = 0, height = 0;
    bool reversed = false;  ///< set by HiZBuildPass::run: texels are minus the depths (hiz.h's keys)
};

/// Makes an R32F texture for the pyramid of a width x height depth buffer (each in [1, 8192]):
/// HiZPyramid::level_count(width, height) mip levels, level l (bit_ceil(W_0) >> l) x
/// (bit_ceil(H_0) >> l), of which the lower-left W_l x H_l texels (hiz.h's sizes) are used; all
/// texels 0. The caller owns it (glDeleteTextures).
HiZTexture create_hiz_texture(int width, int height);
/// Reads a built pyramid back in HiZPyramid::data()'s layout (level l at HiZPyramid's
/// level(l).offset, W_l x H_l row-major, row 0 = bottom). Waits for the GPU.
std::vector<float> read_hiz_texture(const HiZTexture& hiz);

/// Niessner & Loop §4.1's pyramid: level 0 = max over 2x2 pixels of the depth texture, level l = max
/// over 2x2 texels of level l-1 (bit-identical to HiZPyramid::build on the same depth buffer).
class HiZBuildPass {
public:
    explicit HiZBuildPass(PassContext& context);
    HiZBuildPass(HiZBuildPass&&) noexcept;
    HiZBuildPass& operator=(HiZBuildPass&&) noexcept;
    ~HiZBuildPass();
    /// Builds hiz from depth_texture, written in convention (clip_space.h), and records it in
    /// hiz.reversed. depth_texture: GL_DEPTH_COMPONENT32F or GL_DEPTH32F_STENCIL8 (texels
    /// bit-identical to HiZPyramid::build), GL_DEPTH_COMPONENT24 or GL_DEPTH24_STENCIL8 (each depth
    /// widened outward by 1.5 / (2^24 - 1) and one ulp, covering the driver's conversion to float
    /// and GL_LEQUAL / GL_GEQUAL ties, as HiZPyramid::build_unorm24 does from the integers); at
    /// least hiz.width x hiz.height, no compare mode; its lower-left hiz.width x hiz.height texels
    /// are the viewport the frame was drawn with. Other formats: Error naming the format.
    void run(std::uint32_t depth_texture, HiZTexture& hiz, ClipDepth convention);
    /// run(depth_texture, hiz, zero_to_one) for a pyramid that was not built reversed (Error if
    /// hiz.reversed: call the overload above).
    void run(std::uint32_t depth_texture, const HiZTexture& hiz);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// cull_frustum_scalar on the GPU: reason kCullFrustum for a patch whose control points (moved
/// out by its margin) lie outside one plane of planes (make_frustum_planes of object_to_clip).
class FrustumPass {
public:
    explicit FrustumPass(PassContext& context);
    FrustumPass(FrustumPass&&) noexcept;
    FrustumPass& operator=(FrustumPass&&) noexcept;
    ~FrustumPass();
    /// plane_values (optional, diagnostics): a buffer of >= 6 floats per patch of the buffers that
    /// receives, for each tested patch p, the six maxima the decision compares with 0 at 6p.
    void run(const PatchBuffers& patches, const FrustumPlanes& planes, std::uint32_t plane_values = 0);
    /// The same on one view's CullView (view.planes).
    void run(const PatchBuffers& patches, const CullView& view, std::uint32_t plane_values = 0);
    /// The same over a patch source: cull_frustum (core/patch_source.h) on the GPU, margins
    /// included; plane_values at 6 (first + i) for the range's patch i. A Gregory patch is
    /// culled when all 20 points lie outside one plane. Throws Error (one line) for a bad source
    /// (check_patch_source's rules, the buffers' sizes; see GpuPatchSource).
    void run(const GpuPatchSource& source, const FrustumPlanes& planes, std::uint32_t plane_values = 0);
    void run(const GpuPatchSource& source, const CullView& view, std::uint32_t plane_values = 0);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// cull_frustum_disp_scalar on the GPU (Sathe, "View Frustum Culling of Catmull-Clark Patches in
/// DirectX 11", Game Programming Gems 8): reason kCullFrustum for a patch whose Cartesian
/// control-point AABB, grown by its margin (max |D|) on every side, has all 8 corners outside one
/// clip plane of object_to_clip. Decisions equal the CPU kernel's on the same inputs, bit for bit
/// (same operation order; X / W and the multiply-adds correctly rounded also on llvmpipe), and so
/// are the maxima written to plane_values. Conservative for a patch displaced along unit normals
/// by at most its margin (the base surface lies in the hull of its control points, inside the
/// box; displacement moves it at most |D|). A drop-in for FrustumPass in the flag chain: it tests
/// displaced patches too (their margin > 0), and is looser than FrustumPass's hull test for
/// undisplaced ones (a box instead of the points; about the same work per patch).
class FrustumDispPass {
public:
    explicit FrustumDispPass(PassContext& context);
    FrustumDispPass(FrustumDispPass&&) noexcept;
    FrustumDispPass& operator=(FrustumDispPass&&) noexcept;
    ~FrustumDispPass();
    /// depth: the convention of object_to_clip (converted with to_zero_to_one, as the CPU kernel
    /// does). plane_values (optional, diagnostics): a buffer of >= 6 floats per patch of the
    /// buffers that receives, for each tested patch p, the six maxima over the corners (left,
    /// right, bottom, top, near, far) that the decision compares with 0, at 6p.
    void run(const PatchBuffers& patches, const Mat4& object_to_clip, ClipDepth depth, std::uint32_t plane_values = 0);
    /// The same on one view's CullView (view.object_to_clip in view.depth).
    void run(const PatchBuffers& patches, const CullView& view, std::uint32_t plane_values = 0);
    /// The same over a patch source: cull_frustum_disp (core/patch_source.h) on the GPU, margins
    /// included (none: the box of the points alone); plane_values at 6 (first + i) for the range's
    /// patch i. A Gregory patch's box holds its 20 points. Throws Error (one line) for a bad
    /// source (check_patch_source's rules, the buffers' sizes; see GpuPatchSource).
    void run(const GpuPatchSource& source, const Mat4& object_to_clip, ClipDepth depth, std::uint32_t plane_values = 0);
    void run(const GpuPatchSource& source, const CullView& view, std::uint32_t plane_values = 0);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// cull_occlusion_scalar on the GPU against a built pyramid: with_frustum, the frustum test first
/// (reason kCullFrustum, with the margins); then, for patches with margin 0, hiz.h's test (reason
/// kCullOcclusion). Without margins the decisions equal the CPU kernel's (kHiZFrustumCulled <->
/// kCullFrustum, kHiZOccluded <-> kCullOcclusion) on the same matrix and pyramid.
class OcclusionPass {
public:
    explicit OcclusionPass(PassContext& context);
    OcclusionPass(OcclusionPass&&) noexcept;
    OcclusionPass& operator=(OcclusionPass&&) noexcept;
    ~OcclusionPass();
    /// depth: the convention of object_to_clip (clip_space.h; planes and depth keys as the CPU
    /// kernel makes them). The pyramid must have been built by HiZBuildPass::run in a convention
    /// of the same direction (forward or reversed; else Error), from a depth buffer with the
    /// GL_LOWER_LEFT origin. A matrix contradicting depth: Error (check_clip_depth).
    void run(const PatchBuffers& patches, const Mat4& object_to_clip, ClipDepth depth, const HiZTexture& hiz,
             bool with_frustum = true);
    /// The same on one view's CullView (view.object_to_clip in view.depth).
    void run(const PatchBuffers& patches, const CullView& view, const HiZTexture& hiz, bool with_frustum = true);
    /// The same over a patch source: cull_occlusion (core/patch_source.h) on the GPU (a Gregory
    /// patch over its 20 points, visible when one point's NDC coordinate is NaN).
    void run(const GpuPatchSource& source, const Mat4& object_to_clip, ClipDepth depth, const HiZTexture& hiz,
             bool with_frustum = true);
    void run(const GpuPatchSource& source, const CullView& view, const HiZTexture& hiz, bool with_frustum = true);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// cull_tcone_scalar / cull_ncone_scalar on the GPU (eye in object space): reason kCullBackPatch.
class BackpatchConePass {
public:
    explicit BackpatchConePass(PassContext& context);
    BackpatchConePass(BackpatchConePass&&) noexcept;
    BackpatchConePass& operator=(BackpatchConePass&&) noexcept;
    ~BackpatchConePass();
    /// method: tcone or ncone (any other: throws). cone_values (optional, diagnostics): >= 12 floats per
    /// patch; a tested patch p gets (axis.xyz, cos, sin, valid 1/0, sphere centre.xyz, radius, 0,
    /// 0) at 12p.
    void run(const PatchBuffers& patches, BackpatchMethod method, Vec3 eye, std::uint32_t cone_values = 0);
    /// The same over a patch source (cull_backpatch of core/patch_source.h on the GPU); a
    /// Gregory source gets its Gregory tangent cone for either method (cone_values as above).
    void run(const GpuPatchSource& source, BackpatchMethod method, Vec3 eye, std::uint32_t cone_values = 0);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// cull_ptp_scalar on the GPU (Loop, Niessner & Eisenacher §6: 16 invocations per patch): reason kCullBackPatch.
/// object_to_clip = projection * view (* model), alpha = clip_space_eye_alpha(projection). When
/// alpha or det(object_to_clip) is zero or not finite nothing may be culled and nothing runs.
class BackpatchPtpPass {
public:
    explicit BackpatchPtpPass(PassContext& context);
    BackpatchPtpPass(BackpatchPtpPass&&) noexcept;
    BackpatchPtpPass& operator=(BackpatchPtpPass&&) noexcept;
    ~BackpatchPtpPass();
    /// plane_values (optional, diagnostics): >= 128 floats per patch; a tested patch p gets its 64
    /// control plane z values (times the orientation sign, backpatch_ptp.cpp) at 128p + 8 jv + iu and their
    /// 64 rounding-error margins at 128p + 64 + 8 jv + iu. Returns false when nothing ran.
    bool run(const PatchBuffers& patches, const Mat4& object_to_clip, float alpha, PtpRule rule,
             std::uint32_t plane_values = 0);
    /// The same over a patch source; a Gregory source is validated and nothing runs (returns
    /// false: never back-patch culled).
    bool run(const GpuPatchSource& source, const Mat4& object_to_clip, float alpha, PtpRule rule,
             std::uint32_t plane_values = 0);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// cull_displaced_frustum / cull_displaced_occlusion on the GPU (Niessner & Loop §4.2): the bound (caf or
/// oobb) of each displaced patch from its range and cone, tested against the frustum and, when
/// hiz is given, the pyramid: reasons kCullFrustum, kCullOcclusion. only_displaced: patches whose
/// range is (0, 0) are left to the other passes (in a frame); false: every patch of the range is
/// tested, as the CPU kernels do (tests). The programs are compiled per cone kind.
class DisplacedPass {
public:
    explicit DisplacedPass(PassContext& context);
    DisplacedPass(DisplacedPass&&) noexcept;
    DisplacedPass& operator=(DisplacedPass&&) noexcept;
    ~DisplacedPass();
    /// ranges: the buffer of vec2 ranges (0: every patch undisplaced). bounds (optional,
    /// diagnostics): >= 8 floats per patch; a tested patch p gets (ndc_xmin, ndc_xmax, ndc_ymin,
    /// ndc_ymax, depth_near, depth_far, status, 0) at 8p.
    void run(const PatchBuffers& patches, std::uint32_t ranges, DisplacedBoundKind bound, NormalConeKind cone,
             const DisplacedCullView& view, const HiZTexture* hiz, bool only_displaced, std::uint32_t bounds = 0);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// FrustumPass, BackpatchConePass and OcclusionPass (with_frustum = false) in one dispatch, one
/// invocation per patch (the fused pass): the control points are read once, and the tests
/// of `tests` run in the chain's order (frustum, back-patch cone, Hi-Z), stopping at the first that
/// culls. Each patch gets exactly the reason (and the flag word) that the chain begin ->
/// FrustumPass(make_frustum_planes(M, zero_to_one)) -> BackpatchConePass(method, eye) ->
/// OcclusionPass(M, hiz, with_frustum = false) gives it, M = to_zero_to_one(object_to_clip,
/// depth): the shader uses the same GLSL tests (frustum_test.h, backpatch_cones.h, hiz_box_test.h
/// and occlusion.comp.glsl's steps 2-4), and tests/gl/fused_cull_pass_test.cpp checks it. As in
/// the chain, displaced patches (margin > 0) get the frustum test with their margin only (leave
/// them to DisplacedPass), and patches whose reason is already set are skipped. Not fused: ptp
/// (16 invocations per patch, BackpatchPtpPass), FrustumDispPass's box, DisplacedPass's bounds.
class FusedCullPass {
public:
    explicit FusedCullPass(PassContext& context);
    FusedCullPass(FusedCullPass&&) noexcept;
    FusedCullPass& operator=(FusedCullPass&&) noexcept;
    ~FusedCullPass();
    /// tests: a mask of kCullFrustum, kCullBackPatch, kCullOcclusion (core/cull_flags.h); 0 runs
    /// nothing. method: tcone or ncone, used with kCullBackPatch (ptp:
    /// throws). eye: object space, for the cone test. hiz: the built pyramid, required with
    /// kCullOcclusion (see OcclusionPass for its conventions), else ignored (may be null). depth:
    /// the convention of object_to_clip. Throws patchcull::Error for other bits, ptp, or a
    /// missing pyramid.
    void run(const PatchBuffers& patches, std::uint32_t tests, const Mat4& object_to_clip, ClipDepth depth,
             BackpatchMethod method, Vec3 eye, const HiZTexture* hiz);
    /// The same on one view's CullView (view.object_to_clip in view.depth, view.eye; a view
    /// without an eye runs no back-patch test).
    void run(const PatchBuffers& patches, std::uint32_t tests, const CullView& view, BackpatchMethod method,
             const HiZTexture* hiz);
    /// The same over a patch source, the points gathered once per patch (shaders/patch_source.h):
    /// without margins each flag word's reason is cull_fused's decision (core/patch_source.h) with
    /// the plan of `tests` in the chain's order (frustum, back-patch, Hi-Z; a plan for every mask
    /// but those with Hi-Z and no frustum) on the same matrix, eye, cone and pyramid. A Gregory
    /// patch: frustum and Hi-Z over its 20 points, its Gregory tangent cone. Throws Error (one
    /// line) for a bad source (see GpuPatchSource) and for what the run above refuses, before
    /// anything runs.
    void run(const GpuPatchSource& source, std::uint32_t tests, const Mat4& object_to_clip, ClipDepth depth,
             BackpatchMethod method, Vec3 eye, const HiZTexture* hiz);
    void run(const GpuPatchSource& source, std::uint32_t tests, const CullView& view, BackpatchMethod method,
             const HiZTexture* hiz);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

struct DrawListBuffers;  // gl_compaction.h

/// The two ends of the flag chain (see the header).
class CullStatusPass {
public:
    explicit CullStatusPass(PassContext& context);
    CullStatusPass(CullStatusPass&&) noexcept;
    CullStatusPass& operator=(CullStatusPass&&) noexcept;
    ~CullStatusPass();
    /// Clears the reason bits of the range (statuses kept). The control points are not read
    /// (patches.control_points may be 0: GpuPatchSource::flag_buffers()).
    void begin(const PatchBuffers& patches);
    /// Reasons -> statuses: a patch with no reason gets kStatusVisible (plus kStatusNewlyVisible
    /// when it lacked kStatusVisible), a culled one its reason alone. Adds the counts (shared.h's
    /// kCounter*; kCounterDisplacedOcclusion needs the margins) to counters (kCounterCount uints
    /// from byte counters_offset, a multiple of GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT; 0 = not
    /// counted).
    void end(const PatchBuffers& patches, std::uint32_t counters, std::size_t counters_offset = 0);
    /// end(patches, counters, counters_offset), fused with the compaction of the set it decides:
    /// the patches whose new word satisfies (word & mask) == value (shared.h's kDrawMask* /
    /// kDrawValue* pairs, e.g. kDrawMaskSecondPass for the newly visible) go to out.list, and the
    /// commands and draw count to out, exactly as CompactPass::run(patches, mask, value, out,
    /// CompactMethod::atomic_append) would write them after end (gl_compaction.h: same set, same
    /// commands and count; the list's order changes from run to run). One atomicAdd per work group
    /// in the end's own dispatch (no second pass over the flags), then a small dispatch of
    /// compact.comp.glsl's commands step. Also checks out as CompactPass does (same errors, named
    /// "CullStatusPass"), binds kBindingDrawList, kBindingDrawCommands, kBindingDrawCount and a
    /// buffer of its own at kBindingCompactSums (made on the first such call), and ends with
    /// GL_COMMAND_BARRIER_BIT too. A range of 0 patches writes CompactPass's empty command.
    void end(const PatchBuffers& patches, std::uint32_t counters, std::size_t counters_offset,
             const DrawListBuffers& out, std::uint32_t mask, std::uint32_t value);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace patchcull::gl
