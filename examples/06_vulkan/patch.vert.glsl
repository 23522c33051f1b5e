// examples/06_vulkan/patch.vert.glsl: pulls the control points of the listed patches (no vertex
// attributes). Vertex gl_VertexIndex is point gl_VertexIndex % 16 of patch
// draw_list[gl_VertexIndex / 16]: CompactPass's command c starts at firstVertex 16 (list_first + c K)
// (patchcull/vk/vk_passes.h), so gl_VertexIndex already counts from the list's start.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(location = 0) out vec4 vs_point;  // homogeneous control point (w x, w y, w z, w)
layout(location = 1) flat out uint vs_patch;

void main() {
    uint v = uint(gl_VertexIndex);
    vs_patch = draw_list[v / 16u];  // the patch's index in the patch (and flag) buffer
    vs_point = control_points[16u * vs_patch + v % 16u];
}
