// shaders/patch_eval.h: evaluation of a bicubic (rational) Bezier patch, shared by the TES (the
// tessellated points) and the patch fragment shader (the front-facing test of one-sided
// surfaces), so both evaluate the same surface with the same operations. Control point (i, j)
// (i along u) is cp[4*j + i] (patch.h's order); weights are > 0.

void bernstein(float t, out vec4 b, out vec4 db) {
    const float s = 1.0 - t;
    b = vec4(s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t);
    db = vec4(-3.0 * s * s, 3.0 * s * s - 6.0 * t * s, 6.0 * t * s - 3.0 * t * t, 3.0 * t * t);
}

// Cartesian position p and first derivatives pu, pv at (u, v) (quotient rule for rational
// patches); bu, bv are the cubic Bernstein values at u and v (reused by the TES).
void evaluate_patch(const vec4 cp[16], float u, float v, out vec3 p, out vec3 pu, out vec3 pv, out vec4 bu,
                    out vec4 bv) {
    vec4 dbu, dbv;
    bernstein(u, bu, dbu);
    bernstein(v, bv, dbv);
    vec4 h = vec4(0.0), hu = vec4(0.0), hv = vec4(0.0);
    for (int j = 0; j < 4; ++j) {
        vec4 row = vec4(0.0), row_du = vec4(0.0);
        for (int i = 0; i < 4; ++i) {
            row += bu[i] * cp[4 * j + i];
            row_du += dbu[i] * cp[4 * j + i];
        }
        h += bv[j] * row;
        hu += bv[j] * row_du;
        hv += dbv[j] * row;
    }
    p = h.xyz / h.w;
    pu = (hu.xyz - p * hu.w) / h.w;
    pv = (hv.xyz - p * hv.w) / h.w;
}
