// PATCHCULL_SCALAR_CLONES, for the scalar reference kernels (private to patchcull): on x86-64 a
// second clone of each marked function is compiled with FMA enabled (std::fma becomes one vfmadd
// instruction) and picked once at load time (ifunc). Results are identical by definition: fma is
// exactly rounded either way. Not used under AddressSanitizer.
#pragma once

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(__SANITIZE_ADDRESS__)
#define PATCHCULL_SCALAR_CLONES __attribute__((target_clones("fma", "default")))
#else
#define PATCHCULL_SCALAR_CLONES
#endif
