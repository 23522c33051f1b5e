// Patch vertex shader: fetches control point gl_VertexID from the control-point buffer and
// derives the patch index from it (gl_VertexID / 16). llvmpipe restarts gl_PrimitiveID every
// 4096 input vertices (Mesa 22.3.6 to 25.0.7), so no later stage uses gl_PrimitiveID.
// With PATCHCULL_DRAW_LIST (PatchRenderer::draw_indirect: a list CompactPass wrote), vertex
// gl_VertexID is point gl_VertexID % 16 of patch list[gl_VertexID / 16] (patchcull_draw_list.h);
// the patch index passed on is the same flag-buffer index either way.
#version 450 core
#include "shared.h"
#include "draw_params.h"
#define PC_CONTROL_POINTS readonly
#include "patch_buffers.h"
#ifdef PATCHCULL_DRAW_LIST
#include "patchcull_draw_list.h"
#endif

out vec4 vs_point;       // object-space homogeneous control point (x*w, y*w, z*w, w)
flat out uint vs_patch;  // patch index

void main() {
#ifdef PATCHCULL_DRAW_LIST
    vs_patch = patchcull_draw_list_patch(PC_VERTEX_INDEX);
    vs_point = control_points[kDrawListPatchVertices * vs_patch + patchcull_draw_list_point(PC_VERTEX_INDEX)];
#else
    vs_point = control_points[PC_VERTEX_INDEX];
    vs_patch = uint(PC_VERTEX_INDEX) / 16u;
#endif
}
