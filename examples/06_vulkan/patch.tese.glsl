// examples/06_vulkan/patch.tese.glsl: the tessellated point of the patch, in clip space of the
// y-down projection. The winding does not matter: the pipeline culls no faces.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(quads, equal_spacing, ccw) in;
layout(location = 0) in vec4 tcs_point[];
layout(location = 1) patch in uint tcs_patch;
layout(location = 0) out vec2 tes_uv;
layout(location = 1) flat out uint tes_patch;

void main() {
    vec4 cp[16];
    for (int k = 0; k < 16; ++k) cp[k] = tcs_point[k];
    vec3 p, pu, pv;
    evaluate_patch(cp, gl_TessCoord.xy, p, pu, pv);
    tes_uv = gl_TessCoord.xy;
    tes_patch = tcs_patch;
    gl_Position = u.object_to_clip * vec4(p, 1.0);
}
