// shaders/frustum_test.h (GLSL only): the frustum decision of cull_frustum_scalar
// (include/patchcull/frustum.h) for one patch, shared by frustum.comp.glsl and
// occlusion.comp.glsl so that both passes make the same decisions.
//
// For each clip plane q with row r and margin c = fma(D, |r.xyz|, r.w),
// value_k = fma(c, W, fma(r.z, Z, fma(r.y, Y, r.x * X))) for control point k = (X, Y, Z, W); the
// patch is culled when the maximum over the 16 points is < 0 for some plane. `precise` keeps the
// compiler from contracting or reassociating; max is written as the CPU's `a > b ? a : b`; pc_fma
// is exactly rounded also on llvmpipe (exact_fma.h).
//
// The including shader declares, before including this file: exact_fma.h, the buffer
// control_points[] (kBindingControlPoints) and the names u_plane_rows (vec4[6], FrustumPlanes::rows)
// and u_plane_normal_length (vec4[2]: FrustumPlanes::normal_length[q] at [q >> 2][q & 3]), #defines
// onto its parameter block (pass_params.h).

// True when patch p with displacement margin d lies outside one plane; mx receives the six maxima.
bool pc_frustum_culled(uint p, float d, out float mx[6]) {
    precise float c[6];
    precise float m[6];
    for (int q = 0; q < 6; ++q) {
        c[q] = pc_fma(d, u_plane_normal_length[q >> 2][q & 3], u_plane_rows[q].w);
        m[q] = uintBitsToFloat(0xFF800000u);  // -infinity
    }
    for (uint k = 0u; k < 16u; ++k) {
        const vec4 point = control_points[16u * p + k];
        for (int q = 0; q < 6; ++q) {
            const vec4 r = u_plane_rows[q];
            precise float value = r.x * point.x;
            value = pc_fma(r.y, point.y, value);
            value = pc_fma(r.z, point.z, value);
            value = pc_fma(c[q], point.w, value);
            m[q] = m[q] > value ? m[q] : value;
        }
    }
    bool culled = false;
    for (int q = 0; q < 6; ++q) {
        culled = culled || m[q] < 0.0;
        mx[q] = m[q];
    }
    return culled;
}
