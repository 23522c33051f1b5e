// The fused cull kernel's plans, setup and scalar reference (patchcull/core/fused_cull.h). The SIMD
// kernel lives in fused_cull_simd.cpp.
//
// The scalar reference is deliberately made of the separate kernels' own per-patch code
// (frustum_plane_values, the cone kernels on a one-patch batch, patch_screen_bounds and
// hiz_rect_max), so "each stage's verdict equals the separate kernel's" holds by construction here,
// and the SIMD kernel is tested against this reference.
#include "patchcull/core/fused_cull.h"

#include <algorithm>
#include <limits>

#include "core/scalar_clones.h"

namespace patchcull {

bool valid_fused_plan(const FusedPlan& plan) {
    if (plan.count < 1 || plan.count > kFusedStages) return false;
    bool seen[kFusedStages] = {};
    for (int i = 0; i < plan.count; ++i) {
        const int s = static_cast<int>(plan.stages[i]);
        if (s < 0 || s >= kFusedStages || seen[s]) return false;
        if (plan.stages[i] == FusedStage::occlusion && !seen[static_cast<int>(FusedStage::frustum)]) return false;
        seen[s] = true;
    }
    return true;
}

int fused_plans_of(unsigned stages, FusedPlan out[6]) {
    static constexpr FusedStage kAll[kFusedStages] = {FusedStage::frustum, FusedStage::backpatch,
                                                      FusedStage::occlusion};
    FusedStage chosen[kFusedStages];
    int n = 0;
    for (FusedStage s : kAll)
        if (stages & (1u << static_cast<unsigned>(s))) chosen[n++] = s;
    int written = 0;
    if (n == 0) return 0;
    // chosen is in enum order (kAll's), the first permutation.
    do {
        FusedPlan plan;
        plan.count = n;
        std::copy(chosen, chosen + n, plan.stages);
        if (valid_fused_plan(plan)) out[written++] = plan;
    } while (std::next_permutation(chosen, chosen + n));
    return written;
}

std::string fused_plan_name(const FusedPlan& plan) {
    static constexpr char kInitial[kFusedStages] = {'F', 'B', 'H'};
    std::string name;
    for (int i = 0; i < plan.count && i < kFusedStages; ++i)
        name += kInitial[static_cast<int>(plan.stages[i]) % kFusedStages];
    return name;
}

FusedCullSetup make_fused_setup(const Mat4& object_to_clip, ClipDepth depth, Vec3 eye, BackPatchCone cone,
                                const HiZPyramid* hiz) {
    if (hiz) check_hiz_convention(*hiz, depth, "make_fused_setup");
    FusedCullSetup setup;
    setup.planes = make_frustum_planes(object_to_clip, depth);
    setup.eye = eye;
    setup.cone = cone;
    setup.hiz = hiz;
    return setup;
}

double FusedProfile::seconds_per_group(FusedStage s) const {
    if (call_ticks == 0 || groups == 0) return 0;
    const double seconds_per_tick = seconds / static_cast<double>(call_ticks);
    return static_cast<double>(ticks[static_cast<int>(s)]) * seconds_per_tick / static_cast<double>(groups);
}

namespace {

// The separate frustum kernel's verdict on patch p (no displacement).
bool frustum_culled(const PatchBatchView& v, std::size_t p, const FrustumPlanes& planes) {
    FrustumVerdict verdict;
    float value[6];
    for (int k = 0; k < kPatchPoints; ++k) {
        frustum_plane_values(planes, v.at(p, k, 0), v.at(p, k, 1), v.at(p, k, 2), v.at(p, k, 3), value);
        verdict.add(value);
    }
    return verdict.culled(planes);
}

// The separate cone kernel's verdict on patch p: the patch copied to a one-patch batch on the stack.
bool backpatch_culled(const PatchBatchView& v, std::size_t p, const FusedCullSetup& setup) {
    alignas(64) float one[4 * kPatchPoints * kBatchAlignment] = {};
    for (int k = 0; k < kPatchPoints; ++k)
        for (int c = 0; c < 4; ++c) one[(4 * k + c) * kBatchAlignment] = v.at(p, k, c);
    const PatchBatchView single{one, 1, kBatchAlignment};
    std::uint8_t culled = 0;
    (setup.cone == BackPatchCone::tcone ? cull_tcone_scalar : cull_ncone_scalar)(single, setup.eye, &culled);
    return culled != 0;
}

// hiz.h's steps 2-9 on patch p.
bool occluded(const PatchBatchView& v, std::size_t p, const FusedCullSetup& setup, const Mat4& object_to_clip) {
    const HiZPyramid& hiz = *setup.hiz;
    PatchScreenBounds b;
    if (!patch_screen_bounds(v, p, object_to_clip, ClipDepth::zero_to_one, hiz.depth_width(), hiz.depth_height(), b))
        return false;
    return hiz_rect_max(hiz, b.rect) < b.zmin;
}

}  // namespace

PATCHCULL_SCALAR_CLONES
void cull_fused_scalar(const PatchBatchView& patches, const FusedCullSetup& setup, const FusedPlan& plan,
                       std::uint8_t* decision, FusedCullStats* stats) {
    Mat4 object_to_clip;
    for (int r = 0; r < 4; ++r) {
        const Vec4 row = setup.planes.clip_rows[r];
        object_to_clip.at(r, 0) = row.x;
        object_to_clip.at(r, 1) = row.y;
        object_to_clip.at(r, 2) = row.z;
        object_to_clip.at(r, 3) = row.w;
    }
    for (std::size_t p = 0; p < patches.count; ++p) {
        std::uint8_t d = kFusedVisible;
        for (int pos = 0; pos < plan.count && d == kFusedVisible; ++pos) {
            if (stats) ++stats->groups_entered[pos];
            switch (plan.stages[pos]) {
                case FusedStage::frustum:
                    if (frustum_culled(patches, p, setup.planes)) d = kFusedFrustumCulled;
                    break;
                case FusedStage::backpatch:
                    if (backpatch_culled(patches, p, setup)) d = kFusedBackPatchCulled;
                    break;
                case FusedStage::occlusion:
                    if (occluded(patches, p, setup, object_to_clip)) d = kFusedOccluded;
                    break;
            }
            if (stats && d != kFusedVisible) ++stats->patches_culled[static_cast<int>(plan.stages[pos])];
        }
        decision[p] = d;
    }
    if (stats) stats->groups += patches.count;
}

}  // namespace patchcull
