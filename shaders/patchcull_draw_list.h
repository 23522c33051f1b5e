// shaders/patchcull_draw_list.h: what a vertex shader adds to draw a compacted list (GLSL 4.50;
// include after shared.h, whose constants it uses). Shipped for engines
// (shipped_glsl("patchcull_draw_list.h")).
//
// CompactPass (include/patchcull/gl/gl_compaction.h) writes the indices of the patches a draw
// selection keeps into a list at kBindingDrawList and an indirect command whose vertex k of list
// entry e is gl_VertexID = 16 e + k (the command's first is 16 list_first). The draw has no vertex
// attributes: the vertex shader pulls point k of patch list[e] from your control points, e.g.
//     const uint patch_index = patchcull_draw_list_patch(gl_VertexID);
//     gl_Position = control_points[16u * patch_index + patchcull_draw_list_point(gl_VertexID)];
//     v_patch_index = patch_index;  // flat: the flag buffer's index, as in the non-compacted draw
// Every patch of the list passed the selection, so the TCS needs no patchcull_tcs.h check.

layout(std430, binding = kBindingDrawList) readonly buffer PatchcullDrawList {
    uint patchcull_draw_list[];
};

// The patch (its index in the flag and control-point buffers) that vertex vertex_id belongs to.
uint patchcull_draw_list_patch(int vertex_id) {
    return patchcull_draw_list[uint(vertex_id) / kDrawListPatchVertices];
}

// The control point (0..15, patch.h order) that vertex vertex_id is.
uint patchcull_draw_list_point(int vertex_id) {
    return uint(vertex_id) % kDrawListPatchVertices;
}
