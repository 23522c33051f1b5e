// shaders/exact_fma.h (GLSL only): pc_fma(a, b, c), a*b + c rounded once, as std::fma.
//
// The CPU reference kernels use std::fma and the GPU passes must make bit-identical decisions.
// GLSL's fma() is a single rounding on GPUs (NVIDIA: FFMA), but Mesa's llvmpipe (22.3.6) lowers
// it to a multiply and an add, rounded twice (measured: 835 of 4096 random cases differ). With
// PATCHCULL_FMA_VIA_DOUBLE defined (the renderer defines it on software rasterizers), pc_fma is
// computed exactly in double precision instead:
//   p = a*b is exact in double (24 + 24 significant bits), s = p + c rounded to double with its
//   exact error e (TwoSum), so p + c = s + e; float(s) is the correctly rounded result unless s is
//   exactly halfway between two floats and e != 0, where e decides the direction. There s, one
//   double ulp towards e (its low word +-1: a midpoint's 29 low bits are 0x10000000, so no carry),
//   is no longer a midpoint and lies on the side of the midpoint where p + c does.
// Results below the normal floats are not corrected (their midpoints have fewer bits; llvmpipe
// flushes them to zero, and the CPU kernels' thresholds keep the decisions away from them).
#ifdef PATCHCULL_FMA_VIA_DOUBLE
// The fast run (pc_fma_exact false, set by flag_chain.h's PC_RUN_EXACT): pc_fma returns float(s)
// without the fix-up and sets pc_fma_suspect where the exact run would fix s up. Where no call of
// a run was suspect, its results are the exact run's.
bool pc_fma_exact = true;
bool pc_fma_suspect = false;
float pc_fma(float a, float b, float c) {
    precise double p = double(a) * double(b);
    precise double s = p + double(c);
    precise double bv = s - p;
    precise double av = s - bv;
    precise double e = (p - av) + (double(c) - bv);
    uvec2 bits = unpackDouble2x32(s);
    const bool midpoint = e != 0.0lf && (bits.x & 0x1FFFFFFFu) == 0x10000000u;
    if (!pc_fma_exact) {
        pc_fma_suspect = pc_fma_suspect || midpoint;
        return float(s);
    }
    bits.x = midpoint ? ((e > 0.0lf) == (s > 0.0lf) ? bits.x + 1u : bits.x - 1u) : bits.x;
    return float(packDouble2x32(bits));
}
#else

float pc_fma(float a, float b, float c) {
    return fma(a, b, c);
}

#endif
