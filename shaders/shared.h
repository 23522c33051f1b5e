// shaders/shared.h: constants shared by the C++ renderer (src/gl) and the GLSL shaders: the one
// configuration header of the GPU passes (with the flag word of patchcull/core/cull_flags.h).
//
// Valid C++20 and GLSL 4.50 at once. Shaders pull it in with `#include "shared.h"`, which the
// build replaces by this file's text (cmake/GlShaders.cmake) before validating the expanded
// shader with glslangValidator and embedding it into the binary; C++ includes it directly.
// Constants only (uint and float): they are the contract between the two languages (buffer
// binding points, flag bits, work-group sizes, id encoding, the front-facing threshold).
// Sections: every binding point, texture and image unit (each declared once); the flag word, its
// draw selections and counters; drawing and id constants; then one section per pass family with
// its buffer layouts, work groups and modes (back-patch, displaced). The GLSL storage blocks of the
// per-patch buffers that several shaders share are in patch_buffers.h (GLSL, patchcull's shaders).
#ifndef PATCHCULL_SHADERS_SHARED_H
#define PATCHCULL_SHADERS_SHARED_H

#include "patchcull/core/cull_flags.h"

#ifdef __cplusplus
#include <cstdint>
namespace patchcull::gl::shared {
using uint = std::uint32_t;
using patchcull::kCullBackPatch;
using patchcull::kCullFrustum;
using patchcull::kCullObject;
using patchcull::kCullOcclusion;
using patchcull::kCullReasonMask;
using patchcull::kStatusNewlyVisible;
using patchcull::kStatusVisible;
#define PATCHCULL_CONST inline constexpr
#else
#define PATCHCULL_CONST const
#endif

// Shader storage buffer binding points (std430).
PATCHCULL_CONST uint kBindingControlPoints = 0u;  // vec4 cp[16 * patch_count]: patch p's point k at 16p+k
PATCHCULL_CONST uint kBindingCullFlags = 1u;      // uint flags[patch_count]: the flag word (cull reason bits 0-7: 0 = drawn; statuses)
PATCHCULL_CONST uint kBindingMaxDisplacement = 2u; // float max_disp[patch_count], >= 0 (cull margin)
PATCHCULL_CONST uint kBindingPatchTexcoords = 3u;  // vec2 uv[4 * patch_count]: corner texcoords (patch.h order)
PATCHCULL_CONST uint kBindingPlaneValues = 4u;     // float values[6 * patch_count]: frustum diagnostics
// vec4 box[2 * box_count]: the occlusion-query proxies of gl_object_queries.h, box k's min at
// 2k and max at 2k + 1 (xyz, world space, already widened by the caller). (5 held the back-patch
// hook's flags before the flag chain of gl_passes.h.)
PATCHCULL_CONST uint kBindingQueryBoxes = 5u;
PATCHCULL_CONST uint kBindingCullCounters = 6u;    // uint counters[kCounterCount]: added by cull_status (end)
PATCHCULL_CONST uint kBindingOccluderVertices = 7u; // vec4 v[3 * triangle_count]: triangle list, w = 1
// vec4 t[kTangentVec4s * patch_count]: patch p's ACC tangent patches at kTangentVec4s p + (du[0..11],
// dv[0..11]) as (x, y, z, 0); t[kTangentVec4s p].w = 1 when the patch has them (else unused).
PATCHCULL_CONST uint kBindingPatchTangents = 10u;
PATCHCULL_CONST uint kTangentVec4s = 24u;
// uint marks[patch_count], one per patch, written as 1 (never read by a draw): the patches the
// TCS tessellated (PatchRenderer::read_drawn_patches), or the patches with a fragment at the
// front depth (the mark-front pass, PatchRenderer::mark_front_patches). The renderer binds the
// buffer of the pass at hand.
PATCHCULL_CONST uint kBindingPatchMarks = 11u;
// float scale[patch_count]: patch p's uniform tessellation level is min(64, level * scale[p]),
// scale = 2^(D - depth) (PatchAttributes::depth): equal vertex density across refinement depths.
PATCHCULL_CONST uint kBindingPatchTessScale = 12u;
// The passes' own buffers (their layouts: the pass sections below and the headers named). Every
// binding point of patchcull is declared here, once, and each is used by one
// buffer only (tests/gl/shader_bindings_test.cpp): passes leave their buffers bound, so a shared
// number would let one pass read another's buffer.
PATCHCULL_CONST uint kBindingDisplacementRanges = 8u;  // displaced: vec2 (d_min, d_max) per patch
PATCHCULL_CONST uint kBindingDisplacedBounds = 9u;     // displaced: diagnostics
PATCHCULL_CONST uint kBindingPtpPlanes = 13u;          // backpatch_ptp: diagnostics
PATCHCULL_CONST uint kBindingConeValues = 14u;         // backpatch_cones: diagnostics
PATCHCULL_CONST uint kBindingPtpTables = 31u;          // backpatch_ptp on Vulkan: the schedule's tables (ptp_tables.h)
PATCHCULL_CONST uint kBindingProbeIn = 15u;            // backpatch_probe: vec4 in[n]: (a, b, c, unused)
PATCHCULL_CONST uint kBindingProbeOut = 16u;           // backpatch_probe: float out[n]
// pose_stencils (gl_posing.h's StencilPoser; outputs at kBindingControlPoints and
// kBindingPatchTangents): posed control mesh vertices, instances, the per-patch instance table,
// stencil row offsets and terms, the tangent table.
PATCHCULL_CONST uint kBindingPoseVertices = 17u;
PATCHCULL_CONST uint kBindingPoseInstances = 18u;
PATCHCULL_CONST uint kBindingPosePatchTable = 19u;
PATCHCULL_CONST uint kBindingPoseOffsets = 20u;
PATCHCULL_CONST uint kBindingPoseTerms = 21u;
PATCHCULL_CONST uint kBindingPoseTangentTable = 22u;
// Passes over the caller's own control points (gl_passes.h's GpuPatchSource; shaders/patch_source.h):
// the vertex buffer read as float[], the index buffer (uint per slot), the boundary masks (one
// byte per patch, read as packed uint words).
PATCHCULL_CONST uint kBindingSourceVertices = 23u;
PATCHCULL_CONST uint kBindingSourceIndices = 24u;
PATCHCULL_CONST uint kBindingSourceMasks = 25u;
// Compaction (gl_compaction.h's CompactPass: compact.comp.glsl; the draw side patchcull_draw_list.h):
// uint list[n], the indices of the patches a draw selection keeps; the indirect commands
// (DrawArraysIndirectCommand, 4 uints each) and the draw counts, read as uint words; the pass's own
// per-work-group sums of its prefix scan.
PATCHCULL_CONST uint kBindingDrawList = 26u;
PATCHCULL_CONST uint kBindingDrawCommands = 27u;
PATCHCULL_CONST uint kBindingDrawCount = 28u;
PATCHCULL_CONST uint kBindingCompactSums = 29u;
// OpenSubdiv's own patch shaders as gl_osd's OsdPatchTableDraw draws them: with
// OsdDrawOptions::record_tessellated, uint marks[n], set by the TES for each patch it evaluates.
PATCHCULL_CONST uint kBindingOsdTessellated = 30u;

// Uniform buffer binding of the passes' parameter blocks (pass_params.h; one pass runs at a time).
PATCHCULL_CONST uint kUniformPassParams = 0u;
// ... and of the patch-source block (pass_params.h's PatchSourceParams) of the passes run on a GpuPatchSource.
PATCHCULL_CONST uint kUniformPatchSource = 1u;

// Texture units.
PATCHCULL_CONST uint kTextureUnitDisplacement = 0u;  // R32F height map, GL_REPEAT, bilinear
PATCHCULL_CONST uint kTextureUnitDepth = 1u;         // DEPTH32F depth buffer (Hi-Z level 0 input)
PATCHCULL_CONST uint kTextureUnitHiZ = 2u;           // R32F Hi-Z pyramid, level l = hiz.h's level l
PATCHCULL_CONST uint kTextureUnitOsdPatchParam = 4u; // OpenSubdiv's patch-param texture buffer (gl_osd's draws)

// Image units.
PATCHCULL_CONST uint kImageUnitHiZOut = 0u;          // R32F Hi-Z level being written

// Per-patch flag word (kBindingCullFlags): the cull reasons kCullFrustum, kCullBackPatch,
// kCullOcclusion, kCullObject (bits 0-7, kCullReasonMask) and the statuses kStatusVisible,
// kStatusNewlyVisible (bits 8-9) are declared once, for C++ and GLSL, in
// patchcull/core/cull_flags.h (included above). The test passes form a chain (flag_chain.h,
// gl_passes.h) in which the first test that culls a patch sets its reason and the later ones skip
// it; cull_status (end) turns reasons into statuses. kCullObject is written by CullPipeline with a
// buffer clear for patches culled with their object (object_culling.h), before any pass.

// cull_status.comp.glsl's modes (CullStatusParams::mode).
PATCHCULL_CONST uint kStatusBegin = 0u;  // clear the reasons, keep the statuses
PATCHCULL_CONST uint kStatusEnd = 1u;    // reasons -> statuses, counters

// Draw selections (mask, value) on the flag word (patchcull_tcs.h): a draw keeps patch p when
// (flags[p] & mask) == value.
PATCHCULL_CONST uint kDrawMaskUnculled = kCullReasonMask;  // no test culled it this frame
PATCHCULL_CONST uint kDrawValueUnculled = 0u;
PATCHCULL_CONST uint kDrawMaskFirstPass = kStatusVisible;  // tagged visible (by the previous frame)
PATCHCULL_CONST uint kDrawValueFirstPass = kStatusVisible;
PATCHCULL_CONST uint kDrawMaskSecondPass = kStatusVisible | kStatusNewlyVisible;  // newly visible
PATCHCULL_CONST uint kDrawValueSecondPass = kStatusVisible | kStatusNewlyVisible;

// compact.comp.glsl's modes (CompactParams::mode): the atomic append (init, append) and the
// order-preserving prefix scan (group counts, scan of the sums, scatter), each then finish (the
// commands and the draw count from the total).
PATCHCULL_CONST uint kCompactInit = 0u;
PATCHCULL_CONST uint kCompactAppend = 1u;
PATCHCULL_CONST uint kCompactFinish = 2u;
PATCHCULL_CONST uint kCompactGroupCounts = 3u;
PATCHCULL_CONST uint kCompactScanSums = 4u;
PATCHCULL_CONST uint kCompactScatter = 5u;
// The scan of a range of at most kCompactSingleGroupPatches in one dispatch of one work group
// (counts, scan, scatter and finish in a loop over its runs of 2048: fewer dispatches).
PATCHCULL_CONST uint kCompactSingleGroup = 6u;
PATCHCULL_CONST uint kCompactSingleGroupPatches = 16384u;
// Control points a compacted draw pulls per patch (gl_VertexID / kDrawListPatchVertices indexes the list).
PATCHCULL_CONST uint kDrawListPatchVertices = 16u;

// Counters added by cull_status (end) (kBindingCullCounters); the caller clears them.
PATCHCULL_CONST uint kCounterFrustum = 0u;       // patches culled by a frustum test (the bound's, for displaced ones)
PATCHCULL_CONST uint kCounterBackPatch = 1u;     // ... by a back-patch test
PATCHCULL_CONST uint kCounterOcclusion = 2u;     // ... by a Hi-Z test (control points or displaced bound)
PATCHCULL_CONST uint kCounterWasVisible = 3u;    // tagged visible before the test (first-pass draws)
PATCHCULL_CONST uint kCounterVisible = 4u;       // passed the test
PATCHCULL_CONST uint kCounterNewlyVisible = 5u;  // passed the test, not tagged visible before
PATCHCULL_CONST uint kCounterDisplacedOcclusion = 6u;  // of kCounterOcclusion: displaced patches (margin > 0)
PATCHCULL_CONST uint kCounterCount = 8u;

// Patch fragment colour modes (u_color_mode).
PATCHCULL_CONST uint kColorPatch = 0u;   // per-patch hue, shaded
PATCHCULL_CONST uint kColorStatus = 1u;  // status of the flag word (gl_renderer.h's legend), shaded

// One-sided drawing of closed, outward-oriented surfaces (RenderParams::discard_back_facing): the
// patch fragment shader re-evaluates the exact surface at the fragment's (u, v) and keeps the
// fragment only when cos(angle between the normal du x dv and the direction to the eye) exceeds
// this value. Every back-patch test culls only patches whose tangent planes all face away
// (cos <= 0), so a culled patch never has a kept fragment even with the fragment shader's float
// rounding (~1e-6 here); what the margin drops is a sub-pixel band of grazing fragments at
// silhouettes, in the culled and the unculled render alike.
PATCHCULL_CONST float kFrontFacingMinCosine = 1.0e-3f;

// Patch-ID buffer encoding (R32UI): 0 = background, patch p writes p + 1; triangle t of the
// occluder mesh writes kIdOccluderBit | t.
PATCHCULL_CONST uint kIdBackground = 0u;
PATCHCULL_CONST uint kIdOccluderBit = 0x80000000u;

// Compute work-group size of the per-patch cull shaders (one invocation per patch).
PATCHCULL_CONST uint kCullGroupSize = 64u;
// Compaction work groups (the append: one invocation per patch; the scan of the group sums runs in one group).
PATCHCULL_CONST uint kCompactGroupSize = 256u;
// ... and the patches of one invocation in the scan's modes (consecutive; a group holds 2048).
PATCHCULL_CONST uint kCompactScanRun = 8u;
// Hi-Z build work groups: kHiZGroupSize x kHiZGroupSize texels of one level.
PATCHCULL_CONST uint kHiZGroupSize = 8u;
// 24-bit depth textures (HiZBuildPass): a depth d read as float is widened by 1.5 / (2^24 - 1)
// before its key is taken: half a step for GL_LEQUAL / GL_GEQUAL ties, one step for the driver's
// conversion of the integer to float (below 2^-24).
PATCHCULL_CONST float kHiZUnorm24Slack = 1.5f / 16777215.0f;

// ---- Back-patch passes (BackpatchCuller of gl_backpatch.h and the passes it runs) --------------
// Diagnostics, written only on request: backpatch_ptp at kBindingPtpPlanes (float t[64 *
// patch_count]: patch p's control plane z components at 64p + 8 jv + iu, exactly the CPU kernel's
// t); backpatch_cones (tcone / ncone) at kBindingConeValues (float c[kConeValues * patch_count]:
// patch p's cone and sphere at kConeValues p + (axis.x, axis.y, axis.z, cos, sin, valid (1 or 0),
// center.x, center.y, center.z, radius, 0, 0)). backpatch_probe.comp.glsl (tests and the start-up
// fma check) reads kBindingProbeIn and writes kBindingProbeOut.
PATCHCULL_CONST uint kConeValues = 12u;

// Work groups: cones, one invocation per patch; ptp, kPtpLanes invocations per patch (Loop, Niessner &
// Eisenacher §6: 16 threads per patch, each owning one 4x4 block's 4 destinations) and kPtpPatchesPerGroup
// patches per work group (local size kPtpLanes x kPtpPatchesPerGroup).
PATCHCULL_CONST uint kConeGroupSize = 64u;
PATCHCULL_CONST uint kPtpLanes = 16u;
PATCHCULL_CONST uint kPtpPatchesPerGroup = 8u;
PATCHCULL_CONST uint kProbeGroupSize = 64u;

// backpatch_probe modes (u_mode).
PATCHCULL_CONST uint kProbeFma = 0u;       // out = pc_fma(a, b, c)
PATCHCULL_CONST uint kProbeDiv = 1u;       // out = pc_div(a, b)
PATCHCULL_CONST uint kProbeSqrt = 2u;      // out = pc_sqrt(a)
PATCHCULL_CONST uint kProbeDivFrom = 3u;   // out = pc_div_from(a, b, c): c a guess of a / b
PATCHCULL_CONST uint kProbeSqrtFrom = 4u;  // out = pc_sqrt_from(a, b): b a guess of sqrt(a)

// ---- Displaced pass (gl_displaced.h, DisplacedPass: displaced.comp.glsl) ---------------------
// Per-patch displacement ranges at kBindingDisplacementRanges (vec2 range[patch_count]: (d_min,
// d_max)), read only when the pass has ranges (else every patch is undisplaced, as a null ranges
// pointer on the CPU); diagnostics at kBindingDisplacedBounds (float b[kDisplacedBoundValues *
// patch_count]): patch p's DisplacedBound at kDisplacedBoundValues p + (ndc_xmin, ndc_xmax,
// ndc_ymin, ndc_ymax, depth_near, depth_far, status as a float, 0), written only on request.
// The Hi-Z pyramid is on kTextureUnitHiZ.
PATCHCULL_CONST uint kDisplacedBoundValues = 8u;

// One invocation per patch.
PATCHCULL_CONST uint kDisplacedGroupSize = 64u;

// u_bound_kind (DisplacedBoundKind) and the PC_DISPLACED_CONE compile-time define (NormalConeKind).
PATCHCULL_CONST uint kDisplacedBoundOobb = 0u;
PATCHCULL_CONST uint kDisplacedBoundCaf = 1u;
PATCHCULL_CONST uint kDisplacedConeFull = 0u;
PATCHCULL_CONST uint kDisplacedConeAcon = 1u;
PATCHCULL_CONST uint kDisplacedConeCon = 2u;

// ---- Patch sources (GpuPatchSource of gl_passes.h: shaders/patch_source.h) ----------------------
// The basis (PatchSourceParams::basis; core/patch_source.h's PatchBasis, in its order).
PATCHCULL_CONST uint kSourceBasisBezier = 0u;
PATCHCULL_CONST uint kSourceBasisBspline = 1u;
PATCHCULL_CONST uint kSourceBasisGregory = 2u;
// The slots of a 4 x 4 B-spline grid that a boundary edge makes phantom (bspline_real_slots of
// core/patch_source.h: bit k for slot k = 4 row + column): mask bit 0 row 0, bit 1 column 3, bit 2
// row 3, bit 3 column 0.
PATCHCULL_CONST uint kBsplinePhantomRow0 = 0x000Fu;
PATCHCULL_CONST uint kBsplinePhantomColumn3 = 0x8888u;
PATCHCULL_CONST uint kBsplinePhantomRow3 = 0xF000u;
PATCHCULL_CONST uint kBsplinePhantomColumn0 = 0x1111u;
// The B-spline -> Bezier change of basis' constants as float bits: 1.0f / 6.0f and 1.0f / 3.0f
// (patch_source.cpp's kSixth, kThird).
PATCHCULL_CONST uint kBsplineSixthBits = 0x3E2AAAABu;
PATCHCULL_CONST uint kBsplineThirdBits = 0x3EAAAAABu;
// cull_status.comp.glsl's draw-list append (PC_STATUS_APPEND: CullStatusPass::end with a
// DrawListBuffers, gl_passes.h): the words of the pass's own buffer at kBindingCompactSums, written
// before the end's dispatches: the survivor total (0 before; compact.comp.glsl's kCompactFinish then
// reads it as its word 0), the range's first list entry, and the selection (mask, value) on the
// new flag word.
PATCHCULL_CONST uint kStatusAppendTotal = 0u;
PATCHCULL_CONST uint kStatusAppendListFirst = 1u;
PATCHCULL_CONST uint kStatusAppendMask = 2u;
PATCHCULL_CONST uint kStatusAppendValue = 3u;
PATCHCULL_CONST uint kStatusAppendWords = 4u;

#ifdef __cplusplus
}  // namespace patchcull::gl::shared
#endif
#undef PATCHCULL_CONST

#endif  // PATCHCULL_SHADERS_SHARED_H
