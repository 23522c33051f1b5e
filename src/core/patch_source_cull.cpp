// The cull kernels over a PatchSourceView (patchcull/core/patch_source.h): Bezier and B-spline
// sources are gathered 16 patches at a time into a stack block and run through the batch kernels;
// Gregory sources take the scalar 20-point path below.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "patchcull/core/fused_cull.h"
#include "patchcull/core/patch_source.h"

namespace patchcull {

namespace {

constexpr int kGregoryPoints = 20;

// Calls body(block view, first) for every block of kBlockPatches patches of a Bezier or B-spline
// source, gathered into one 4 KiB stack block.
template <class Body>
void for_each_block(const PatchSourceView& source, const Body& body) {
    alignas(64) float block[kBlockFloats];
    for (std::size_t first = 0; first < source.count; first += kBlockPatches) {
        const std::size_t n = std::min(kBlockPatches, source.count - first);
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

}  // namespace

void cull_frustum(const PatchSourceView& source, const float* max_displacement, const CullView& view,
                  std::uint8_t* culled) {
    check_patch_source(source, "cull_frustum");
    if (source.basis == PatchBasis::gregory) {
        float pts[kGregoryPoints][4];
        for (std::size_t p = 0; p < source.count; ++p) {
            gregory_points(source, p, pts);
            culled[p] = gregory_frustum_culled(view.planes, pts, max_displacement ? max_displacement + p : nullptr);
        }
        return;
    }
    for_each_block(source, [&](const PatchBatchView& block, std::size_t first) {
        cull_frustum_simd(block, max_displacement ? max_displacement + first : nullptr, view.planes, culled + first);
    });
}

void cull_backpatch(BackpatchMethod id, const PatchSourceView& source, const CullView& view,
                    const BackpatchOptions& options, std::uint8_t* culled) {
    check_patch_source(source, "cull_backpatch");
    const BackpatchMethodInfo& method = backpatch_method_info(id);
    const BackpatchKernel kernel = method.simd ? method.simd : method.scalar;
    if (source.basis == PatchBasis::gregory) {
        if (source.count) std::memset(culled, 0, source.count);
        return;
    }
    for_each_block(
        source, [&](const PatchBatchView& block, std::size_t first) { kernel(block, view, options, culled + first); });
}

void cull_occlusion(const PatchSourceView& source, const CullView& view, const HiZPyramid& hiz,
                    std::uint8_t* decision) {
    check_patch_source(source, "cull_occlusion");
    check_hiz_convention(hiz, view.depth, "cull_occlusion");
    if (source.basis == PatchBasis::gregory) {
        float pts[kGregoryPoints][4];
        for (std::size_t p = 0; p < source.count; ++p) {
            gregory_points(source, p, pts);
            if (gregory_frustum_culled(view.planes, pts, nullptr)) {
                decision[p] = kHiZFrustumCulled;
            } else {
                decision[p] = gregory_occluded(view.planes, hiz, pts) ? kHiZOccluded : kHiZVisible;
            }
        }
        return;
    }
    // cull_occlusion_simd's plan on a setup made once.
    const FusedCullSetup setup = make_fused_setup(view, BackPatchCone::tcone, &hiz);
    FusedPlan plan;
    plan.stages[0] = FusedStage::frustum;
    plan.stages[1] = FusedStage::occlusion;
    plan.count = 2;
    for_each_block(source, [&](const PatchBatchView& block, std::size_t first) {
        cull_fused_simd(block, setup, plan, decision + first, nullptr);
    });
}

}  // namespace patchcull
