// Patch tessellation control shader: passes the 16 control points through and sets the
// tessellation factors. A patch whose cull flag is nonzero gets outer and inner levels 0, so the
// tessellator discards it (seed 000 §3: the decision lands where the tessellator reads it).
#version 450 core
#include "shared.h"

layout(vertices = 16) out;

layout(std430, binding = kBindingCullFlags) readonly buffer CullFlags {
    uint cull_flags[];
};

uniform float u_tess_level;     // uniform level for every edge and the interior, in [1, 64]
uniform bool u_use_cull_flags;  // false: draw every patch (the reference render)

in vec4 vs_point[];
flat in uint vs_patch[];
out vec4 tcs_point[];
patch out uint tcs_patch;

void main() {
    tcs_point[gl_InvocationID] = vs_point[gl_InvocationID];
    if (gl_InvocationID == 0) {
        const uint p = vs_patch[0];
        const bool culled = u_use_cull_flags && cull_flags[p] != 0u;
        const float level = culled ? 0.0 : u_tess_level;
        gl_TessLevelOuter[0] = level;
        gl_TessLevelOuter[1] = level;
        gl_TessLevelOuter[2] = level;
        gl_TessLevelOuter[3] = level;
        gl_TessLevelInner[0] = level;
        gl_TessLevelInner[1] = level;
        tcs_patch = p;
    }
}
