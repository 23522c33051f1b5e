// shaders/patchcull_tcs.h: what a tessellation control shader adds to honour patchcull's cull
// decisions (GLSL 4.50; include after shared.h, whose constants it uses). Shipped for engines:
// patchcull's own patch.tesc.glsl uses exactly this file.
//
// The cull passes (include/patchcull/gl/gl_passes.h) leave one flag word per patch in the caller's
// flag buffer; a draw reads it at kBindingCullFlags, indexed by the patch's position in the
// caller's patch buffer (patch p = the p-th patch of the draw when the draw starts at patch 0;
// derive it from gl_VertexID / 16 in the vertex shader rather than gl_PrimitiveID, which restarts
// on some drivers, e.g. Mesa llvmpipe). A patch that is not drawn gets tessellation levels 0, and
// the tessellator discards it before any evaluation (Niessner & Loop, "Patch-Based Occlusion
// Culling for Hardware Tessellation", §3).
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
// writes (the last write wins).

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
