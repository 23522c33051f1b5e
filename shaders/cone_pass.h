// The body of the cone back-patch passes (cull_tcone.comp.glsl, cull_ncone.comp.glsl), which
// differ only in the cone: the including shader defines PC_PASS_CONE (pc_tangent_cone or
// pc_normal_cone) and includes shared.h, backpatch_shared.h, exact_fma.h, backpatch_exact.h and
// backpatch_cones.h first (the build inlines includes one level deep, so this file has none).
// Per patch: the cone, the control-point sphere and the perspective back-facing test; rational
// patches (any w != 1) are never culled. Writes kCullBackPatch or 0 to the patch's back-patch
// flag word (kBindingBackPatchFlags, the input of cull_occlusion's back-patch hook).

layout(local_size_x = kConeGroupSize) in;

layout(std430, binding = kBindingControlPoints) readonly buffer ControlPoints {
    vec4 control_points[];  // patch p's point k at 16p + k (patch.h order)
};
layout(std430, binding = kBindingBackPatchFlags) writeonly buffer BackPatchFlags {
    uint backpatch_flags[];
};

layout(std430, binding = kBindingConeValues) writeonly buffer ConeValues {
    float cone_values[];  // kConeValues per patch, written only when u_write_cones
};

uniform uint u_patch_count;
uniform uint u_first_patch;  // dispatches cover patches from here (large sets take several)
uniform vec3 u_eye;  // object space
uniform bool u_write_cones;

void main() {
    const uint p = u_first_patch + gl_GlobalInvocationID.x;
    if (p >= u_patch_count) return;
    vec4 P[16];
    for (int k = 0; k < 16; ++k) P[k] = control_points[16u * p + uint(k)];
    const PcCone cone = PC_PASS_CONE(P);
    const PcSphere sphere = pc_sphere_of_points(P);
    const bool culled = pc_is_polynomial(P) && pc_back_facing(cone, sphere, u_eye);
    backpatch_flags[p] = culled ? kCullBackPatch : 0u;
    if (u_write_cones) {
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
