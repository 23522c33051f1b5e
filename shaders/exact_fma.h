// shaders/exact_fma.h (GLSL only): pc_fma(a, b, c), a*b + c rounded once, as std::fma.
//
// The CPU reference kernels use std::fma and the GPU passes must make bit-identical decisions.
// GLSL's fma() is a single rounding on GPUs (NVIDIA: FFMA), but Mesa's llvmpipe (22.3.6) lowers
// it to a multiply and an add, rounded twice (measured: 835 of 4096 random cases differ). With
// PATCHCULL_FMA_VIA_DOUBLE defined (the renderer defines it on software rasterizers), pc_fma is
// computed exactly in double precision instead:
//   p = a*b is exact in double (24 + 24 significant bits), s = p + c rounded to double with its
//   exact error e (TwoSum), so p + c = s + e; float(s) is the correctly rounded result unless s is
//   exactly halfway between two floats and e != 0, where e decides the direction.
// (Subnormal results may still differ on llvmpipe, which flushes denormals to zero.)
#ifdef PATCHCULL_FMA_VIA_DOUBLE
// The fast run (pc_fma_exact false, set by flag_chain.h's PC_RUN_EXACT): pc_fma returns float(s)
// without the fix-up and sets pc_fma_suspect where s is a midpoint between two normal floats (the
// 29 low bits of its double significand 0x10000000) or below the normal floats, the only cases
// where float(s) can differ from the correctly rounded a*b + c. Where no call of a run was
// suspect, its results are the exact run's.
bool pc_fma_exact = true;
bool pc_fma_suspect = false;
float pc_next_float(float r, bool up) {
    if (r == 0.0) return up ? uintBitsToFloat(1u) : -uintBitsToFloat(1u);
    const uint b = floatBitsToUint(r);
    return uintBitsToFloat((r > 0.0) == up ? b + 1u : b - 1u);  // magnitude up or down one ulp
}
float pc_fma(float a, float b, float c) {
    precise double p = double(a) * double(b);
    precise double s = p + double(c);
    float r = float(s);
    precise double bv = s - p;
    precise double av = s - bv;
    precise double e = (p - av) + (double(c) - bv);
    if (!pc_fma_exact) {
        const double smallest_normal = packDouble2x32(uvec2(0u, 0x38100000u));  // 2^-126
        pc_fma_suspect = pc_fma_suspect ||
                         (e != 0.0lf && ((unpackDouble2x32(s).x & 0x1FFFFFFFu) == 0x10000000u ||
                                         abs(s) < smallest_normal));
        return r;
    }
    if (e != 0.0lf && double(r) != s) {
        const float other = pc_next_float(r, s > double(r));
        precise double below = s - double(r);
        precise double above = double(other) - s;
        if (below == above) r = (e > 0.0lf) == (other > r) ? other : r;  // s is a midpoint
    }
    return r;
}
#else

float pc_fma(float a, float b, float c) {
    return fma(a, b, c);
}

#endif
