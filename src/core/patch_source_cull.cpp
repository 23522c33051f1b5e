// The cull kernels over a PatchSourceView (patchcull/core/patch_source.h): Bezier and B-spline
// sources are gathered 16 patches at a time into a stack block and run through the batch kernels;
// Gregory sources take the scalar 20-point path below. Each entry checks its inputs once, then
// runs the unchecked range function of core/patch_source_internal.h (which the parallel entries
// run per range).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "core/cones_internal.h"
#include "core/frustum_box_internal.h"
#include "core/patch_source_internal.h"
#include "patchcull/core/error.h"
#include "patchcull/core/fused_cull.h"
#include "patchcull/core/patch_source.h"

namespace patchcull {

namespace {

using cones_detail::kGregoryPoints;

// Calls body(block view, first) for every block of kBlockPatches patches of source patches
// [begin, end) of a Bezier or B-spline source, gathered into one 4 KiB stack block.
template <class Body>
void for_each_block(const PatchSourceView& source, std::size_t begin, std::size_t end, const Body& body) {
    alignas(64) float block[kBlockFloats];
    for (std::size_t first = begin; first < end; first += kBlockPatches) {
        const std::size_t n = std::min(kBlockPatches, end - first);
        gather_bezier(source, first, n, block);
        body(PatchBatchView{block, n, kBlockPatches, kBlockFloats}, first);
    }
}

// The 20 points of Gregory patch p, pts[k] = (X, Y, Z, W).
void gregory_points(const PatchSourceView& s, std::size_t p, float pts[kGregoryPoints][4]) {
    const char* base = static_cast<const char*>(s.points.data) + s.points.offset_bytes;
    const std::uint32_t* idx = s.indices ? s.indices + kGregoryPoints * p : nullptr;
    const std::size_t bytes = static_cast<std::size_t>(s.points.components) * sizeof(float);
    for (int k = 0; k < kGregoryPoints; ++k) {
        const std::size_t i = idx ? idx[k] : kGregoryPoints * p + static_cast<std::size_t>(k);
        pts[k][3] = 1.0f;
        std::memcpy(pts[k], base + i * s.points.stride_bytes, bytes);
    }
}

// All 20 points outside one plane (frustum.h's plane values and verdict, margins when d >= 0).
bool gregory_frustum_culled(const FrustumPlanes& planes, const float pts[kGregoryPoints][4], const float* d) {
    FrustumVerdict verdict;
    float v[6];
    for (int k = 0; k < kGregoryPoints; ++k) {
        frustum_plane_values(planes, pts[k][0], pts[k][1], pts[k][2], pts[k][3], v);
        if (d) add_frustum_margins(planes, *d, pts[k][3], v);
        verdict.add(v);
    }
    return verdict.culled(planes);
}

// cull_frustum_disp_scalar's test (frustum.cpp) on the box of the 20 Cartesian points grown by d.
bool gregory_frustum_disp_culled(const FrustumPlanes& planes, const float pts[kGregoryPoints][4], float d) {
    const auto point_at = [pts](int k, int a) { return pts[k][a]; };
    return frustum_detail::box_outside_frustum(planes, kGregoryPoints, d, point_at);
}

// hiz.h's steps 2-9 over the 20 points: true when the pyramid hides them all. The clip rows are
// frustum.h's (the depth-key matrix, step 2's order); not projectable (step 3) or a NaN in the box
// (a finite point whose clip coordinates overflow) -> false.
bool gregory_occluded(const FrustumPlanes& planes, const HiZPyramid& hiz, const float pts[kGregoryPoints][4]) {
    constexpr float kWSafety = 0x1p-20f;  // hiz.h step 3
    const Vec4 rw = planes.clip_rows[3];
    const float aw[4] = {std::fabs(rw.x), std::fabs(rw.y), std::fabs(rw.z), std::fabs(rw.w)};
    float nxmin = INFINITY, nxmax = -INFINITY, nymin = INFINITY, nymax = -INFINITY, zmin = INFINITY;
    for (int k = 0; k < kGregoryPoints; ++k) {
        const float X = pts[k][0], Y = pts[k][1], Z = pts[k][2], W = pts[k][3];
        float c[4];
        for (int r = 0; r < 4; ++r) {
            const Vec4 m = planes.clip_rows[r];
            c[r] = std::fma(m.w, W, std::fma(m.z, Z, std::fma(m.y, Y, m.x * X)));
        }
        float s = aw[0] * std::fabs(X);
        s = std::fma(aw[1], std::fabs(Y), s);
        s = std::fma(aw[2], std::fabs(Z), s);
        s = std::fma(aw[3], std::fabs(W), s);
        if (!(c[3] > kWSafety * s)) return false;
        const float nx = c[0] / c[3], ny = c[1] / c[3], nz = c[2] / c[3];
        if (std::isnan(nx) || std::isnan(ny) || std::isnan(nz)) return false;
        nxmin = std::min(nxmin, nx);
        nxmax = std::max(nxmax, nx);
        nymin = std::min(nymin, ny);
        nymax = std::max(nymax, ny);
        zmin = std::min(zmin, nz);
    }
    const float half_w = 0.5f * static_cast<float>(hiz.depth_width());
    const float half_h = 0.5f * static_cast<float>(hiz.depth_height());
    const PixelRect rect = hiz_rect_from_window_box(std::fma(nxmin, half_w, half_w), std::fma(nxmax, half_w, half_w),
                                                    std::fma(nymin, half_h, half_h), std::fma(nymax, half_h, half_h),
                                                    hiz.depth_width(), hiz.depth_height());
    return hiz_rect_max(hiz, rect) < zmin;
}

// The cone test of a Gregory patch (cones_internal.h's tangent_cone_gregory, its 20-point sphere and
// back_facing); never culls a patch with a point of w != 1.
bool gregory_back_facing(const float pts[kGregoryPoints][4], Vec3 eye) {
    Vec3 g[kGregoryPoints];
    bool polynomial = true;
    for (int k = 0; k < kGregoryPoints; ++k) {
        g[k] = {pts[k][0], pts[k][1], pts[k][2]};
        polynomial = polynomial && pts[k][3] == 1.0f;
    }
    const NormalCone cone = cones_detail::tangent_cone_gregory(g);
    const PatchSphere sphere = cones_detail::sphere_of_gregory_points(g);
    return polynomial && cones_detail::back_facing(cone, sphere, eye);
}

}  // namespace

namespace detail {

void source_frustum(const PatchSourceView& source, std::size_t first, std::size_t last, const float* max_displacement,
                    const FrustumPlanes& planes, std::uint8_t* culled) {
    if (source.basis == PatchBasis::gregory) {
        float pts[kGregoryPoints][4];
        for (std::size_t p = first; p < last; ++p) {
            gregory_points(source, p, pts);
            culled[p] = gregory_frustum_culled(planes, pts, max_displacement ? max_displacement + p : nullptr);
        }
        return;
    }
    for_each_block(source, first, last, [&](const PatchBatchView& block, std::size_t f) {
        cull_frustum_simd(block, max_displacement ? max_displacement + f : nullptr, planes, culled + f);
    });
}

void source_frustum_disp(const PatchSourceView& source, std::size_t first, std::size_t last,
                         const float* max_displacement, const FrustumPlanes& planes, std::uint8_t* culled) {
    if (source.basis == PatchBasis::gregory) {
        float pts[kGregoryPoints][4];
        for (std::size_t p = first; p < last; ++p) {
            gregory_points(source, p, pts);
            culled[p] = gregory_frustum_disp_culled(planes, pts, max_displacement ? max_displacement[p] : 0.0f);
        }
        return;
    }
    for_each_block(source, first, last, [&](const PatchBatchView& block, std::size_t f) {
        cull_frustum_disp_simd_planes(block, max_displacement ? max_displacement + f : nullptr, planes, culled + f);
    });
}

void source_backpatch(const BackpatchMethodInfo& method, const PatchSourceView& source, std::size_t first,
                      std::size_t last, const CullView& view, const BackpatchOptions& options, std::uint8_t* culled) {
    if (source.basis == PatchBasis::gregory) {
        // The cone methods (fusable) get the Gregory cone test; the others never cull.
        const bool cone = method.fusable && view.has_eye;
        float pts[kGregoryPoints][4];
        for (std::size_t p = first; p < last; ++p) {
            bool out = false;
            if (cone) {
                gregory_points(source, p, pts);
                out = gregory_back_facing(pts, view.eye);
            }
            culled[p] = out ? 1 : 0;
        }
        return;
    }
    const BackpatchKernel kernel = method.simd ? method.simd : method.scalar;
    for_each_block(source, first, last,
                   [&](const PatchBatchView& block, std::size_t f) { kernel(block, view, options, culled + f); });
}

void source_fused(const PatchSourceView& source, std::size_t first, std::size_t last, const FusedCullSetup& setup,
                  const FusedPlan& plan, std::uint8_t* decision, FusedCullStats* stats) {
    if (source.basis == PatchBasis::gregory) {
        float pts[kGregoryPoints][4];
        for (std::size_t p = first; p < last; ++p) {
            gregory_points(source, p, pts);
            std::uint8_t d = kFusedVisible;
            for (int pos = 0; pos < plan.count && d == kFusedVisible; ++pos) {
                if (stats) ++stats->groups_entered[pos];
                const FusedStage stage = plan.stages[pos];
                if (stage == FusedStage::frustum && gregory_frustum_culled(setup.planes, pts, nullptr))
                    d = kFusedFrustumCulled;
                if (stage == FusedStage::occlusion && gregory_occluded(setup.planes, *setup.hiz, pts))
                    d = kFusedOccluded;
                if (stage == FusedStage::backpatch && gregory_back_facing(pts, setup.eye)) d = kFusedBackPatchCulled;
                if (stats && d != kFusedVisible) ++stats->patches_culled[static_cast<int>(stage)];
            }
            decision[p] = d;
        }
        if (stats) stats->groups += last - first;
        return;
    }
    for_each_block(source, first, last, [&](const PatchBatchView& block, std::size_t f) {
        cull_fused_simd(block, setup, plan, decision + f, stats);
    });
}

void check_fused_inputs(const FusedCullSetup& setup, const FusedPlan& plan, const char* what) {
    if (!valid_fused_plan(plan)) throw Error(std::string(what) + ": invalid plan " + fused_plan_name(plan));
    bool occlusion = false;
    for (int pos = 0; pos < plan.count; ++pos) occlusion |= plan.stages[pos] == FusedStage::occlusion;
    if (!occlusion) return;
    if (!setup.hiz) throw Error(std::string(what) + ": the plan has occlusion but setup.hiz is null");
    check_hiz_convention(*setup.hiz, setup.planes.depth, what);
}

}  // namespace detail

void cull_frustum(const PatchSourceView& source, const float* max_displacement, const CullView& view,
                  std::uint8_t* culled) {
    check_patch_source(source, "cull_frustum");
    detail::source_frustum(source, 0, source.count, max_displacement, view.planes, culled);
}

void cull_frustum_disp(const PatchSourceView& source, const float* max_displacement, const CullView& view,
                       std::uint8_t* culled) {
    check_patch_source(source, "cull_frustum_disp");
    const FrustumPlanes planes = make_frustum_planes(view.object_to_clip, view.depth);  // refuses a contradiction
    detail::source_frustum_disp(source, 0, source.count, max_displacement, planes, culled);
}

void cull_backpatch(BackpatchMethod id, const PatchSourceView& source, const CullView& view,
                    const BackpatchOptions& options, std::uint8_t* culled) {
    check_patch_source(source, "cull_backpatch");
    const BackpatchMethodInfo& method = backpatch_method_info(id);
    detail::source_backpatch(method, source, 0, source.count, view, options, culled);
}

void cull_occlusion(const PatchSourceView& source, const CullView& view, const HiZPyramid& hiz,
                    std::uint8_t* decision) {
    check_patch_source(source, "cull_occlusion");
    check_hiz_convention(hiz, view.depth, "cull_occlusion");
    // cull_occlusion_simd's plan on a setup made once (the Gregory path: frustum, then steps 2-9).
    const FusedCullSetup setup = make_fused_setup(view, BackPatchCone::tcone, &hiz);
    FusedPlan plan;
    plan.stages[0] = FusedStage::frustum;
    plan.stages[1] = FusedStage::occlusion;
    plan.count = 2;
    detail::source_fused(source, 0, source.count, setup, plan, decision, nullptr);
}

void cull_fused(const PatchSourceView& source, const FusedCullSetup& setup, const FusedPlan& plan,
                std::uint8_t* decision, FusedCullStats* stats) {
    check_patch_source(source, "cull_fused");
    detail::check_fused_inputs(setup, plan, "cull_fused");
    detail::source_fused(source, 0, source.count, setup, plan, decision, stats);
}

}  // namespace patchcull
