// examples/06_vulkan/patch.tesc.glsl: one uniform level for the whole patch. Nothing of
// patchcull's here: a culled patch is simply not in the list (the indirect draw never issues it).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(vertices = 16) out;
layout(location = 0) in vec4 vs_point[];
layout(location = 1) flat in uint vs_patch[];
layout(location = 0) out vec4 tcs_point[];
layout(location = 1) patch out uint tcs_patch;

void main() {
    tcs_point[gl_InvocationID] = vs_point[gl_InvocationID];
    if (gl_InvocationID == 0) {
        float level = u.eye_level.w;
        gl_TessLevelOuter[0] = gl_TessLevelOuter[1] = gl_TessLevelOuter[2] = gl_TessLevelOuter[3] = level;
        gl_TessLevelInner[0] = gl_TessLevelInner[1] = level;
        tcs_patch = vs_patch[0];
    }
}
