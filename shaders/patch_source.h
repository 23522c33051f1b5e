// shaders/patch_source.h (GLSL only): a cull pass's control points read from the caller's own
// buffers (GpuPatchSource of include/patchcull/gl/gl_passes.h), the GPU twin of
// core/patch_source.h's gather_bezier. Included by frustum.comp.glsl, frustum_disp.comp.glsl,
// occlusion.comp.glsl, fused_cull.comp.glsl, backpatch_cones.comp.glsl and backpatch_ptp.comp.glsl
// after shared.h and pass_params.h; empty
// unless the program is compiled with PC_PATCH_SOURCE (and PC_PATCH_SOURCE_GREGORY for Gregory
// sources, 20 points per patch).
//
// pc_gather_source(p) fills pc_source_points with the points of the shader's patch p (flag index
// p; source patch s = p + pc_source.patch_delta):
// - bezier: the 16 points as they are, (x, y, z, 1) for 3 components;
// - bspline: the 16 real points (phantom slots beyond the boundary edges of its mask, never read,
//   are zero), converted to Bezier form along u within each row (mask bits 3 and 1: columns 0 and
//   3), then along v within each column (bits 0 and 2: rows 0 and 3), with gather_bezier's
//   arithmetic operation by operation: end point (b0 + 4 b1 + b2) * fl(1/6) (b1 at a boundary),
//   inner points (2 b1 + b2) * fl(1/3) and (b1 + 2 b2) * fl(1/3), other end (b1 + 4 b2 + b3) *
//   fl(1/6) (b2 at a boundary); `precise` keeps the compiler from contracting or reassociating, and
//   the multiplications by 2 and 4 are exact, so every converted point equals the CPU's bit for
//   bit; with 3 components w stays 1 (the CPU converts x, y, z only);
// - gregory: the 20 points as they are.
// It returns false (the pass then leaves the patch unculled) when an index that would be read is
// >= point_count: no vertex past the caller's buffer is ever read.
#ifdef PC_PATCH_SOURCE

layout(std430, binding = kBindingSourceVertices) readonly buffer SourceVertices {
    float source_vertices[];  // point i's x at vertex_base + i vertex_stride, then y, z (and w)
};
layout(std430, binding = kBindingSourceIndices) readonly buffer SourceIndices {
    uint source_indices[];  // patch s's slot k at index_base + n s + k (read when has_indices)
};
layout(std430, binding = kBindingSourceMasks) readonly buffer SourceMasks {
    uint source_masks[];  // one byte per patch: patch s's at byte mask_base + s (read when has_masks)
};

#ifdef PC_PATCH_SOURCE_GREGORY
#define PC_SOURCE_POINTS 20u
#else
#define PC_SOURCE_POINTS 16u
#endif

vec4 pc_source_points[PC_SOURCE_POINTS];  // the gathered patch (this invocation's)

// The slots of a 4 x 4 B-spline grid that hold real points under boundary mask m
// (bspline_real_slots of core/patch_source.h).
uint pc_bspline_real_slots(uint m) {
    uint phantom = 0u;
    if ((m & 1u) != 0u) phantom |= kBsplinePhantomRow0;
    if ((m & 2u) != 0u) phantom |= kBsplinePhantomColumn3;
    if ((m & 4u) != 0u) phantom |= kBsplinePhantomRow3;
    if ((m & 8u) != 0u) phantom |= kBsplinePhantomColumn0;
    return ~phantom & 0xFFFFu;
}

// One direction of the change of basis on points a, b, c, d of pc_source_points (patch_source.cpp's
// bspline_to_bezier); lo / hi: a boundary at the first / last end.
void pc_bspline_to_bezier(uint a, uint b, uint c, uint d, bool lo, bool hi) {
    const float sixth = uintBitsToFloat(kBsplineSixthBits), third = uintBitsToFloat(kBsplineThirdBits);
    const vec4 p0 = pc_source_points[a], p1 = pc_source_points[b], p2 = pc_source_points[c],
               p3 = pc_source_points[d];
    precise vec4 e0 = p0 + 4.0 * p1;
    e0 = e0 + p2;
    e0 = e0 * sixth;
    precise vec4 e1 = 2.0 * p1;
    e1 = e1 + p2;
    e1 = e1 * third;
    precise vec4 e2 = 2.0 * p2;
    e2 = p1 + e2;
    e2 = e2 * third;
    precise vec4 e3 = 4.0 * p2;
    e3 = p1 + e3;
    e3 = e3 + p3;
    e3 = e3 * sixth;
    pc_source_points[a] = lo ? p1 : e0;
    pc_source_points[b] = e1;
    pc_source_points[c] = e2;
    pc_source_points[d] = hi ? p2 : e3;
}

// Point `index` of the vertex buffer into v; false (v = 0) when index >= point_count.
bool pc_source_vertex(uint index, out vec4 v) {
    v = vec4(0.0);
    if (index >= pc_source.point_count) return false;
    const uint at = pc_source.vertex_base + index * pc_source.vertex_stride;
    v = vec4(source_vertices[at], source_vertices[at + 1u], source_vertices[at + 2u], 1.0);
    if (pc_source.components == 4u) v.w = source_vertices[at + 3u];
    return true;
}

// Gathers the shader's patch p into pc_source_points (see the top of this file).
bool pc_gather_source(uint p) {
    const uint s = p + pc_source.patch_delta;
    uint mask = 0u;
    if (pc_source.has_masks != 0u) {
        const uint byte_at = pc_source.mask_base + s;
        mask = (source_masks[byte_at >> 2] >> (8u * (byte_at & 3u))) & 15u;
    }
    const uint real = pc_bspline_real_slots(mask);  // every slot without a mask
    bool ok = true;
    for (uint k = 0u; k < PC_SOURCE_POINTS; ++k) {
        vec4 v = vec4(0.0);
        if (k >= 16u || ((real >> k) & 1u) != 0u) {
            const uint index = pc_source.has_indices != 0u
                                   ? source_indices[pc_source.index_base + PC_SOURCE_POINTS * s + k]
                                   : PC_SOURCE_POINTS * s + k;
            if (!pc_source_vertex(index, v)) ok = false;
        }
        pc_source_points[k] = v;
    }
#ifndef PC_PATCH_SOURCE_GREGORY
    if (pc_source.basis == kSourceBasisBspline) {
        const bool u0 = (mask & 8u) != 0u, u1 = (mask & 2u) != 0u, v0 = (mask & 1u) != 0u, v1 = (mask & 4u) != 0u;
        for (uint r = 0u; r < 4u; ++r) pc_bspline_to_bezier(4u * r, 4u * r + 1u, 4u * r + 2u, 4u * r + 3u, u0, u1);
        for (uint i = 0u; i < 4u; ++i) pc_bspline_to_bezier(i, 4u + i, 8u + i, 12u + i, v0, v1);
        if (pc_source.components == 3u)
            for (uint k = 0u; k < 16u; ++k) pc_source_points[k].w = 1.0;
    }
#endif
    return ok;
}

#endif  // PC_PATCH_SOURCE
