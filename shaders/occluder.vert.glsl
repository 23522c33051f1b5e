// Triangle-mesh occluder vertex shader (Niessner & Loop §3: triangle meshes are drawn before the Hi-Z is
// built, so they occlude patches). Non-indexed triangle list fetched from an SSBO (the renderer
// expands the index buffer); the triangle index gl_VertexID / 3 becomes the id.
#version 450 core
#include "shared.h"
#include "draw_params.h"

layout(std430, binding = kBindingOccluderVertices) readonly buffer OccluderVertices {
    vec4 occluder_vertices[];  // xyz object space, w = 1
};

out vec3 occ_position;
flat out uint occ_triangle;

void main() {
    const vec4 v = occluder_vertices[PC_VERTEX_INDEX];
    occ_position = v.xyz;
    occ_triangle = uint(PC_VERTEX_INDEX) / 3u;
    gl_Position = u_object_to_clip * vec4(v.xyz, 1.0);
}
