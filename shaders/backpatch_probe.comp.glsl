// Probe of the back-patch shaders' exact arithmetic (shaders/exact_fma.h, backpatch_exact.h):
// out[i] = pc_fma(a, b, c), pc_div(a, b), pc_sqrt(a), pc_div_from(a, b, c) or pc_sqrt_from(a, b)
// of in[i] = (a, b, c, -) by u_mode
// (shared.h's kProbe*). Used by BackpatchCuller's start-up check of GLSL fma() on GPUs
// and by tests/gl/backpatch_gpu_test.cpp (against std::fma, / and std::sqrt).
#version 450 core
#include "shared.h"
#include "exact_fma.h"
#include "backpatch_exact.h"

layout(local_size_x = kProbeGroupSize) in;

layout(std430, binding = kBindingProbeIn) readonly buffer ProbeIn {
    vec4 probe_in[];
};
layout(std430, binding = kBindingProbeOut) writeonly buffer ProbeOut {
    float probe_out[];
};

uniform uint u_count;
uniform uint u_mode;

void main() {
    const uint i = gl_GlobalInvocationID.x;
    if (i >= u_count) return;
    const vec4 v = probe_in[i];
    float r;
    if (u_mode == kProbeFma) r = pc_fma(v.x, v.y, v.z);
    else if (u_mode == kProbeDiv) r = pc_div(v.x, v.y);
    else if (u_mode == kProbeSqrt) r = pc_sqrt(v.x);
    else if (u_mode == kProbeDivFrom) r = pc_div_from(v.x, v.y, v.z);
    else r = pc_sqrt_from(v.x, v.y);
    probe_out[i] = r;
}
