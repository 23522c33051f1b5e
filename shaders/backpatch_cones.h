// shaders/backpatch_cones.h (GLSL only; include after exact_fma.h and backpatch_exact.h): the
// GPU twin of src/core/cones_internal.h, operation by operation (backpatch_cones.comp.glsl,
// tcone and ncone). Every std::fma there is pc_fma here, sqrt and division are pc_sqrt and
// pc_div (correctly rounded, backpatch_exact.h), every other operation is one separately rounded
// float operation in the same order (all marked precise so the compiler neither fuses nor
// reorders them). The derivations and the error analysis behind the constants are in
// src/core/cones.cpp.
//
// Differences in form, not in values:
// - cone_of_vectors skips unused vectors with an explicit flag instead of the CPU's NaN trick
//   (min_like_simd(NaN, lo) = lo): the same lo, hi and cmin, without relying on NaN semantics of
//   the GPU's min/max.
// - A zero control vector is recognised from its bits (all three components +-0) rather than from
//   |v|^2 == 0: where the CPU's |v|^2 underflows to 0 but the vector is not zero (components below
//   ~2^-75), the CPU skips the vector and the GPU invalidates the cone (no cull). Where llvmpipe
//   flushes a subnormal |v|^2 to 0 (components in ~[2^-75, 2^-63)) the CPU invalidates the cone
//   and so does the GPU. So the GPU never skips a vector the CPU uses.

// Constants of cones_internal.h, as their float bits (tests/gl/backpatch_gpu_test.cpp checks
// them against the C++ values): GLSL compilers parse decimal literals through double, which can
// round differently from the C++ float literal. (Macros: uintBitsToFloat is not a constant
// expression in GLSL 4.50.)
#define kMinLen2 uintBitsToFloat(0x0DA24260u)          // 1e-30f
#define kMaxLen2 uintBitsToFloat(0x7149F2CAu)          // 1e30f
#define kCosSlack uintBitsToFloat(0x360637BDu)         // 2e-6f
#define kSinSlack uintBitsToFloat(0x368637BDu)         // 4e-6f
#define kNormalRoundoff uintBitsToFloat(0x368637BDu)   // 4e-6f
#define kRadiusScale uintBitsToFloat(0x3F800008u)      // 1 + 2^-20
#define kFacingSlack uintBitsToFloat(0x3727C5ACu)      // 1e-5f
#define kGregoryWidenScale uintBitsToFloat(0x3E63C71Cu) // 2 (1 + 2^-10) / 9

#define kPcInf uintBitsToFloat(0x7F800000u)

// u_zero: always 0.0, provided by the including shader as a member of its parameter block (a
// #define, pass_params.h: BackpatchConeParams::zero, DisplacedParams::zero; the host sets it).
// Sums start from this run-time zero, not from a literal, because Mesa folds `x + 0.0` into x even
// in precise code (the CPU's fma(a, b, +0) is +0 for a*b = -0; see backpatch_ptp.comp.glsl, where
// this was measured).

struct PcCone {
    vec3 axis;
    float cos_angle;
    float sin_angle;
    bool valid;
};

struct PcSphere {
    vec3 center;
    float radius;
};

bool pc_is_zero_vector(vec3 v) {
    return ((floatBitsToUint(v.x) | floatBitsToUint(v.y) | floatBitsToUint(v.z)) & 0x7FFFFFFFu) == 0u;
}

/// cone_of_vectors<n>(v, widen) of cones_internal.h for the first n of v (has_widen: widen used).
PcCone pc_cone_of_vectors(const int n, vec3 v[36], float widen[36], const bool has_widen) {
    vec3 h[36];
    float ratio[36];
    bool used[36];
    bool bad = false;
    precise vec3 lo = vec3(kPcInf);
    precise vec3 hi = vec3(-kPcInf);
    for (int k = 0; k < n; ++k) {
        precise float len2 = pc_dot3(v[k], v[k]);
        const bool nz = len2 >= kMinLen2 && len2 <= kMaxLen2;
        const bool zero_ok = pc_is_zero_vector(v[k]) && (!has_widen || widen[k] == 0.0);
        bad = bad || !(nz || zero_ok);
        used[k] = nz;
        h[k] = vec3(0.0);
        ratio[k] = 0.0;
        if (nz) {
            precise float inv = pc_div(1.0, pc_sqrt(len2));
            precise vec3 hk = vec3(v[k].x * inv, v[k].y * inv, v[k].z * inv);
            h[k] = hk;
            precise float rk = widen[k] * inv;
            ratio[k] = rk;
            lo = vec3(pc_min_like(hk.x, lo.x), pc_min_like(hk.y, lo.y), pc_min_like(hk.z, lo.z));
            hi = vec3(pc_max_like(hk.x, hi.x), pc_max_like(hk.y, hi.y), pc_max_like(hk.z, hi.z));
        }
    }
    precise vec3 s = vec3((lo.x + hi.x) * 0.5, (lo.y + hi.y) * 0.5, (lo.z + hi.z) * 0.5);
    precise float slen2 = pc_dot3(s, s);
    precise float sinv = slen2 >= kMinLen2 ? pc_div(1.0, pc_sqrt(slen2)) : 0.0;
    precise vec3 axis = vec3(s.x * sinv, s.y * sinv, s.z * sinv);
    precise float cmin = 1.0;
    for (int k = 0; k < n; ++k) {
        precise float dk = pc_dot3(axis, h[k]);
        if (has_widen) dk = dk - ratio[k];
        cmin = pc_min_like(cmin, used[k] ? dk : 1.0);
    }
    precise float c = cmin - kCosSlack;
    PcCone cone;
    cone.axis = axis;
    cone.cos_angle = c;
    cone.sin_angle = pc_sqrt(pc_fma(-c, c, 1.0));
    cone.valid = !bad && slen2 >= kMinLen2 && c > 0.0;
    return cone;
}

/// tangent_vectors of cones_internal.h: U[3b + a] = P(a+1, b) - P(a, b), V[4d + c] = P(c, d+1) - P(c, d).
void pc_tangent_vectors(vec4 P[16], out vec3 U[36], out vec3 V[36]) {
    for (int k = 0; k < 36; ++k) {
        U[k] = vec3(0.0);
        V[k] = vec3(0.0);
    }
    for (int b = 0; b < 4; ++b)
        for (int a = 0; a < 3; ++a) {
            const vec4 p0 = P[4 * b + a], p1 = P[4 * b + a + 1];
            precise vec3 u = vec3(p1.x - p0.x, p1.y - p0.y, p1.z - p0.z);
            U[3 * b + a] = u;
        }
    for (int d = 0; d < 3; ++d)
        for (int c = 0; c < 4; ++c) {
            const vec4 p0 = P[4 * d + c], p1 = P[4 * d + 4 + c];
            precise vec3 v = vec3(p1.x - p0.x, p1.y - p0.y, p1.z - p0.z);
            V[4 * d + c] = v;
        }
}

/// combine_cones of cones_internal.h (Sederberg & Meyers).
PcCone pc_combine_cones(PcCone t, PcCone b) {
    precise vec3 nrm = pc_cross3(t.axis, b.axis);
    precise float sin2 = pc_dot3(nrm, nrm);
    precise float ac = abs(pc_dot3(t.axis, b.axis));
    const float st = t.sin_angle, sb = b.sin_angle;
    precise float q = st * st;
    precise float f = (ac + ac) * st;
    q = pc_fma(f, sb, q);
    q = pc_fma(sb, sb, q);
    precise float sn = pc_sqrt(pc_div(q, sin2)) + kSinSlack;
    precise float inv = pc_div(1.0, pc_sqrt(sin2));
    PcCone cone;
    precise vec3 axis = vec3(nrm.x * inv, nrm.y * inv, nrm.z * inv);
    cone.axis = axis;
    cone.sin_angle = sn;
    cone.cos_angle = pc_sqrt(pc_fma(-sn, sn, 1.0));
    cone.valid = t.valid && b.valid && sin2 >= kMinLen2 && sn < 1.0;
    return cone;
}

/// tangent_cone_polynomial (TCONE).
PcCone pc_tangent_cone(vec4 P[16]) {
    vec3 U[36], V[36];
    pc_tangent_vectors(P, U, V);
    float no_widen[36];
    for (int k = 0; k < 36; ++k) no_widen[k] = 0.0;
    const PcCone t = pc_cone_of_vectors(12, U, no_widen, false);
    const PcCone b = pc_cone_of_vectors(12, V, no_widen, false);
    return pc_combine_cones(t, b);
}

/// gregory_direction_cone of cones_internal.h over a Gregory patch's 20 points: the 22 net
/// differences and the 4 blend differences of the s direction (s_direction) or the t direction,
/// as its kGregoryNet* / kGregoryBlend* tables ({to, from} pairs, flattened).
PcCone pc_gregory_direction_cone(vec4 G[20], const bool s_direction) {
    const int net_s[44] = int[44](1, 0, 7, 1, 5, 7, 17, 15, 11, 17, 10, 11, 3, 2, 4, 2, 8, 3, 8, 4, 9, 3, 9, 4, 6, 8,
                                  6, 9, 18, 16, 19, 16, 13, 18, 13, 19, 14, 18, 14, 19, 12, 13, 12, 14);
    const int net_t[44] = int[44](2, 0, 16, 2, 15, 16, 6, 5, 12, 6, 10, 12, 3, 1, 4, 1, 18, 3, 18, 4, 19, 3, 19, 4,
                                  17, 18, 17, 19, 8, 7, 9, 7, 13, 8, 13, 9, 14, 8, 14, 9, 11, 13, 11, 14);
    const int blend_s[8] = int[8](3, 4, 8, 9, 14, 13, 19, 18);
    const int blend_t[8] = int[8](4, 3, 8, 9, 13, 14, 19, 18);
    precise float moved = 0.0;
    for (int k = 0; k < 4; ++k) {
        const int to = s_direction ? blend_s[2 * k] : blend_t[2 * k];
        const int from = s_direction ? blend_s[2 * k + 1] : blend_t[2 * k + 1];
        precise vec3 d = vec3(G[to].x - G[from].x, G[to].y - G[from].y, G[to].z - G[from].z);
        moved = moved + pc_sqrt(pc_dot3(d, d));
    }
    precise float widen_each = moved * kGregoryWidenScale;
    vec3 v[36];
    float widen[36];
    for (int k = 0; k < 36; ++k) {
        v[k] = vec3(0.0);
        widen[k] = 0.0;
    }
    for (int k = 0; k < 22; ++k) {
        const int to = s_direction ? net_s[2 * k] : net_t[2 * k];
        const int from = s_direction ? net_s[2 * k + 1] : net_t[2 * k + 1];
        precise vec3 d = vec3(G[to].x - G[from].x, G[to].y - G[from].y, G[to].z - G[from].z);
        v[k] = d;
        widen[k] = widen_each;
    }
    return pc_cone_of_vectors(22, v, widen, true);
}

/// tangent_cone_gregory of cones_internal.h.
PcCone pc_tangent_cone_gregory(vec4 G[20]) {
    return pc_combine_cones(pc_gregory_direction_cone(G, true), pc_gregory_direction_cone(G, false));
}

/// sphere_of_gregory_points of cones_internal.h (sphere_of over the 20 points).
PcSphere pc_sphere_of_gregory_points(vec4 G[20]) {
    precise vec3 lo = G[0].xyz;
    precise vec3 hi = lo;
    for (int k = 1; k < 20; ++k) {
        const vec3 q = G[k].xyz;
        lo = vec3(pc_min_like(lo.x, q.x), pc_min_like(lo.y, q.y), pc_min_like(lo.z, q.z));
        hi = vec3(pc_max_like(hi.x, q.x), pc_max_like(hi.y, q.y), pc_max_like(hi.z, q.z));
    }
    precise vec3 c = vec3((lo.x + hi.x) * 0.5, (lo.y + hi.y) * 0.5, (lo.z + hi.z) * 0.5);
    precise float r2 = 0.0;
    for (int k = 0; k < 20; ++k) {
        const vec3 q = G[k].xyz;
        precise vec3 d = vec3(q.x - c.x, q.y - c.y, q.z - c.z);
        r2 = pc_max_like(r2, pc_dot3(d, d));
    }
    PcSphere sphere;
    sphere.center = c;
    precise float r = pc_sqrt(r2) * kRadiusScale;
    sphere.radius = r;
    return sphere;
}

bool pc_is_polynomial_gregory(vec4 G[20]) {
    bool all_one = true;
    for (int k = 0; k < 20; ++k) all_one = all_one && G[k].w == 1.0;
    return all_one;
}

/// normal_patch_vectors + normal_cone_polynomial (NCONE).
PcCone pc_normal_cone(vec4 P[16]) {
    const float kC2[3] = float[3](1.0, 2.0, 1.0);
    const float kC3[4] = float[4](1.0, 3.0, 3.0, 1.0);
    vec3 U[36], V[36];
    pc_tangent_vectors(P, U, V);
    float lu[12], lv[12];
    for (int b = 0; b < 4; ++b)
        for (int a = 0; a < 3; ++a) {
            precise float w = kC2[a] * kC3[b];
            const vec3 u0 = U[3 * b + a];
            precise vec3 u = vec3(u0.x * w, u0.y * w, u0.z * w);
            U[3 * b + a] = u;
            precise float l = (abs(u.x) + abs(u.y)) + abs(u.z);
            lu[3 * b + a] = l;
        }
    for (int d = 0; d < 3; ++d)
        for (int c = 0; c < 4; ++c) {
            precise float w = kC3[c] * kC2[d];
            const vec3 v0 = V[4 * d + c];
            precise vec3 v = vec3(v0.x * w, v0.y * w, v0.z * w);
            V[4 * d + c] = v;
            precise float l = (abs(v.x) + abs(v.y)) + abs(v.z);
            lv[4 * d + c] = l;
        }
    vec3 nv[36];
    float widen[36];
    for (int j = 0; j < 6; ++j)
        for (int i = 0; i < 6; ++i) {
            precise float nx = u_zero, ny = u_zero, nz = u_zero, m = u_zero;
            const int a0 = i > 3 ? i - 3 : 0, a1 = i < 2 ? i : 2;
            const int b0 = j > 2 ? j - 2 : 0, b1 = j < 3 ? j : 3;
            for (int a = a0; a <= a1; ++a)
                for (int b = b0; b <= b1; ++b) {
                    const vec3 u = U[3 * b + a], v = V[4 * (j - b) + (i - a)];
                    nx = pc_fma(u.y, v.z, nx);
                    nx = pc_fma(-u.z, v.y, nx);
                    ny = pc_fma(u.z, v.x, ny);
                    ny = pc_fma(-u.x, v.z, ny);
                    nz = pc_fma(u.x, v.y, nz);
                    nz = pc_fma(-u.y, v.x, nz);
                    m = pc_fma(lu[3 * b + a], lv[4 * (j - b) + (i - a)], m);
                }
            nv[6 * j + i] = vec3(nx, ny, nz);
            precise float wd = (2.0 * kNormalRoundoff) * m;  // 2 * kNormalRoundoff: exact (power of two)
            widen[6 * j + i] = wd;
        }
    return pc_cone_of_vectors(36, nv, widen, true);
}

/// sphere_of_points<false> (polynomial patches: the points are the xyz of the control points).
PcSphere pc_sphere_of_points(vec4 P[16]) {
    precise vec3 lo = P[0].xyz;
    precise vec3 hi = lo;
    for (int k = 1; k < 16; ++k) {
        const vec3 q = P[k].xyz;
        lo = vec3(pc_min_like(lo.x, q.x), pc_min_like(lo.y, q.y), pc_min_like(lo.z, q.z));
        hi = vec3(pc_max_like(hi.x, q.x), pc_max_like(hi.y, q.y), pc_max_like(hi.z, q.z));
    }
    precise vec3 c = vec3((lo.x + hi.x) * 0.5, (lo.y + hi.y) * 0.5, (lo.z + hi.z) * 0.5);
    precise float r2 = 0.0;
    for (int k = 0; k < 16; ++k) {
        const vec3 q = P[k].xyz;
        precise vec3 d = vec3(q.x - c.x, q.y - c.y, q.z - c.z);
        r2 = pc_max_like(r2, pc_dot3(d, d));
    }
    PcSphere sphere;
    sphere.center = c;
    precise float r = pc_sqrt(r2) * kRadiusScale;
    sphere.radius = r;
    return sphere;
}

/// back_facing of cones_internal.h: the perspective back-facing test.
bool pc_back_facing(PcCone cone, PcSphere sphere, vec3 eye) {
    precise vec3 d = vec3(eye.x - sphere.center.x, eye.y - sphere.center.y, eye.z - sphere.center.z);
    precise float len = pc_sqrt(pc_dot3(d, d));
    precise float sb = pc_div(sphere.radius, len);
    precise float cb = pc_sqrt(pc_fma(-sb, sb, 1.0));
    precise float cs = cone.cos_angle * sb;
    precise float ss = cone.sin_angle * sb;
    precise float sin_ab = pc_fma(cone.sin_angle, cb, cs);
    precise float cos_ab = pc_fma(cone.cos_angle, cb, -ss);
    precise float ad = pc_dot3(cone.axis, d);
    precise float limit = len * (sin_ab + kFacingSlack);
    return cone.valid && len > sphere.radius && cos_ab >= 0.0 && ad <= -limit;
}

bool pc_is_polynomial(vec4 P[16]) {
    bool all_one = true;
    for (int k = 0; k < 16; ++k) all_one = all_one && P[k].w == 1.0;
    return all_one;
}
