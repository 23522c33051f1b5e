// patchcull/core/fused_cull.h: one CPU kernel for the frustum, back-patch and Hi-Z occlusion tests of
// a patch batch, in a caller-chosen order, leaving each group of patches as soon as every patch of
// it is decided.
//
// The separate kernels (frustum.h, backpatch.h, hiz.h) each read all 64 control-point components
// of every patch; the Hi-Z kernel even repeats the frustum test. Here every test is one stage of a
// single pass over the batch: a group of patches (one per SIMD lane) is loaded once, its
// clip-space control points are computed once and serve both the frustum planes (w + x, w - x, ...
// as comparisons of the clip coordinates, frustum.h) and the screen box of the Hi-Z test (hiz.h,
// steps 3-9), and the group skips the remaining stages once all of its lanes are culled. Which
// order pays depends on the object and the frame: FusedCostModel (fused_cost_model.h) chooses it.
//
// ---- Decisions -------------------------------------------------------------------------------
// decision[i] is the first stage of the plan that culls patch i, or kFusedVisible:
//   kFusedFrustumCulled  cull_frustum_scalar's test without displacement (frustum.h),
//   kFusedOccluded       hiz.h's steps 2-9 (not projectable -> not occluded),
//   kFusedBackPatchCulled the plan's cone test, cull_tcone_scalar or cull_ncone_scalar (backpatch.h).
// Each stage's verdict on a patch is exactly the separate kernel's, so for every plan
//   culled by the fused kernel  <=>  culled by one of the plan's separate kernels,
// and the recorded reason is the first of them in plan order (tests/core/fused_cull_test.cpp checks
// both against the separate scalar kernels, on random batches and every plan). With the plan
// {frustum, occlusion} the decisions equal cull_occlusion_scalar's byte for byte (kFusedVisible,
// kFusedFrustumCulled, kFusedOccluded have HiZDecision's values); cull_occlusion_simd is that plan.
// Conservative because each separate test is (their headers give the arguments); no stage looks
// at another's verdict except to skip work.
//
// ---- Plans -----------------------------------------------------------------------------------
// A plan lists 1 to 3 distinct stages. Occlusion must come after frustum (it reads the clip
// coordinates the frustum stage computed; alone it would also test patches that the frustum test
// would cull, which it may call occluded: correct, but another plan). valid_fused_plan() checks.
// Back-patch stages apply to undisplaced polynomial patches only, like the cone kernels; callers
// leave them out for displaced objects. A patch with a non-finite coordinate is never culled: the
// frustum stage's probe keeps it (frustum.h), the occlusion stage finds it not projectable (hiz.h
// step 3) and the cone stages never cull it (backpatch.h).
//
// ---- Statistics --------------------------------------------------------------------------------
// When stats is given, the kernel counts per plan position the groups that reached that stage and,
// per stage, the patches it culled. A group is Lanes(d) patches for the SIMD kernel and 1 patch
// for the scalar reference, so the counts differ between the two (the decisions do not).
//
// Over your own control points (a PatchSourceView: strided float3/float4, indices, B-spline and
// Gregory patches, e.g. an OpenSubdiv table) the same kernel is cull_fused in patch_source.h.
//
// Contracts: decision holds patches.count bytes; the plan is valid; setup.hiz is set and built
// when the plan has occlusion. Kernels never allocate or throw; make_fused_setup throws Error for a
// matrix that contradicts its convention or a pyramid of the other direction.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/clip_space.h"
#include "patchcull/core/cull_flags.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"

namespace patchcull {

enum FusedDecision : std::uint8_t {
    kFusedVisible = 0,          ///< = kHiZVisible
    kFusedFrustumCulled = 1,    ///< = kHiZFrustumCulled
    kFusedOccluded = 2,         ///< = kHiZOccluded
    kFusedBackPatchCulled = 3,  ///< the plan's back-patch cone culled it
};

/// A stage of a plan is one of the cull tests (cull_flags.h): FusedStage::frustum is
/// CullTest::frustum, and a stage's flag bit is cull_test_flag(stage).
using FusedStage = CullTest;
inline constexpr int kFusedStages = kCullTestCount;

/// Tests in the order they run; stages[0 .. count).
struct FusedPlan {
    FusedStage stages[kFusedStages] = {FusedStage::frustum, FusedStage::backpatch, FusedStage::occlusion};
    int count = 3;
};

/// True when plan has 1..3 distinct stages and occlusion, if present, comes after frustum.
bool valid_fused_plan(const FusedPlan& plan);

/// Every valid plan made of exactly the stages in `stages` (a bit per FusedStage), in a fixed
/// order; returns how many were written to out (at most 6).
int fused_plans_of(unsigned stages, FusedPlan out[6]);

/// Short name of a plan: its stages' initials in order, e.g. "FBH", "FH", "BFH".
std::string fused_plan_name(const FusedPlan& plan);

enum class BackPatchCone : std::uint8_t { tcone, ncone };

/// Per-object, per-frame inputs, prepared once (no work per call beyond reading them).
struct FusedCullSetup {
    FrustumPlanes planes;  ///< make_frustum_planes(object_to_clip, depth); clip_rows feed the Hi-Z box
    Vec3 eye;              ///< the eye in the patches' (object) space, for the cone test
    BackPatchCone cone = BackPatchCone::tcone;
    const HiZPyramid* hiz = nullptr;  ///< needed by plans with occlusion; its size is the screen
};

/// object_to_clip and its depth convention (clip_space.h), the object-space eye, the cone test
/// and the pyramid (null when no plan will have occlusion).
FusedCullSetup make_fused_setup(const Mat4& object_to_clip, ClipDepth depth, Vec3 eye, BackPatchCone cone,
                                const HiZPyramid* hiz);
struct CullView;  // cull_view.h
/// The same from one view's CullView (its planes and eye).
FusedCullSetup make_fused_setup(const CullView& view, BackPatchCone cone, const HiZPyramid* hiz);

/// Work counts of one or more kernel calls (added to, never reset by the kernel).
struct FusedCullStats {
    std::uint64_t groups_entered[kFusedStages] = {};  ///< by plan position
    std::uint64_t patches_culled[kFusedStages] = {};  ///< by FusedStage
    std::uint64_t groups = 0;                         ///< groups in the calls
};

/// Scalar reference: each patch runs the plan's stages until one culls it.
void cull_fused_scalar(const PatchBatchView& patches, const FusedCullSetup& setup, const FusedPlan& plan,
                       std::uint8_t* decision, FusedCullStats* stats = nullptr);

/// SIMD (Highway, target chosen once at run time): the same decisions, a group of patches per
/// vector, the group leaving as soon as all its lanes are culled.
void cull_fused_simd(const PatchBatchView& patches, const FusedCullSetup& setup, const FusedPlan& plan,
                     std::uint8_t* decision, FusedCullStats* stats = nullptr);

/// What one or more profiling calls measured (added to, never reset by the kernel).
struct FusedProfile {
    std::uint64_t groups = 0;
    /// decided[S]: groups all of whose patches some stage of S culls (S a bit per FusedStage,
    /// only subsets of the plan's stages are counted; decided[0] stays 0).
    std::uint64_t decided[1u << kFusedStages] = {};
    /// patches_culled_by[S]: patches that some stage of S culls (same subsets as decided).
    std::uint64_t patches_culled_by[1u << kFusedStages] = {};
    std::uint64_t ticks[kFusedStages] = {};  ///< time-stamp-counter ticks spent in each stage
    std::uint64_t call_ticks = 0;            ///< ticks of the whole calls
    double seconds = 0;                      ///< wall time of the calls
    /// Seconds per profiled group of stage s (ticks converted at the calls' seconds per tick).
    double seconds_per_group(FusedStage s) const;
};

/// Profiling variant of cull_fused_simd: the same decisions, but on a sample of the groups every
/// stage of the plan runs (no early exit) so that profile learns each stage's time and which
/// subsets of stages would have decided each group. The sample is every k-th group with
/// k = max(1, groups / max_profiled_groups) (max_profiled_groups 0: every group), so a profile of
/// a large object costs about max_profiled_groups groups' worth of extra work; the other groups
/// run as in cull_fused_simd. The cost model (fused_cost_model.h) runs it on a few frames only.
void cull_fused_profile_simd(const PatchBatchView& patches, const FusedCullSetup& setup, const FusedPlan& plan,
                             std::uint8_t* decision, FusedProfile& profile, std::size_t max_profiled_groups = 32);

}  // namespace patchcull
