// Hi-Z build pass (HiZBuildPass, src/gl/hiz_build_pass.cpp; Niessner & Loop §4.1): one dispatch per pyramid level, one invocation per texel of the
// level written. Level 0 (half resolution) reduces the depth buffer (u_depth), level l > 0 reduces
// level l-1 of the pyramid itself (u_hiz, another level of the same texture than the one written).
// Texel (tx, ty) = max of its (up to) 2x2 children (2tx+i, 2ty+j); a child past the last
// row/column of the source is replaced by the last one (clamp), which a max ignores: exactly
// hiz.h's "children outside the parent level skipped", in the CPU's order
// (max(max(a0, a1), max(b0, b1)) with `a > b ? a : b`), so the texels are bit-identical to
// HiZPyramid::build on the same depth buffer. Row 0 = bottom in both. Level 0 stores depth keys
// (hiz.h): d, or -d when hiz_build.reversed; from a 24-bit depth texture the far end of the depths
// that store the same integer, widened by 1.5 / (2^24 - 1) and one ulp (HiZBuildPass::run).
#version 450 core
#include "shared.h"
#include "pass_params.h"

layout(local_size_x = kHiZGroupSize, local_size_y = kHiZGroupSize) in;

layout(binding = kTextureUnitDepth) uniform sampler2D u_depth;  // a depth format, no compare mode
layout(binding = kTextureUnitHiZ) uniform sampler2D u_hiz;      // the pyramid (source level)
layout(binding = kImageUnitHiZOut, r32f) writeonly uniform image2D u_out;


float pc_max(float a, float b) { return a > b ? a : b; }

// The next float above x (x finite).
float pc_next_up(float x) {
    const uint b = floatBitsToUint(x);
    if (x == 0.0) return uintBitsToFloat(1u);
    return uintBitsToFloat(x > 0.0 ? b + 1u : b - 1u);
}

// The depth key of depth-buffer value d. Level 0's program is compiled for the texture's format
// and convention (PC_HIZ_UNORM24, PC_HIZ_REVERSED: 0 or 1; llvmpipe computes every side of a
// branch, even on a uniform).
#ifdef PC_HIZ_UNORM24
#define PC_HIZ_IS_UNORM24 (PC_HIZ_UNORM24 != 0)
#define PC_HIZ_IS_REVERSED (PC_HIZ_REVERSED != 0)
#else
#define PC_HIZ_IS_UNORM24 (hiz_build.unorm24 != 0u)
#define PC_HIZ_IS_REVERSED (hiz_build.reversed != 0u)
#endif
float depth_key(float d) {
    if (!PC_HIZ_IS_UNORM24) return PC_HIZ_IS_REVERSED ? -d : d;
    precise float widened = PC_HIZ_IS_REVERSED ? kHiZUnorm24Slack - d : d + kHiZUnorm24Slack;
    return pc_next_up(widened);
}

float source(int x, int y) {
#ifdef PC_HIZ_FROM_DEPTH
    // One program for level 0 and one for the others (llvmpipe runs both sides of a branch).
    const bool from_depth = PC_HIZ_FROM_DEPTH != 0;
#else
    const bool from_depth = hiz_build.from_depth != 0u;
#endif
    return from_depth ? depth_key(texelFetch(u_depth, ivec2(x, y), 0).r)
                      : texelFetch(u_hiz, ivec2(x, y), hiz_build.source_level).r;
}

void main() {
    const ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (t.x >= hiz_build.out_width || t.y >= hiz_build.out_height) return;
#if defined(PC_HIZ_FROM_DEPTH) && PC_HIZ_FROM_DEPTH != 0
    // Level 0 (GL): one textureGather of the 2x2 children around their shared corner. The pass
    // binds a nearest, clamp-to-edge sampler, so a child past the last row or column is the last
    // one, as below; gather's x, y, z, w are children (x0, y1), (x1, y1), (x1, y0), (x0, y0).
    const vec2 corner = vec2(2 * t + 1) / vec2(hiz_build.source_width, hiz_build.source_height);
    const vec4 d = textureGather(u_depth, corner, 0);
    const float m0 = pc_max(depth_key(d.w), depth_key(d.z));
    const float m1 = pc_max(depth_key(d.x), depth_key(d.y));
#else
    const int x0 = 2 * t.x, x1 = min(2 * t.x + 1, hiz_build.source_width - 1);
    const int y0 = 2 * t.y, y1 = min(2 * t.y + 1, hiz_build.source_height - 1);
    const float m0 = pc_max(source(x0, y0), source(x1, y0));
    const float m1 = pc_max(source(x0, y1), source(x1, y1));
#endif
    imageStore(u_out, t, vec4(pc_max(m0, m1), 0.0, 0.0, 0.0));
}
