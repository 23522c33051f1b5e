// shaders/displaced_bounds.h (GLSL only; include after shared.h, exact_fma.h, backpatch_exact.h
// and backpatch_cones.h): the GPU twin of src/core/displaced_bounds.cpp, the
// bounds of displaced patches of include/patchcull/core/displaced_bounds.h (Niessner & Loop §4.2: the
// camera-aligned frustum `caf`; Munkberg et al.'s object-oriented box `oobb`; cones full / acon /
// con) and their frustum and Hi-Z decisions. Every step is written in the CPU's order with the
// CPU's operations: std::fma <-> pc_fma, IEEE / and sqrt <-> pc_div, pc_sqrt (correctly rounded,
// backpatch_exact.h), min_f / max_f <-> pc_min_like / pc_max_like (`a < b ? a : b`), dot3 / cross3
// <-> pc_dot3 / pc_cross3, math.h's dot / normalize (plain products and sums, no fma: the CPU is
// built with -ffp-contract=off) <-> pc_plain_dot / pc_normalize; all intermediates `precise`, so
// the compiler neither fuses nor reorders. The cones are backpatch_cones.h's, the operation-by-
// operation mirror of src/core/cones_internal.h (tests/gl/backpatch_gpu_test.cpp).
//
// Differences in form only:
// - all_finite (the CPU adds v * 0 and compares with 0) is an exponent-bits test here: Mesa may
//   fold x * 0.0 to 0.0, and the bits test is exactly "finite".
// - The float constants of displaced_bounds.h (kDisplacedDeltaSlack, kDisplacedExtScale,
//   kDisplacedFramePad, kDisplacedDepthSafety) are uniforms set from the C++ constants, so the two
//   sides cannot drift apart (and no decimal literal is parsed by the GLSL compiler).
//
// The including shader provides the names used here (displaced.comp.glsl: #defines onto its
// parameter block, pass_params.h's DisplacedParams): the DisplacedCullView (u_object_to_view,
// u_abs_row_z (4 values), u_axis_unit (vec4s, xyz used), u_axis_length (4 values, 3 used), u_proj =
// (P00, P02, P11, P12), u_proj_z = (P22, P23, key_near, key_far) of the depth-key projection, u_view_planes) and the constants (u_delta_slack, u_ext_scale,
// u_frame_pad, u_depth_safety).

// DisplacedBoundStatus of displaced_bounds.h.
const uint kPcBoundProjected = 0u;
const uint kPcBoundOutsidePlane = 1u;
const uint kPcBoundUnprojectable = 2u;
const uint kPcBoundInvalid = 3u;

// HiZDecision of hiz.h.
const uint kPcHiZVisible = 0u;
const uint kPcHiZFrustumCulled = 1u;
const uint kPcHiZOccluded = 2u;

struct PcDisplacedBound {
    float ndc_xmin, ndc_xmax, ndc_ymin, ndc_ymax;
    float depth_near, depth_far;
    uint status;
};

PcDisplacedBound pc_invalid_bound() {
    // DisplacedBound{}: the default values, status invalid.
    return PcDisplacedBound(-1.0, 1.0, -1.0, 1.0, 0.0, 1.0, kPcBoundInvalid);
}

PcDisplacedBound pc_unprojectable(bool outside_plane) {
    PcDisplacedBound b = pc_invalid_bound();
    b.status = outside_plane ? kPcBoundOutsidePlane : kPcBoundUnprojectable;
    return b;
}

bool pc_finite(float x) {
    return (floatBitsToUint(x) & 0x7F800000u) != 0x7F800000u;
}

/// math.h's dot (x*x + y*y) + z*z, separately rounded.
float pc_plain_dot(vec3 a, vec3 b) {
    precise float xx = a.x * b.x;
    precise float yy = a.y * b.y;
    precise float zz = a.z * b.z;
    precise float r = (xx + yy) + zz;
    return r;
}

/// math.h's normalize: a * (1 / |a|), or 0 when |a| is 0.
vec3 pc_normalize(vec3 a) {
    precise float len = pc_sqrt(pc_plain_dot(a, a));
    if (!(len > 0.0)) return vec3(0.0);
    precise float inv = pc_div(1.0, len);
    precise vec3 r = vec3(a.x * inv, a.y * inv, a.z * inv);
    return r;
}

/// extension_along: the range [-minus, plus] of r.d for the displacement d = D n, r a unit
/// direction of length `len`. Returns vec2(plus, minus).
vec2 pc_extension_along(vec3 r, float len, PcCone cone, float d_min, float d_max, float radius) {
    precise float scale = len * u_ext_scale;
    if (!cone.valid) {
        precise float e = radius * scale;
        return vec2(e, e);
    }
    precise float c = pc_dot3(r, cone.axis);
    precise vec3 x = pc_cross3(r, cone.axis);
    precise float s = pc_sqrt(pc_dot3(x, x));
    const float ca = cone.cos_angle, sa = cone.sin_angle;
    precise float sin_term = s * sa;
    precise float dp_raw = pc_fma(c, ca, sin_term) + u_delta_slack;
    precise float nc = -c;
    precise float dm_raw = pc_fma(nc, ca, sin_term) + u_delta_slack;
    precise float delta_plus = c >= ca ? 1.0 : pc_min_like(1.0, dp_raw);
    precise float delta_minus = nc >= ca ? 1.0 : pc_min_like(1.0, dm_raw);
    precise float neg_min = -d_min;
    precise float plus = pc_max_like(d_max * delta_plus, neg_min * delta_minus) * scale;
    precise float minus = pc_max_like(d_max * delta_minus, neg_min * delta_plus) * scale;
    return vec2(plus, minus);
}

/// to_view: (x, y, t = -z, magnitude of t's terms) of an object-space point.
vec4 pc_to_view(vec3 p) {
    const mat4 v = u_object_to_view;  // v[c][r] = V(r, c)
    precise float x = pc_fma(v[2][0], p.z, pc_fma(v[1][0], p.y, v[0][0] * p.x)) + v[3][0];
    precise float y = pc_fma(v[2][1], p.z, pc_fma(v[1][1], p.y, v[0][1] * p.x)) + v[3][1];
    precise float z = pc_fma(v[2][2], p.z, pc_fma(v[1][2], p.y, v[0][2] * p.x)) + v[3][2];
    precise float t = -z;
    precise float terms = pc_fma(u_abs_row_z[2], abs(p.z), pc_fma(u_abs_row_z[1], abs(p.y), u_abs_row_z[0] * abs(p.x))) +
                          u_abs_row_z[3];
    return vec4(x, y, t, terms);
}

/// Step 5 (to_screen): NDC rectangle and depths.
PcDisplacedBound pc_to_screen(float x_min, float x_max, float y_min, float y_max, float t_front, float t_back) {
    precise float ax = pc_fma(u_proj.x, x_min, -u_proj.y);
    precise float bx = pc_fma(u_proj.x, x_max, -u_proj.y);
    precise float ay = pc_fma(u_proj.z, y_min, -u_proj.w);
    precise float by = pc_fma(u_proj.z, y_max, -u_proj.w);
    const float df = pc_div(pc_fma(-u_proj_z.x, t_front, u_proj_z.y), t_front);
    const float db = pc_div(pc_fma(-u_proj_z.x, t_back, u_proj_z.y), t_back);
    PcDisplacedBound b;
    b.ndc_xmin = pc_min_like(ax, bx);
    b.ndc_xmax = pc_max_like(ax, bx);
    b.ndc_ymin = pc_min_like(ay, by);
    b.ndc_ymax = pc_max_like(ay, by);
    b.depth_near = pc_min_like(df, db);
    b.depth_far = pc_max_like(df, db);
    const bool finite = pc_finite(b.ndc_xmin) && pc_finite(b.ndc_xmax) && pc_finite(b.ndc_ymin) &&
                        pc_finite(b.ndc_ymax) && pc_finite(b.depth_near) && pc_finite(b.depth_far);
    b.status = finite ? kPcBoundProjected : kPcBoundInvalid;
    return b;
}

/// The value of a view-space clip plane row r at a view point (x, y, t): fma(r.z, -t, fma(r.y, y, r.x x)) + r.w.
float pc_plane_value(vec4 r, vec4 q) {
    precise float nt = -q.z;
    precise float v = pc_fma(r.z, nt, pc_fma(r.y, q.y, r.x * q.x)) + r.w;
    return v;
}

// ---- caf ------------------------------------------------------------------------------------------

PcDisplacedBound pc_caf_bound(vec3 p[16], PcCone cone, float d_min, float d_max, float radius) {
    // Step 2: extensions along the view axes (rows of L): ext[i] = (plus, minus).
    vec2 ext[3];
    for (int i = 0; i < 3; ++i) ext[i] = pc_extension_along(u_axis_unit[i].xyz, u_axis_length[i], cone, d_min, d_max, radius);
    const float t_near_ext = ext[2].x, t_far_ext = ext[2].y;

    // Steps 1 and 3.
    vec4 q[16];
    precise float t_min = 0.0, t_max = 0.0, terms = 0.0;
    for (int k = 0; k < 16; ++k) {
        q[k] = pc_to_view(p[k]);
        t_min = k == 0 ? q[k].z : pc_min_like(t_min, q[k].z);
        t_max = k == 0 ? q[k].z : pc_max_like(t_max, q[k].z);
        terms = k == 0 ? q[k].w : pc_max_like(terms, q[k].w);
    }
    precise float t_front = t_min - t_near_ext;
    precise float t_back = t_max + t_far_ext;
    precise float margin = u_depth_safety * (terms + t_near_ext);
    if (!(t_front > margin)) {
        // Not projectable: homogeneous plane test of the 16 boxes.
        bool outside = false;
        for (int plane = 0; plane < 6; ++plane) {
            const vec4 r = u_view_planes[plane];
            precise float mx = pc_max_like(r.x * ext[0].x, -r.x * ext[0].y);
            precise float my = pc_max_like(r.y * ext[1].x, -r.y * ext[1].y);
            precise float mz = pc_max_like(r.z * ext[2].x, -r.z * ext[2].y);
            precise float box_margin = (mx + my) + mz;
            precise float best = 0.0;
            for (int k = 0; k < 16; ++k) {
                const float value = pc_plane_value(r, q[k]);
                best = k == 0 ? value : pc_max_like(best, value);
            }
            precise float total = best + box_margin;
            outside = outside || (total < 0.0);
        }
        if (!(pc_finite(t_front) && pc_finite(t_back) && pc_finite(margin))) return pc_invalid_bound();
        return pc_unprojectable(outside);
    }
    // Step 4: extremes of x/t and y/t over each box (at its corners).
    precise float x_min = 0.0, x_max = 0.0, y_min = 0.0, y_max = 0.0;
    for (int k = 0; k < 16; ++k) {
        precise float t_lo = q[k].z - t_near_ext;
        precise float t_hi = q[k].z + t_far_ext;
        precise float x_lo = q[k].x - ext[0].y;
        precise float x_hi = q[k].x + ext[0].x;
        precise float y_lo = q[k].y - ext[1].y;
        precise float y_hi = q[k].y + ext[1].x;
        const float bx_lo = pc_div(x_lo, x_lo >= 0.0 ? t_hi : t_lo);
        const float bx_hi = pc_div(x_hi, x_hi >= 0.0 ? t_lo : t_hi);
        const float by_lo = pc_div(y_lo, y_lo >= 0.0 ? t_hi : t_lo);
        const float by_hi = pc_div(y_hi, y_hi >= 0.0 ? t_lo : t_hi);
        x_min = k == 0 ? bx_lo : pc_min_like(x_min, bx_lo);
        x_max = k == 0 ? bx_hi : pc_max_like(x_max, bx_hi);
        y_min = k == 0 ? by_lo : pc_min_like(y_min, by_lo);
        y_max = k == 0 ? by_hi : pc_max_like(y_max, by_hi);
    }
    return pc_to_screen(x_min, x_max, y_min, y_max, t_front, t_back);
}

// ---- oobb -------------------------------------------------------------------------------------------

/// oobb_frame: e[0] = e_u, e[1] = e_v, e[2] = e_n.
void pc_oobb_frame(vec3 p[16], out vec3 e[3]) {
    precise vec3 diag0 = vec3(p[3].x - p[12].x, p[3].y - p[12].y, p[3].z - p[12].z);
    precise vec3 diag1 = vec3(p[15].x - p[0].x, p[15].y - p[0].y, p[15].z - p[0].z);
    vec3 n = pc_normalize(pc_cross3(diag0, diag1));
    if (pc_dot3(n, n) == 0.0) n = vec3(0.0, 0.0, 1.0);
    precise vec3 s0 = vec3(p[3].x + p[15].x, p[3].y + p[15].y, p[3].z + p[15].z);
    precise vec3 s1 = vec3(p[0].x + p[12].x, p[0].y + p[12].y, p[0].z + p[12].z);
    precise vec3 u0 = vec3(s0.x - s1.x, s0.y - s1.y, s0.z - s1.z);
    precise float un = pc_dot3(u0, n);
    precise vec3 nun = vec3(n.x * un, n.y * un, n.z * un);
    precise vec3 u1 = vec3(u0.x - nun.x, u0.y - nun.y, u0.z - nun.z);
    vec3 u = pc_normalize(u1);
    if (pc_dot3(u, u) == 0.0) {
        // 0.9f (bits: the GLSL compiler parses decimal literals through double).
        const vec3 helper = abs(n.x) < uintBitsToFloat(0x3F666666u) ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
        u = pc_normalize(pc_cross3(n, helper));
    }
    e[0] = u;
    e[1] = pc_cross3(n, u);
    e[2] = n;
}

PcDisplacedBound pc_oobb_bound(vec3 p[16], PcCone cone, float d_min, float d_max, float radius) {
    vec3 e[3];
    pc_oobb_frame(p, e);
    const vec3 origin = p[0];
    precise float lo[3], hi[3];
    for (int i = 0; i < 3; ++i) {
        lo[i] = 0.0;
        hi[i] = 0.0;
    }
    for (int k = 0; k < 16; ++k) {
        precise vec3 d = vec3(p[k].x - origin.x, p[k].y - origin.y, p[k].z - origin.z);
        for (int i = 0; i < 3; ++i) {
            const float c = pc_dot3(e[i], d);
            lo[i] = k == 0 ? c : pc_min_like(lo[i], c);
            hi[i] = k == 0 ? c : pc_max_like(hi[i], c);
        }
    }
    precise float size = 0.0;
    for (int i = 0; i < 3; ++i) {
        const vec2 x = pc_extension_along(e[i], 1.0, cone, d_min, d_max, radius);
        lo[i] = lo[i] - x.y;
        hi[i] = hi[i] + x.x;
        size = pc_max_like(size, pc_max_like(abs(lo[i]), abs(hi[i])));
    }
    precise float pad = u_frame_pad * size;
    for (int i = 0; i < 3; ++i) {
        lo[i] = lo[i] - pad;
        hi[i] = hi[i] + pad;
    }
    vec4 corner[8];
    precise float t_min = 0.0, t_max = 0.0, terms = 0.0;
    for (int c = 0; c < 8; ++c) {
        const float a = (c & 1) != 0 ? hi[0] : lo[0];
        const float b = (c & 2) != 0 ? hi[1] : lo[1];
        const float g = (c & 4) != 0 ? hi[2] : lo[2];
        precise vec3 x = vec3(origin.x + pc_fma(e[2].x, g, pc_fma(e[1].x, b, e[0].x * a)),
                              origin.y + pc_fma(e[2].y, g, pc_fma(e[1].y, b, e[0].y * a)),
                              origin.z + pc_fma(e[2].z, g, pc_fma(e[1].z, b, e[0].z * a)));
        corner[c] = pc_to_view(x);
        t_min = c == 0 ? corner[c].z : pc_min_like(t_min, corner[c].z);
        t_max = c == 0 ? corner[c].z : pc_max_like(t_max, corner[c].z);
        terms = c == 0 ? corner[c].w : pc_max_like(terms, corner[c].w);
    }
    precise float margin = u_depth_safety * terms;
    if (!(t_min > margin)) {
        bool outside = false;
        for (int plane = 0; plane < 6; ++plane) {
            const vec4 r = u_view_planes[plane];
            precise float best = 0.0;
            for (int c = 0; c < 8; ++c) {
                const float value = pc_plane_value(r, corner[c]);
                best = c == 0 ? value : pc_max_like(best, value);
            }
            outside = outside || best < 0.0;
        }
        if (!(pc_finite(t_min) && pc_finite(t_max))) return pc_invalid_bound();
        return pc_unprojectable(outside);
    }
    precise float x_min = 0.0, x_max = 0.0, y_min = 0.0, y_max = 0.0;
    for (int c = 0; c < 8; ++c) {
        const float x = pc_div(corner[c].x, corner[c].z);
        const float y = pc_div(corner[c].y, corner[c].z);
        x_min = c == 0 ? x : pc_min_like(x_min, x);
        x_max = c == 0 ? x : pc_max_like(x_max, x);
        y_min = c == 0 ? y : pc_min_like(y_min, y);
        y_max = c == 0 ? y : pc_max_like(y_max, y);
    }
    return pc_to_screen(x_min, x_max, y_min, y_max, t_min, t_max);
}

// ---- the patch -------------------------------------------------------------------------------------

/// bound_with_cone: validation, Cartesian points, the range widened to hold 0, then caf or oobb.
PcDisplacedBound pc_displaced_bound_with_cone(vec4 P[16], vec2 range, PcCone cone, uint bound_kind) {
    bool finite = pc_finite(range.x) && pc_finite(range.y);
    for (int k = 0; k < 16; ++k)
        finite = finite && pc_finite(P[k].x) && pc_finite(P[k].y) && pc_finite(P[k].z) && pc_finite(P[k].w);
    if (!finite) return pc_invalid_bound();
    vec3 p[16];
    bool positive = true;
    bool points_finite = true;
    for (int k = 0; k < 16; ++k) {
        const vec4 c = P[k];
        positive = positive && c.w > 0.0;
        p[k] = c.w == 1.0 ? c.xyz : vec3(pc_div(c.x, c.w), pc_div(c.y, c.w), pc_div(c.z, c.w));
        points_finite = points_finite && pc_finite(p[k].x) && pc_finite(p[k].y) && pc_finite(p[k].z);
    }
    if (!positive || !points_finite) return pc_invalid_bound();
    const float d_min = pc_min_like(range.x, 0.0), d_max = pc_max_like(range.y, 0.0);
    const float radius = pc_max_like(d_max, -d_min);
    PcCone used = cone;
    if (!(cone.valid && pc_finite(cone.axis.x) && pc_finite(cone.axis.y) && pc_finite(cone.axis.z))) used.valid = false;
#ifdef PC_DISPLACED_BOUND
    // One program per bound kind (llvmpipe would compute both bounds for a uniform choice).
    return PC_DISPLACED_BOUND == kDisplacedBoundCaf ? pc_caf_bound(p, used, d_min, d_max, radius)
                                                    : pc_oobb_bound(p, used, d_min, d_max, radius);
#else
    return bound_kind == kDisplacedBoundCaf ? pc_caf_bound(p, used, d_min, d_max, radius)
                                            : pc_oobb_bound(p, used, d_min, d_max, radius);
#endif
}

/// outside_frustum of a bound.
bool pc_bound_outside_frustum(PcDisplacedBound b) {
    if (b.status == kPcBoundOutsidePlane) return true;
    if (b.status != kPcBoundProjected) return false;
    return b.ndc_xmax < -1.0 || b.ndc_xmin > 1.0 || b.ndc_ymax < -1.0 || b.ndc_ymin > 1.0 ||
           b.depth_near > u_proj_z.w || b.depth_far < u_proj_z.z;
}
