// Fused cull pass (FusedCullPass, src/gl/fused_cull_pass.cpp), one invocation per patch: the
// frustum test (frustum.comp.glsl's), the cone back-patch test (backpatch_cones.comp.glsl's: tcone,
// or ncone with PATCHCULL_NCONE) and the Hi-Z test (occlusion.comp.glsl's) in one dispatch, in the
// flag chain's order, stopping at the first test that culls. The tests are the shared GLSL headers
// the separate passes use (frustum_test.h, backpatch_cones.h, hiz_box_test.h) and steps 2-4 of
// occlusion.comp.glsl operation by operation, so each patch gets the reason the chain
// begin -> FrustumPass -> BackpatchConePass -> OcclusionPass(with_frustum = false) would give it.
// Why fuse: the chain reads every surviving patch's 16 control points (256 bytes) once per pass and
// launches three dispatches; here they are read once and the later tests run only where the
// earlier ones kept the patch, in registers.
// A link of the flag chain (flag_chain.h): patches culled earlier (e.g. kCullObject) are skipped;
// displaced patches (margin > 0) get the frustum test with their margin only (the cone and the
// control-point Hi-Z test bound neither a displaced surface's normals nor its depth), as in the
// chain; DisplacedPass tests them afterwards.
#version 450 core
#include "shared.h"
#include "pass_params.h"
#include "backpatch_shared.h"
#include "exact_fma.h"
#include "backpatch_exact.h"
#define u_zero fused.zero
#include "backpatch_cones.h"
#include "flag_chain.h"

#ifdef PATCHCULL_NCONE
#define PC_PASS_CONE pc_normal_cone
#else
#define PC_PASS_CONE pc_tangent_cone
#endif

layout(local_size_x = kCullGroupSize) in;

layout(std430, binding = kBindingControlPoints) readonly buffer ControlPoints {
    vec4 control_points[];  // patch p's point k at 16p + k (patch.h order)
};
layout(binding = kTextureUnitHiZ) uniform sampler2D u_hiz;

// frustum_test.h's and hiz_box_test.h's names.
#define u_clip_rows fused.clip_rows
#define u_plane_normal_length fused.plane_normal_length
#define u_screen ivec2(fused.screen_width, fused.screen_height)
#define u_hiz_levels fused.hiz_levels

#include "frustum_test.h"
#include "hiz_box_test.h"

// The fusion: each control point goes to clip space once (frustum_test.h's pc_clip_point, which
// is hiz.h's step 2 in its operation order), and both the frustum planes and the Hi-Z screen box
// read those coordinates.

// pc_frustum_culled (frustum_test.h) on the clip points C of the patch's points P: the same plane
// values, margins and maxima, without transforming the points again.
bool pc_fused_frustum_culled(vec4 C[16], vec4 P[16], bool with_margins, float d) {
    precise float margin[6];
    precise float m[6];
    for (int q = 0; q < 6; ++q) {
        margin[q] = d * u_plane_normal_length[q >> 2][q & 3];
        m[q] = uintBitsToFloat(0xFF800000u);  // -infinity
    }
    for (int k = 0; k < 16; ++k) {
        float v[6];
        pc_frustum_plane_values(C[k], v);
        for (int q = 0; q < 6; ++q) {
            precise float value = v[q];
            if (with_margins) value = pc_fma(margin[q], P[k].w, value);
            m[q] = m[q] > value ? m[q] : value;
        }
    }
    bool culled = false;
    for (int q = 0; q < 6; ++q) culled = culled || m[q] < 0.0;
    return culled;
}

// occlusion.comp.glsl's pc_div (backpatch_exact.h's pc_div has the name here): a / b in double,
// rounded once to float. Both are correctly rounded for the normal quotients of step 4, but only
// this one is the occlusion pass's operation for every input, so the decisions match bit for bit.
float pc_div_hiz(float a, float b) {
    precise double q = double(a) / double(b);
    return float(q);
}

// 2^-20: step 3's safety factor (hiz.cpp kWSafety).
const float kWSafety = 9.5367431640625e-07;

// occlusion.comp.glsl's hiz_occluded (steps 3-9 of hiz.h) on the patch's points P and their clip
// coordinates C (step 2).
bool pc_fused_hiz_occluded(vec4 C[16], vec4 P[16]) {
    precise float nxmin = 0.0, nxmax = 0.0, nymin = 0.0, nymax = 0.0, zmin = 0.0;
    for (int k = 0; k < 16; ++k) {
        // Step 3: projectable (provably w > 0), else the patch is not screen-tested.
        // (|M(3, c)| = |u_clip_rows[3][c]|: the w row.)
        const vec4 w_row = u_clip_rows[3];
        precise float s = abs(w_row.x) * abs(P[k].x);
        s = pc_fma(abs(w_row.y), abs(P[k].y), s);
        s = pc_fma(abs(w_row.z), abs(P[k].z), s);
        s = pc_fma(abs(w_row.w), abs(P[k].w), s);
        precise float bound = kWSafety * s;
        if (!(C[k].w > bound)) return false;
        // Step 4: NDC box and front plane.
        const float nx = pc_div_hiz(C[k].x, C[k].w);
        const float ny = pc_div_hiz(C[k].y, C[k].w);
        const float nz = pc_div_hiz(C[k].z, C[k].w);
        if (k == 0) {
            nxmin = nx;
            nxmax = nx;
            nymin = ny;
            nymax = ny;
            zmin = nz;
        } else {
            nxmin = hiz_min(nxmin, nx);
            nxmax = hiz_max(nxmax, nx);
            nymin = hiz_min(nymin, ny);
            nymax = hiz_max(nymax, ny);
            zmin = hiz_min(zmin, nz);
        }
    }
    return hiz_box_occluded(nxmin, nxmax, nymin, nymax, zmin);  // steps 5-9
}

void main() {
    const uint p = fused.first_patch + gl_GlobalInvocationID.x;
    if (gl_GlobalInvocationID.x >= fused.patch_count || pc_chain_culled(p)) return;
    const float d = pc_margin(p, fused.has_margins);
    // The separate passes' own conditions (the same for a valid margin, >= 0; these keep even a
    // NaN or negative one's decisions equal): BackpatchConePass skips margin > 0, OcclusionPass
    // tests margin == 0 only.
    const bool frustum_tested = (fused.tests & kCullFrustum) != 0u;
    const bool cone_tested = (fused.tests & kCullBackPatch) != 0u && !(d > 0.0);
    const bool hiz_tested = (fused.tests & kCullOcclusion) != 0u && d == 0.0;
    if (!frustum_tested && !cone_tested && !hiz_tested) return;
    vec4 P[16];
    for (int k = 0; k < 16; ++k) P[k] = control_points[16u * p + uint(k)];
    vec4 C[16];
    if (frustum_tested || hiz_tested)
        for (int k = 0; k < 16; ++k) C[k] = pc_clip_point(P[k]);
    if (frustum_tested && pc_fused_frustum_culled(C, P, fused.has_margins != 0u, d)) {
        pc_chain_cull(p, kCullFrustum);
        return;
    }
    if (cone_tested) {
        const PcCone cone = PC_PASS_CONE(P);
        const PcSphere sphere = pc_sphere_of_points(P);
        if (pc_is_polynomial(P) && pc_back_facing(cone, sphere, fused.eye.xyz)) {
            pc_chain_cull(p, kCullBackPatch);
            return;
        }
    }
    if (hiz_tested && pc_fused_hiz_occluded(C, P)) pc_chain_cull(p, kCullOcclusion);
}
