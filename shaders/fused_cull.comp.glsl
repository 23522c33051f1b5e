// Fused cull pass (FusedCullPass, src/gl/fused_cull_pass.cpp), one invocation per patch: the
// frustum test (frustum.comp.glsl's), the cone back-patch test (backpatch_cones.comp.glsl's: tcone,
// or ncone with PATCHCULL_NCONE) and the Hi-Z test (occlusion.comp.glsl's) in one dispatch, in the
// flag chain's order, stopping at the first test that culls. The tests are the shared GLSL headers
// the separate passes use (frustum_test.h, backpatch_cones.h, hiz_box_test.h) and steps 2-4 of
// occlusion.comp.glsl operation by operation, so each patch gets the reason the chain
// begin -> FrustumPass -> BackpatchConePass -> OcclusionPass(with_frustum = false) would give it.
// Why fuse: the chain reads every surviving patch's 16 control points (256 bytes) once per pass,
// transforms them to clip space twice (frustum and Hi-Z) and launches three dispatches; here one
// loop over the points computes their clip coordinates once for the frustum planes and the Hi-Z
// box (pc_fused_points), and the cone test runs only on what the frustum kept.
// A link of the flag chain (flag_chain.h): patches culled earlier (e.g. kCullObject) are skipped;
// displaced patches (margin > 0) get the frustum test with their margin only (the cone and the
// control-point Hi-Z test bound neither a displaced surface's normals nor its depth), as in the
// chain; DisplacedPass tests them afterwards.
// With PC_PATCH_SOURCE the points come from the caller's patch source (patch_source.h: Bezier or
// converted B-spline points, gathered once per patch); with PC_PATCH_SOURCE_GREGORY a Gregory
// patch's 20 points feed the frustum and Hi-Z tests (a point whose NDC coordinate is NaN leaves
// the patch unoccluded, as occlusion.comp.glsl) and the cone test is the Gregory tangent cone
// (backpatch_cones.h's pc_tangent_cone_gregory, as cull_fused over a PatchSourceView).
#version 450 core
#include "shared.h"
#include "pass_params.h"
#define PC_CONTROL_POINTS readonly
#define PC_CULL_FLAGS
#define PC_MAX_DISPLACEMENT readonly
#include "patch_buffers.h"
#include "exact_fma.h"
#include "backpatch_exact.h"
#define u_zero fused.zero
#include "backpatch_cones.h"
#include "flag_chain.h"
#include "patch_source.h"

#ifdef PC_PATCH_SOURCE
#define PC_PATCH_POINT(p, k) pc_source_points[k]
#define PC_PATCH_POINT_COUNT PC_SOURCE_POINTS
#endif

#ifdef PATCHCULL_NCONE
#define PC_PASS_CONE pc_normal_cone
#else
#define PC_PASS_CONE pc_tangent_cone
#endif

layout(local_size_x = kCullGroupSize) in;

layout(binding = kTextureUnitHiZ) uniform sampler2D u_hiz;

// frustum_test.h's and hiz_box_test.h's names.
#define u_clip_rows fused.clip_rows
#define u_plane_normal_length fused.plane_normal_length
#define u_plane_depth fused.plane_depth
#define u_screen ivec2(fused.screen_width, fused.screen_height)
#define u_hiz_levels fused.hiz_levels

#include "frustum_test.h"
#include "hiz_box_test.h"

#ifdef PC_PATCH_SOURCE_GREGORY
// True when v is NaN (a test of the bits, which no compiler folds away).
bool pc_is_nan(float v) { return (floatBitsToUint(v) & 0x7FFFFFFFu) > 0x7F800000u; }
#endif

// The fusion: one loop over the 16 control points (a Gregory patch's 20). Each goes to clip space
// once (frustum_test.h's pc_clip_point, which is hiz.h's step 2 in its operation order), and those
// coordinates feed both the frustum planes' maxima (pc_frustum_culled's arithmetic) and the Hi-Z
// test's NDC box and front depth (occlusion.comp.glsl's steps 3-4). Only the six maxima and the
// box stay live, not the points (the cone test reloads them, from cache, if the patch gets that
// far), which keeps the registers low on a GPU. The price: a patch the frustum culls has had its
// box built too.
struct PcFusedPoints {
    bool frustum_culled;
    bool projectable;  // step 3 held for every point (else the patch is not screen-tested)
    float nxmin, nxmax, nymin, nymax, zmin;
};

PcFusedPoints pc_fused_points(uint p, bool frustum, bool hiz, bool with_margins, float d) {
    PcFusedPoints r;
    precise float margin[6];
    precise float m[6];
    for (int q = 0; q < 6; ++q) {
        margin[q] = d * u_plane_normal_length[q >> 2][q & 3];
        m[q] = uintBitsToFloat(0xFF800000u);  // -infinity
    }
    r.projectable = hiz;
    HiZPointBox box;
    box.nxmin = box.nxmax = box.nymin = box.nymax = box.zmin = 0.0;
    bool non_finite = false;
    for (uint k = 0u; k < PC_PATCH_POINT_COUNT; ++k) {
        const vec4 P = PC_PATCH_POINT(p, k);
        const vec4 c = pc_clip_point(P);
        if (frustum) {
            float v[6];
            pc_frustum_plane_values(c, v);
            for (int q = 0; q < 6; ++q) {
                precise float value = v[q];
                if (with_margins) value = pc_fma(margin[q], P.w, value);
                m[q] = m[q] > value ? m[q] : value;
                if (q == 4) non_finite = non_finite || pc_non_finite(value);
            }
        }
        // Steps 3-4 (hiz_box_test.h), as occlusion.comp.glsl.
        if (r.projectable) r.projectable = hiz_add_point(P, c, u_clip_rows[3], k == 0u, box);
#ifdef PC_PATCH_SOURCE_GREGORY
        if (r.projectable &&
            (pc_is_nan(hiz_div(c.x, c.w)) || pc_is_nan(hiz_div(c.y, c.w)) || pc_is_nan(hiz_div(c.z, c.w))))
            r.projectable = false;
#endif
    }
    r.frustum_culled = frustum && pc_frustum_outside(m, non_finite);
    r.nxmin = box.nxmin;
    r.nxmax = box.nxmax;
    r.nymin = box.nymin;
    r.nymax = box.nymax;
    r.zmin = box.zmin;
    return r;
}

void main() {
    const uint p = fused.first_patch + gl_GlobalInvocationID.x;
    if (gl_GlobalInvocationID.x >= fused.patch_count || pc_chain_culled(p)) return;
#ifdef PC_PATCH_SOURCE
    if (!pc_gather_source(p)) return;  // an index past the points: left unculled
#endif
    const float d = pc_margin(p, fused.has_margins);
    // The separate passes' own conditions (the same for a valid margin, >= 0; these keep even a
    // NaN or negative one's decisions equal): BackpatchConePass skips margin > 0, OcclusionPass
    // tests margin == 0 only.
    const bool frustum_tested = (fused.tests & kCullFrustum) != 0u;
    const bool cone_tested = (fused.tests & kCullBackPatch) != 0u && !(d > 0.0);
    const bool hiz_tested = (fused.tests & kCullOcclusion) != 0u && d == 0.0;
    PcFusedPoints points;
    points.frustum_culled = false;
    points.projectable = false;
    if (frustum_tested || hiz_tested) points = pc_fused_points(p, frustum_tested, hiz_tested, PC_HAS_MARGINS(fused.has_margins), d);
    if (points.frustum_culled) {
        pc_chain_cull(p, kCullFrustum);
        return;
    }
#ifdef PC_PATCH_SOURCE_GREGORY
    if (cone_tested) {
        // A Gregory patch: its own tangent cone (either cone method), as BackpatchConePass.
        const PcCone cone = pc_tangent_cone_gregory(pc_source_points);
        const PcSphere sphere = pc_sphere_of_gregory_points(pc_source_points);
        if (pc_is_polynomial_gregory(pc_source_points) && pc_back_facing(cone, sphere, fused.eye.xyz)) {
            pc_chain_cull(p, kCullBackPatch);
            return;
        }
    }
#else
    if (cone_tested) {
        vec4 P[16];
        for (int k = 0; k < 16; ++k) P[k] = PC_PATCH_POINT(p, uint(k));
        const PcCone cone = PC_PASS_CONE(P);
        const PcSphere sphere = pc_sphere_of_points(P);
        if (pc_is_polynomial(P) && pc_back_facing(cone, sphere, fused.eye.xyz)) {
            pc_chain_cull(p, kCullBackPatch);
            return;
        }
    }
#endif
    // Steps 5-9 on the box (hiz_box_test.h).
    if (points.projectable &&
        hiz_box_occluded(points.nxmin, points.nxmax, points.nymin, points.nymax, points.zmin))
        pc_chain_cull(p, kCullOcclusion);
}
