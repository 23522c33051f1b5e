// Patch vertex shader: fetches control point gl_VertexID from the control-point buffer and
// derives the patch index from it (gl_VertexID / 16). llvmpipe restarts gl_PrimitiveID every
// 4096 input vertices (Mesa 22.3.6 to 25.0.7), so no later stage uses gl_PrimitiveID.
#version 450 core
#include "shared.h"
#define PC_CONTROL_POINTS readonly
#include "patch_buffers.h"

out vec4 vs_point;       // object-space homogeneous control point (x*w, y*w, z*w, w)
flat out uint vs_patch;  // patch index

void main() {
    vs_point = control_points[gl_VertexID];
    vs_patch = uint(gl_VertexID) / 16u;
}
