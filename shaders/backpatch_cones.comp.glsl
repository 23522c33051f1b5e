// Cone back-patch cull pass (BackpatchConePass, src/gl/backpatch_cones_pass.cpp), one invocation
// per patch: the GPU twin of cull_tcone_scalar and cull_ncone_scalar (include/patchcull/core/backpatch.h,
// src/core/backpatch_cones.cpp). TCONE (default): the Sederberg & Meyers cone of the tangent and
// bitangent control vectors; NCONE (compiled with PATCHCULL_NCONE): the cone of the 36 control
// vectors of the normal patch (Shirman & Abi-Ezzi). The cones and the test are backpatch_cones.h,
// the operation-by-operation mirror of src/core/cones_internal.h.
// Per patch: the cone, the control-point sphere and the perspective back-facing test; rational
// patches (any w != 1) are never culled. A link of the flag chain (flag_chain.h): patches culled
// earlier are skipped, and so are displaced ones (margin > 0: a displaced surface is not bounded by
// the base patch's normals, Loop, Niessner & Eisenacher §8); a culled patch gets kCullBackPatch.
// With PC_PATCH_SOURCE the 16 points come from the caller's patch source (patch_source.h); with
// PC_PATCH_SOURCE_GREGORY a Gregory patch's 20 points give its Gregory tangent cone
// (tangent_cone_gregory of cones_internal.h) whichever cone method runs.
#version 450 core
#include "shared.h"
#include "pass_params.h"
#define PC_CONTROL_POINTS readonly
#define PC_CULL_FLAGS
#define PC_MAX_DISPLACEMENT readonly
#include "patch_buffers.h"
#include "exact_fma.h"
#include "backpatch_exact.h"
#define u_zero cones.zero
#include "backpatch_cones.h"
#include "flag_chain.h"
#include "patch_source.h"

#ifdef PATCHCULL_NCONE
#define PC_PASS_CONE pc_normal_cone
#else
#define PC_PASS_CONE pc_tangent_cone
#endif

layout(local_size_x = kConeGroupSize) in;

layout(std430, binding = kBindingConeValues) writeonly buffer ConeValues {
    float cone_values[];  // kConeValues per patch, written only when write_cones
};

void main() {
    const uint p = cones.first_patch + gl_GlobalInvocationID.x;
    if (gl_GlobalInvocationID.x >= cones.patch_count || pc_chain_culled(p)) return;
    if (pc_margin(p, cones.has_margins) > 0.0) return;
#ifdef PC_PATCH_SOURCE_GREGORY
    // A Gregory patch: its own tangent cone (either cone method) and the sphere of its 20 points.
    if (!pc_gather_source(p)) return;
    const PcCone cone = pc_tangent_cone_gregory(pc_source_points);
    const PcSphere sphere = pc_sphere_of_gregory_points(pc_source_points);
    const bool polynomial = pc_is_polynomial_gregory(pc_source_points);
#else
    vec4 P[16];
#ifdef PC_PATCH_SOURCE
    if (!pc_gather_source(p)) return;
    for (uint k = 0u; k < 16u; ++k) P[k] = pc_source_points[k];
#else
    for (int k = 0; k < 16; ++k) P[k] = control_points[16u * p + uint(k)];
#endif
    const PcCone cone = PC_PASS_CONE(P);
    const PcSphere sphere = pc_sphere_of_points(P);
    const bool polynomial = pc_is_polynomial(P);
#endif
    if (polynomial && pc_back_facing(cone, sphere, cones.eye.xyz)) pc_chain_cull(p, kCullBackPatch);
    if (cones.write_cones != 0u) {
        const uint o = kConeValues * p;
        cone_values[o] = cone.axis.x;
        cone_values[o + 1u] = cone.axis.y;
        cone_values[o + 2u] = cone.axis.z;
        cone_values[o + 3u] = cone.cos_angle;
        cone_values[o + 4u] = cone.sin_angle;
        cone_values[o + 5u] = cone.valid ? 1.0 : 0.0;
        cone_values[o + 6u] = sphere.center.x;
        cone_values[o + 7u] = sphere.center.y;
        cone_values[o + 8u] = sphere.center.z;
        cone_values[o + 9u] = sphere.radius;
        cone_values[o + 10u] = 0.0;
        cone_values[o + 11u] = 0.0;
    }
}
