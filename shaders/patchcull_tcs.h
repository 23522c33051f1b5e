// shaders/patchcull_tcs.h: what a tessellation control shader adds to honour patchcull's cull
// decisions (GLSL 4.50; include after shared.h, whose constants it uses). Shipped for engines:
// patchcull's own patch.tesc.glsl and the OpenSubdiv patch shaders of the gl_osd layer use exactly
// this file.
//
// The cull passes (include/patchcull/gl/gl_passes.h) leave one flag word per patch in the caller's
// flag buffer; a draw reads it at kBindingCullFlags, indexed by the patch's position in that buffer.
// Where the index comes from:
// - non-indexed draws (glDrawArrays, n points a patch): gl_VertexID / n in the vertex shader,
//   passed on `flat` (gl_VertexID includes the draw's first);
// - indexed draws (glDrawElements over an index buffer, e.g. OpenSubdiv's patch arrays):
//   patchcull_primitive_patch_index(base), gl_PrimitiveID plus the draw's first patch (OpenSubdiv's
//   PrimitiveIdBase, OsdGetPatchIndex(gl_PrimitiveID)).
// gl_PrimitiveID counts the draw's patches from 0 on GPUs, but Mesa's llvmpipe (measured on 22.3.6)
// restarts it at 0 within a draw: every floor(1024 / n) patches of an indexed draw (64 B-spline,
// 51 Gregory-basis patches) and every floor(4096 / n) of a non-indexed one. Each draw starts at 0,
// so on llvmpipe split indexed draws into sub-draws of at most floor(1024 / n) patches, each with
// its own base. A patch that is not drawn gets tessellation levels 0, and the tessellator discards
// it before any evaluation (Niessner & Loop, "Patch-Based Occlusion Culling for Hardware
// Tessellation", §3).
//
// Which patches a draw keeps is a (mask, value) pair on the flag word (shared.h):
//   kDrawMaskUnculled, kDrawValueUnculled   one-pass culling: no test culled the patch this frame
//   kDrawMaskFirstPass, kDrawValueFirstPass  two-pass occlusion culling, pass 1: tagged visible by
//                                           the previous frame (before this frame's tests)
//   kDrawMaskSecondPass, kDrawValueSecondPass  pass 2: newly visible this frame
//   0, 0                                    every patch (the unculled reference)
//
// Use (invocation 0 of the TCS, after computing the levels):
//     if (!patchcull_patch_drawn(patch_index, u_draw_mask, u_draw_value)) patchcull_skip_patch();
// patchcull_skip_patch sets every outer and inner level to 0; call it after your own level
// writes (the last write wins). Where the check must come before the level writes (OpenSubdiv's
// OSD_PATCH_CULL(N) hook in its B-spline and Gregory-basis TCS, invocation 0), use
//     PATCHCULL_RETURN_UNLESS_DRAWN(patch_index, mask, value)
// which skips the patch and returns from the calling function (main), so no later write runs:
//     #undef OSD_PATCH_CULL
//     #define OSD_PATCH_CULL(N) PATCHCULL_RETURN_UNLESS_DRAWN(OsdGetPatchIndex(gl_PrimitiveID), m, v)

layout(std430, binding = kBindingCullFlags) readonly buffer PatchcullCullFlags {
    uint patchcull_cull_flags[];
};

bool patchcull_patch_drawn(uint patch_index, uint mask, uint value) {
    return (patchcull_cull_flags[patch_index] & mask) == value;
}

void patchcull_skip_patch() {
    gl_TessLevelOuter[0] = 0.0;
    gl_TessLevelOuter[1] = 0.0;
    gl_TessLevelOuter[2] = 0.0;
    gl_TessLevelOuter[3] = 0.0;
    gl_TessLevelInner[0] = 0.0;
    gl_TessLevelInner[1] = 0.0;
}

// The patch index of an indexed draw: gl_PrimitiveID + primitive_id_base (the flag index of the
// draw's first patch). See the top of this file for llvmpipe.
uint patchcull_primitive_patch_index(int primitive_id_base) {
    return uint(gl_PrimitiveID + primitive_id_base);
}

// Skips the patch (levels 0) and returns from the calling function unless the draw keeps it.
#define PATCHCULL_RETURN_UNLESS_DRAWN(patch_index, mask, value)       \
    if (!patchcull_patch_drawn(uint(patch_index), (mask), (value))) { \
        patchcull_skip_patch();                                      \
        return;                                                      \
    }
