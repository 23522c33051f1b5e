// shaders/frustum_test.h (GLSL only): the frustum decision of cull_frustum_scalar
// (include/patchcull/core/frustum.h) for one patch, shared by frustum.comp.glsl, occlusion.comp.glsl
// and the fused pass, so that they all make the same decisions.
//
// For each control point k = (X, Y, Z, W): clip coordinates once,
// c_r = fma(M(r,3), W, fma(M(r,2), Z, fma(M(r,1), Y, M(r,0) * X))) (hiz.h's step 2), then the plane
// values w + x, w - x, w + y, w - y, k + near_w w, far_w w - k (k: the depth-key row), and with
// margins fma(d * |plane row xyz|, W, value) (frustum_plane_values / add_frustum_margins in
// frustum.h); the patch is culled when the maximum over the 16 points is < 0 for some plane (<
// far_limit for the far one) and no point's near value was NaN or infinite (FrustumVerdict's
// probe: here a test of the exponent bits, which no compiler folds away). `precise` keeps the compiler from contracting or
// reassociating; max is written as the CPU's `a > b ? a : b`; pc_fma is exactly rounded also on
// llvmpipe (exact_fma.h).
//
// The including shader declares, before including this file: exact_fma.h, the buffer
// control_points[] (patch_buffers.h, PC_CONTROL_POINTS) and the names u_clip_rows (vec4[4], FrustumPlanes::clip_rows)
// , u_plane_normal_length (vec4[2]: FrustumPlanes::normal_length[q] at [q >> 2][q & 3]) and
// u_plane_depth (vec4: FrustumPlanes::near_w, far_w, far_limit), #defines
// onto its parameter block (pass_params.h). A pass over a patch source (patch_source.h) defines
// PC_PATCH_POINT(p, k) and PC_PATCH_POINT_COUNT before including this file: the tests then read
// the gathered points (16 Bezier points, or a Gregory patch's 20) instead of control_points[].

#ifndef PC_PATCH_POINT
#define PC_PATCH_POINT(p, k) control_points[16u * (p) + (k)]
#define PC_PATCH_POINT_COUNT 16u
#endif

// Plane values of clip-space point c (before margins).
void pc_frustum_plane_values(const vec4 c, out float v[6]) {
    precise float s[6];
    s[0] = c.w + c.x;
    s[1] = c.w - c.x;
    s[2] = c.w + c.y;
    s[3] = c.w - c.y;
    s[4] = c.z + u_plane_depth.x * c.w;
    s[5] = u_plane_depth.y * c.w - c.z;
    v = s;
}

// True when v is NaN or infinite (exponent bits all set).
bool pc_non_finite(float v) { return (floatBitsToUint(v) & 0x7F800000u) == 0x7F800000u; }

// The frustum verdict from the six maxima and the non-finite flag (FrustumVerdict::culled).
bool pc_frustum_outside(const float m[6], bool non_finite) {
    bool culled = m[5] < u_plane_depth.z;
    for (int q = 0; q < 5; ++q) culled = culled || m[q] < 0.0;
    return culled && !non_finite;
}

// Clip coordinates of object-space point P (hiz.h's step 2).
vec4 pc_clip_point(const vec4 P) {
    precise vec4 c;
    for (int r = 0; r < 4; ++r) {
        const vec4 m = u_clip_rows[r];
        precise float t = m.x * P.x;
        t = pc_fma(m.y, P.y, t);
        t = pc_fma(m.z, P.z, t);
        c[r] = pc_fma(m.w, P.w, t);
    }
    return c;
}

// True when the maxima so far keep every plane from culling (m >= 0, the far one >= far_limit:
// false for NaN).
bool pc_frustum_settled(const float m[6]) {
    bool settled = m[5] >= u_plane_depth.z;
    for (int q = 0; q < 5; ++q) settled = settled && m[q] >= 0.0;
    return settled;
}

// True when patch p, with displacement margin d when with_margins, lies outside one plane. With
// want_maxima, mx receives the six maxima over all points. Without, mx is undefined and the loop
// over the points stops once the verdict cannot change, which gives the same verdict: (a) once a
// near value was non-finite the patch is kept whatever follows; (b) once every plane's maximum is
// settled (pc_frustum_settled), a later point can only raise a maximum, unless one of its values
// is NaN, and with a finite matrix, near_w, far_w and margins a NaN value needs an infinite clip
// w or z (c = M P rounds to +-inf, never NaN, for finite P and M; a non-finite P makes every row
// non-finite), which makes that point's near value non-finite: (a) again. A non-finite matrix,
// near_w, far_w or margin never stops early.
bool pc_frustum_culled(uint p, bool with_margins, float d, bool want_maxima, out float mx[6]) {
    precise float margin[6];
    precise float m[6];
    bool margins_finite = true;
    for (int q = 0; q < 6; ++q) {
        margin[q] = d * u_plane_normal_length[q >> 2][q & 3];
        margins_finite = margins_finite && !pc_non_finite(margin[q]);
        m[q] = uintBitsToFloat(0xFF800000u);  // -infinity
    }
    bool uniforms_finite = !pc_non_finite(u_plane_depth.x) && !pc_non_finite(u_plane_depth.y);
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) uniforms_finite = uniforms_finite && !pc_non_finite(u_clip_rows[r][c]);
    const bool may_stop = !want_maxima && uniforms_finite && (!with_margins || margins_finite);
    bool non_finite = false;
    for (uint k = 0u; k < PC_PATCH_POINT_COUNT; ++k) {
        const vec4 point = PC_PATCH_POINT(p, k);
        float v[6];
        pc_frustum_plane_values(pc_clip_point(point), v);
        for (int q = 0; q < 6; ++q) {
            precise float value = v[q];
            if (with_margins) value = pc_fma(margin[q], point.w, value);
            m[q] = m[q] > value ? m[q] : value;
            if (q == 4) non_finite = non_finite || pc_non_finite(value);
        }
        if (may_stop && (non_finite || pc_frustum_settled(m))) break;
    }
    for (int q = 0; q < 6; ++q) mx[q] = m[q];
    return pc_frustum_outside(m, non_finite);
}
