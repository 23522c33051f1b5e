// shaders/backpatch_exact.h (GLSL only; include after exact_fma.h): the correctly rounded float
// operations the back-patch compute shaders need beyond pc_fma, so that their values equal the
// CPU kernels' (src/core/cones_internal.h: IEEE sqrt and division, std::fma) bit for bit.
//
// GLSL only promises correctly rounded +, - and * for floats (GLSL 4.50 §4.7.1); division is
// 2.5 ULP and sqrt is "inherited from inversesqrt", and a driver may implement a / b as
// a * (1 / b) (two roundings). pc_div and pc_sqrt therefore take the driver's value only as a
// guess and correct it to the correctly rounded result with exact double-precision midpoint tests:
//   division, q > 0 a guess of A / B (magnitudes): the correctly rounded quotient is the float m
//   with (m- + m) / 2 < A / B < (m + m+) / 2, m-/m+ its neighbours (A / B is never exactly a
//   midpoint of two floats). The midpoints have 25 significant bits, so mid * B (25 x 24 bits)
//   is exact in double and A < mid * B is an exact comparison. Three steps of one ulp each cover
//   the 2.5 ULP GLSL allows.
//   sqrt: likewise with x < mid * mid (mid^2 has 50 bits: exact in double).
// On llvmpipe a / b and sqrt are already correctly rounded (LLVM's fdiv and sqrt), so the
// correction never moves there, yet costs its full length: llvmpipe runs both sides of every
// branch. With PATCHCULL_NATIVE_DIV_SQRT defined (the GL passes define it on a software rasterizer
// whose / and sqrt pass the start-up check, gl_passes.h) pc_div and pc_sqrt are the driver's own.
// The probe's *_from modes test the correction from perturbed guesses either way.
// Exact as long as double +, * are correctly rounded (IEEE; llvmpipe and the GPUs we know). Not
// handled (values returned as the driver computes them): zero, negative, infinite or NaN
// operands and results, and subnormal results (llvmpipe flushes float subnormals to zero, the
// CPU does not; the kernels' thresholds, e.g. |v|^2 >= 1e-30, keep the decisions away from them).
// min/max are written `a < b ? a : b` as cones_internal.h's min_like_simd (inputs are never NaN
// here: unused vectors are skipped explicitly instead of through NaN, see backpatch_cones.h).

#define kPcFloatMax uintBitsToFloat(0x7F7FFFFFu)  // FLT_MAX

float pc_next_up(float x) { return uintBitsToFloat(floatBitsToUint(x) + 1u); }    // x > 0 finite
float pc_next_down(float x) { return uintBitsToFloat(floatBitsToUint(x) - 1u); }  // x > 0 finite

/// a / b correctly rounded from a guess q within 3 ulps of it (used as is when q or an operand
/// is zero, infinite or NaN).
float pc_div_from(float a, float b, float q) {
    const float m0 = abs(q);
    if (!(m0 > 0.0 && m0 <= kPcFloatMax) || !(abs(a) <= kPcFloatMax) || !(abs(b) <= kPcFloatMax)) return q;
    precise double A = abs(double(a));
    precise double B = abs(double(b));
    float m = m0;
    for (int i = 0; i < 3; ++i) {
        precise double md = double(m);
        precise double lo = (double(pc_next_down(m)) + md) * 0.5lf;
        precise double hi = (md + double(pc_next_up(m))) * 0.5lf;
        precise double lo_b = lo * B;
        precise double hi_b = hi * B;
        if (A < lo_b) m = pc_next_down(m);
        else if (A > hi_b) m = pc_next_up(m);
    }
    return ((a < 0.0) != (b < 0.0)) ? -m : m;
}


/// sqrt(x) correctly rounded from a guess s within 3 ulps of it (used as is when x or s is zero,
/// negative, infinite or NaN).
float pc_sqrt_from(float x, float s) {
    if (!(x > 0.0 && x <= kPcFloatMax) || !(s > 0.0 && s <= kPcFloatMax)) return s;
    precise double xd = double(x);
    for (int i = 0; i < 3; ++i) {
        precise double sd = double(s);
        precise double lo = (double(pc_next_down(s)) + sd) * 0.5lf;
        precise double hi = (sd + double(pc_next_up(s))) * 0.5lf;
        precise double lo2 = lo * lo;
        precise double hi2 = hi * hi;
        if (xd < lo2) s = pc_next_down(s);
        else if (xd > hi2) s = pc_next_up(s);
    }
    return s;
}

/// a / b and sqrt(x) correctly rounded (std's a / b and std::sqrt for normal operands and
/// results): the driver's own where PATCHCULL_NATIVE_DIV_SQRT says it rounds them correctly,
/// else corrected from its value.
#ifdef PATCHCULL_NATIVE_DIV_SQRT
float pc_div(float a, float b) {
    precise float q = a / b;
    return q;
}
float pc_sqrt(float x) {
    precise float s = sqrt(x);
    return s;
}
#else
float pc_div(float a, float b) {
    precise float q = a / b;
    return pc_div_from(a, b, q);
}
float pc_sqrt(float x) {
    precise float s = sqrt(x);
    return pc_sqrt_from(x, s);
}
#endif

float pc_min_like(float a, float b) {
    precise float r = a < b ? a : b;
    return r;
}
float pc_max_like(float a, float b) {
    precise float r = a > b ? a : b;
    return r;
}

/// a . b as mul, fma, fma (cones_internal.h's dot3).
float pc_dot3(vec3 a, vec3 b) {
    precise float xx = a.x * b.x;
    precise float r = pc_fma(a.z, b.z, pc_fma(a.y, b.y, xx));
    return r;
}

/// a x b, each component one mul and one fma (cones_internal.h's cross3).
vec3 pc_cross3(vec3 a, vec3 b) {
    precise float zy = a.z * b.y;
    precise float xz = a.x * b.z;
    precise float yx = a.y * b.x;
    precise vec3 r = vec3(pc_fma(a.y, b.z, -zy), pc_fma(a.z, b.x, -xz), pc_fma(a.x, b.y, -yx));
    return r;
}
