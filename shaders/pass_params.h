// shaders/pass_params.h: the parameter block of every GPU cull pass (include/patchcull/gl/gl_passes.h),
// declared once for C++ and GLSL.
//
// Valid C++20 and GLSL 4.50 at once, like shared.h. In GLSL each PC_PARAMS block is a std140
// uniform block at binding kUniformPassParams (only one pass runs at a time, so they share it) with
// the instance name given to PC_END; in C++ it is a struct of the same name and std140 layout that
// the pass uploads whole (glNamedBufferSubData) before each dispatch. Members are ordered so that
// the C++ layout equals std140 without padding rules: matrices and vec4 arrays first, then 4-byte
// scalars, each block padded to 16 bytes (static_asserts in src/gl/pass_common.cpp check the
// sizes). Booleans are uint (std140 has no 1-byte type). Float arrays are packed into vec4s
// (std140 gives a float array a 16-byte stride): element q of a packed array a is a[q >> 2][q & 3].
//
// The include order of a shader is shared.h, then this file (it uses shared.h's
// kUniformPassParams).
#ifndef PATCHCULL_SHADERS_PASS_PARAMS_H
#define PATCHCULL_SHADERS_PASS_PARAMS_H

#ifdef __cplusplus
#include <cstdint>
namespace patchcull::gl::pass_params {
using uint = std::uint32_t;
struct vec4 {
    float x = 0, y = 0, z = 0, w = 0;
};
#define PC_PARAMS(name, slot) struct alignas(16) name
#define PC_END(instance)
#define PC_VEC4(member) vec4 member
#define PC_MAT4(member) alignas(16) float member[16]
#define PC_UINT(member) uint member = 0
#define PC_INT(member) std::int32_t member = 0
#define PC_FLOAT(member) float member = 0
#else
#include "api.h"  // PC_PARAMS: a std140 uniform block (OpenGL) or the push constants (Vulkan)
#define PC_END(instance) instance
#define PC_VEC4(member) vec4 member
#define PC_MAT4(member) mat4 member
#define PC_UINT(member) uint member
#define PC_INT(member) int member
#define PC_FLOAT(member) float member
#endif

// Every per-patch pass covers patches [first_patch, first_patch + patch_count) of its buffers
// (one dispatch covers at most 65535 work groups; pass_common.cpp's dispatch_patches splits larger
// ranges and sets first_patch per dispatch). has_margins: the margin buffer (kBindingMaxDisplacement)
// is bound; a patch with a margin > 0 is displaced (see gl_passes.h, "The flag chain").

// frustum.comp.glsl (FrustumPass): cull_frustum_scalar's test.
PC_PARAMS(FrustumParams, kUniformPassParams) {
    PC_VEC4(clip_rows[4]);             // FrustumPlanes::clip_rows
    PC_VEC4(plane_normal_length[2]);   // FrustumPlanes::normal_length[q] at [q >> 2][q & 3]
    PC_VEC4(plane_depth);              // FrustumPlanes::near_w, far_w, far_limit (w unused)
    PC_UINT(first_patch);
    PC_UINT(patch_count);
    PC_UINT(has_margins);
    PC_UINT(write_plane_values);       // diagnostics: 6 maxima per patch at kBindingPlaneValues
} PC_END(frustum);

// frustum_disp.comp.glsl (FrustumDispPass): cull_frustum_disp_scalar's test (Sathe's displaced AABB).
PC_PARAMS(FrustumDispParams, kUniformPassParams) {
    PC_VEC4(clip_rows[4]);             // FrustumPlanes::clip_rows of make_frustum_planes(object_to_clip)
    PC_VEC4(plane_depth);              // FrustumPlanes::near_w, far_w, far_limit (w unused)
    PC_UINT(first_patch);
    PC_UINT(patch_count);
    PC_UINT(has_margins);              // the margin is the patch's max |D| (the box grows by it on every side)
    PC_UINT(write_plane_values);       // diagnostics: 6 maxima per patch at kBindingPlaneValues
} PC_END(frustum_disp);

// occlusion.comp.glsl (OcclusionPass): cull_occlusion_scalar's test against a Hi-Z pyramid.
PC_PARAMS(OcclusionParams, kUniformPassParams) {
    PC_VEC4(clip_rows[4]);             // make_frustum_planes(object_to_clip, depth): the frustum
                                       // planes' and the Hi-Z box's clip transform (hiz.h step 2)
    PC_VEC4(plane_normal_length[2]);
    PC_VEC4(plane_depth);              // FrustumPlanes::near_w, far_w, far_limit (w unused)
    PC_UINT(first_patch);
    PC_UINT(patch_count);
    PC_UINT(has_margins);
    PC_UINT(with_frustum);             // 1: the frustum test first (as the CPU kernel), 0: Hi-Z only
    PC_INT(screen_width);              // the pyramid's depth buffer W x H (viewport 0, 0, W, H)
    PC_INT(screen_height);
    PC_INT(hiz_levels);                // HiZPyramid::level_count(W, H)
    PC_UINT(pad0);
} PC_END(occlusion);

// hiz_build.comp.glsl (HiZBuildPass): one dispatch per level.
PC_PARAMS(HiZBuildParams, kUniformPassParams) {
    PC_UINT(from_depth);               // level 0: reduce the depth texture, else the pyramid's level source_level
    PC_INT(source_level);
    PC_INT(source_width);              // used size of the source (W x H, or W_{l-1} x H_{l-1})
    PC_INT(source_height);
    PC_INT(out_width);                 // W_l x H_l
    PC_INT(out_height);
    PC_UINT(reversed);                 // level 0 stores -depth (reversed conventions: clip_space.h's keys)
    PC_UINT(unorm24);                  // level 0: the depth texture is 24-bit unsigned normalized
} PC_END(hiz_build);

// backpatch_cones.comp.glsl (BackpatchConePass): tcone, or ncone with PATCHCULL_NCONE.
PC_PARAMS(BackpatchConeParams, kUniformPassParams) {
    PC_VEC4(eye);                      // object space, w unused
    PC_UINT(first_patch);
    PC_UINT(patch_count);
    PC_UINT(has_margins);
    PC_UINT(write_cones);              // diagnostics: kConeValues per patch at kBindingConeValues
    PC_FLOAT(zero);                    // 0.0 at run time (Mesa folds a literal x + 0.0 into x)
    PC_UINT(pad0);
    PC_UINT(pad1);
    PC_UINT(pad2);
} PC_END(cones);

// backpatch_ptp.comp.glsl (BackpatchPtpPass).
PC_PARAMS(BackpatchPtpParams, kUniformPassParams) {
    PC_VEC4(rows[3]);                  // rows x, y, w of s * object_to_clip (backpatch_ptp.cpp: s = sign(alpha) sign(det))
    PC_UINT(first_patch);
    PC_UINT(patch_count);
    PC_UINT(has_margins);
    PC_UINT(pcnt);                     // PtpRule::pcnt (else ncnt)
    PC_UINT(write_planes);             // diagnostics: t[64], thr[64] per patch at kBindingPtpPlanes
    PC_FLOAT(zero);                    // 0.0 at run time (see BackpatchConeParams::zero)
    PC_UINT(pad0);
    PC_UINT(pad1);
} PC_END(ptp);

// displaced.comp.glsl (DisplacedPass): Niessner & Loop §4.2's bounds, DisplacedCullView's constants.
PC_PARAMS(DisplacedParams, kUniformPassParams) {
    PC_MAT4(object_to_view);           // column-major
    PC_VEC4(view_planes[6]);           // make_frustum_planes(projection).rows
    PC_VEC4(axis_unit[3]);             // xyz used
    PC_VEC4(axis_length);              // xyz used
    PC_VEC4(abs_row_z);                // |V(2, c)|
    PC_VEC4(proj);                     // P00, P02, P11, P12
    PC_VEC4(proj_z);                   // P22, P23 (depth-key projection), key_near, key_far
    PC_VEC4(constants);                // kDisplacedDeltaSlack, kDisplacedExtScale, kDisplacedFramePad, kDisplacedDepthSafety
    PC_UINT(first_patch);
    PC_UINT(patch_count);
    PC_UINT(has_ranges);               // the range buffer (kBindingDisplacementRanges) is bound
    PC_UINT(only_displaced);           // 1: patches with range (0, 0) are left to the other passes
    PC_UINT(write_bounds);             // diagnostics: kDisplacedBoundValues per patch
    PC_UINT(bound_kind);               // kDisplacedBoundOobb or kDisplacedBoundCaf
    PC_UINT(occlusion);                // also the Hi-Z test (else frustum only)
    PC_UINT(view_valid);               // DisplacedCullView::valid
    PC_INT(screen_width);
    PC_INT(screen_height);
    PC_INT(hiz_levels);
    PC_FLOAT(zero);                    // 0.0 at run time (see BackpatchConeParams::zero)
} PC_END(displaced);

// cull_status.comp.glsl (CullStatusPass): the ends of the flag chain.
PC_PARAMS(CullStatusParams, kUniformPassParams) {
    PC_UINT(first_patch);
    PC_UINT(patch_count);
    PC_UINT(has_margins);
    PC_UINT(mode);                     // kStatusBegin or kStatusEnd
} PC_END(status);

// compact.comp.glsl (CompactPass, gl_compaction.h): the patches of the range whose flag word
// satisfies (flag & mask) == value, written to the draw list from list_first on.
PC_PARAMS(CompactParams, kUniformPassParams) {
    PC_UINT(first_patch);
    PC_UINT(patch_count);
    PC_UINT(mask);
    PC_UINT(value);
    PC_UINT(mode);                     // kCompactInit .. kCompactScatter
    PC_UINT(list_first);               // the range's first entry of the draw list
    PC_UINT(command_word);             // the command at words [command_word, command_word + 4)
    PC_UINT(count_word);               // the draw count at this word of its buffer
    PC_UINT(write_count);              // the draw-count buffer is bound
    PC_UINT(group_base);               // the range-wide index of this dispatch's first work group
                                       // (kCompactFinish: its first command)
    PC_UINT(group_count);              // scan: the range's work groups (entries of the sums);
                                       // kCompactFinish: the word of the sums holding the total
    PC_UINT(patches_per_command);      // K of the commands, in [1, max(patch_count, 1)]
} PC_END(compact);

// fused_cull.comp.glsl (FusedCullPass): the frustum, back-patch cone and Hi-Z tests of one patch in
// one invocation, in the chain's order (tcone, or ncone with PATCHCULL_NCONE).
PC_PARAMS(FusedCullParams, kUniformPassParams) {
    PC_VEC4(clip_rows[4]);             // FrustumPlanes::clip_rows of make_frustum_planes(object_to_clip,
                                       // depth): the frustum planes' and the Hi-Z test's clip transform
    PC_VEC4(plane_normal_length[2]);   // FrustumPlanes::normal_length[q] at [q >> 2][q & 3]
    PC_VEC4(plane_depth);              // FrustumPlanes::near_w, far_w, far_limit (w unused)
    PC_VEC4(eye);                      // object space, w unused (the cone test)
    PC_UINT(first_patch);
    PC_UINT(patch_count);
    PC_UINT(has_margins);
    PC_UINT(tests);                    // kCullFrustum | kCullBackPatch | kCullOcclusion: the tests run
    PC_INT(screen_width);              // the pyramid's depth buffer W x H (with kCullOcclusion)
    PC_INT(screen_height);
    PC_INT(hiz_levels);                // HiZPyramid::level_count(W, H)
    PC_FLOAT(zero);                    // 0.0 at run time (see BackpatchConeParams::zero)
} PC_END(fused);

// patch_source.h: the caller's control points of a pass compiled with PC_PATCH_SOURCE, at
// kUniformPatchSource beside the pass's own block (GpuPatchSource of gl_passes.h). The shader's
// patch p (an index of the flag buffer) is source patch p + patch_delta (mod 2^32). Declared in
// GLSL only with PC_PATCH_SOURCE.
#if defined(__cplusplus) || defined(PC_PATCH_SOURCE)
PC_PARAMS(PatchSourceParams, kUniformPatchSource) {
    PC_UINT(vertex_base);              // GpuPatchSource::offset_bytes / 4: x of point i at vertex_base + i vertex_stride
    PC_UINT(vertex_stride);            // stride_bytes / 4
    PC_UINT(components);               // 3 (w = 1) or 4
    PC_UINT(point_count);              // an index >= point_count is not read (the patch is not culled)
    PC_UINT(basis);                    // kSourceBasisBezier, kSourceBasisBspline or kSourceBasisGregory
    PC_UINT(has_indices);              // 0: patch s reads points n s .. n s + n - 1
    PC_UINT(index_base);               // indices_offset_bytes / 4: patch s's slot k at index_base + n s + k
    PC_UINT(has_masks);                // bspline: the boundary-mask buffer is bound
    PC_UINT(mask_base);                // masks_offset_bytes: patch s's mask is byte mask_base + s
    PC_UINT(patch_delta);              // source_first - first
    PC_UINT(pad0);
    PC_UINT(pad1);
} PC_END(pc_source);
#endif

#undef PC_PARAMS
#undef PC_END
#undef PC_VEC4
#undef PC_MAT4
#undef PC_UINT
#undef PC_INT
#undef PC_FLOAT

#ifdef __cplusplus
}  // namespace patchcull::gl::pass_params
#endif

#endif  // PATCHCULL_SHADERS_PASS_PARAMS_H
