// Views over the caller's control points (patchcull/core/patch_source.h): the one check of a view
// and the gather of 16 patches into a blocked block, converting B-spline spans to Bezier form.
#include "patchcull/core/patch_source.h"

#include <algorithm>
#include <cstring>
#include <string>

#include "patchcull/core/error.h"

namespace patchcull {

namespace {

constexpr std::size_t kLanes = kBlockPatches;

// The slots of a 4 x 4 B-spline grid that are real points under OpenSubdiv's boundary mask
// (bit 0: row 0 phantom, bit 1: column 3, bit 2: row 3, bit 3: column 0): bit k set for slot k.
constexpr std::uint32_t real_slots(unsigned mask) {
    std::uint32_t slots = 0;
    for (int k = 0; k < 16; ++k) {
        const int row = k / 4, col = k % 4;
        const bool phantom = ((mask & 1u) && row == 0) || ((mask & 2u) && col == 3) || ((mask & 4u) && row == 3) ||
                             ((mask & 8u) && col == 0);
        if (!phantom) slots |= 1u << k;
    }
    return slots;
}

std::string basis_name(PatchBasis basis) {
    switch (basis) {
        case PatchBasis::bezier:
            return "bezier";
        case PatchBasis::bspline:
            return "bspline";
        case PatchBasis::gregory:
            return "gregory";
    }
    return "unknown";
}

// Point i of the layout, as 4 floats (w = 1 for 3 components). C is the component count.
template <int C>
inline void load_point(const char* base, std::size_t stride, std::size_t i, float out[4]) {
    std::memcpy(out, base + i * stride, C * sizeof(float));
    if constexpr (C == 3) out[3] = 1.0f;
}

// One direction of the B-spline -> Bezier change of basis on 4 points of C components (lo / hi:
// boundary at the first / last end, where the phantom point b0 = 2 b1 - b2 (b3 = 2 b2 - b1) makes
// the end point b1 (b2) and the phantom drops out, so it is never read).
template <int C>
inline void bspline_to_bezier(const float* b0, const float* b1, const float* b2, const float* b3, bool lo, bool hi,
                              float* e0, float* e1, float* e2, float* e3) {
    constexpr float kSixth = 1.0f / 6.0f, kThird = 1.0f / 3.0f;
    for (int c = 0; c < C; ++c) {
        e0[c] = lo ? b1[c] : (b0[c] + 4.0f * b1[c] + b2[c]) * kSixth;
        e1[c] = (2.0f * b1[c] + b2[c]) * kThird;
        e2[c] = (b1[c] + 2.0f * b2[c]) * kThird;
        e3[c] = hi ? b2[c] : (b1[c] + 4.0f * b2[c] + b3[c]) * kSixth;
    }
}

template <int C>
void gather_bezier_points(const PatchSourceView& s, std::size_t first, std::size_t n, float* block) {
    const char* base = static_cast<const char*>(s.points.data) + s.points.offset_bytes;
    const std::size_t stride = s.points.stride_bytes;
    for (std::size_t j = 0; j < n; ++j) {
        const std::size_t p = first + j;
        const std::uint32_t* idx = s.indices ? s.indices + kPatchPoints * p : nullptr;
        for (int k = 0; k < kPatchPoints; ++k) {
            float v[4];
            load_point<C>(base, stride, idx ? idx[k] : kPatchPoints * p + static_cast<std::size_t>(k), v);
            for (int c = 0; c < 4; ++c) block[static_cast<std::size_t>(4 * k + c) * kLanes + j] = v[c];
        }
    }
}

// Bezier points of B-spline patch p, out[k][c] (k = 4 j + i).
template <int C>
void bspline_patch(const PatchSourceView& s, std::size_t p, float out[16][4]) {
    const char* base = static_cast<const char*>(s.points.data) + s.points.offset_bytes;
    const std::size_t stride = s.points.stride_bytes;
    const std::uint32_t* idx = s.indices ? s.indices + kPatchPoints * p : nullptr;
    const unsigned mask = s.boundary_mask ? s.boundary_mask[p] & 15u : 0u;
    const std::uint32_t slots = real_slots(mask);
    float grid[16][4];
    for (int k = 0; k < kPatchPoints; ++k) {
        if (slots & (1u << k)) {
            load_point<C>(base, stride, idx ? idx[k] : kPatchPoints * p + static_cast<std::size_t>(k), grid[k]);
        } else {
            for (float& v : grid[k]) v = 0.0f;  // phantom: never reaches the result
        }
    }
    // Along u within each row (columns 0 / 3 phantom: bits 3 / 1), then along v (rows 0 / 3: bits 0 / 2).
    float rows[16][4];
    for (int r = 0; r < 4; ++r)
        bspline_to_bezier<C>(grid[4 * r], grid[4 * r + 1], grid[4 * r + 2], grid[4 * r + 3], mask & 8u, mask & 2u,
                             rows[4 * r], rows[4 * r + 1], rows[4 * r + 2], rows[4 * r + 3]);
    for (int i = 0; i < 4; ++i)
        bspline_to_bezier<C>(rows[i], rows[4 + i], rows[8 + i], rows[12 + i], mask & 1u, mask & 4u, out[i], out[4 + i],
                             out[8 + i], out[12 + i]);
    if constexpr (C == 3)
        for (int k = 0; k < kPatchPoints; ++k) out[k][3] = 1.0f;
}

template <int C>
void gather_bspline(const PatchSourceView& s, std::size_t first, std::size_t n, float* block) {
    for (std::size_t j = 0; j < n; ++j) {
        float cp[16][4];
        bspline_patch<C>(s, first + j, cp);
        for (int k = 0; k < kPatchPoints; ++k)
            for (int c = 0; c < 4; ++c) block[static_cast<std::size_t>(4 * k + c) * kLanes + j] = cp[k][c];
    }
}

}  // namespace

void check_patch_source(const PatchSourceView& s, const char* what) {
    if (s.count == 0) return;  // nothing is read
    const auto fail = [&](const std::string& message) { throw Error(std::string(what) + ": " + message); };
    const PointLayout& pts = s.points;
    if (pts.components != 3 && pts.components != 4)
        fail("points.components is " + std::to_string(pts.components) +
             "; it must be 3 (x, y, z with w = 1) or 4 (homogeneous w x, w y, w z, w)");
    const std::size_t point_bytes = static_cast<std::size_t>(pts.components) * sizeof(float);
    if (pts.stride_bytes < pts.offset_bytes + point_bytes)
        fail("points.stride_bytes is " + std::to_string(pts.stride_bytes) + ", smaller than offset_bytes (" +
             std::to_string(pts.offset_bytes) + ") + " + std::to_string(point_bytes) + " bytes of " +
             std::to_string(pts.components) + " floats: a point must lie inside its vertex");
    if (s.basis != PatchBasis::bezier && s.basis != PatchBasis::bspline && s.basis != PatchBasis::gregory)
        fail("unknown basis " + std::to_string(static_cast<int>(s.basis)));
    if (pts.data == nullptr) fail("points.data is null for " + std::to_string(s.count) + " patches");
    if (s.boundary_mask && s.basis != PatchBasis::bspline)
        fail("boundary_mask is for bspline patches only, and the basis is " + basis_name(s.basis));
    const std::size_t per_patch = static_cast<std::size_t>(patch_source_points(s.basis));
    if (s.indices == nullptr) {
        if (s.count > pts.point_count / per_patch)
            fail("indices is null, so patch p reads points " + std::to_string(per_patch) + " p .. " +
                 std::to_string(per_patch) + " p + " + std::to_string(per_patch - 1) + ": " + std::to_string(s.count) +
                 " patches need " + std::to_string(s.count) + " x " + std::to_string(per_patch) +
                 " points, but points.point_count is " + std::to_string(pts.point_count));
    }
    if (s.boundary_mask) {
        for (std::size_t p = 0; p < s.count; ++p)
            if (s.boundary_mask[p] >= 16)
                fail("boundary_mask[" + std::to_string(p) + "] is " + std::to_string(s.boundary_mask[p]) +
                     "; a quad patch's boundary mask has 4 bits (OpenSubdiv's PatchParam::GetBoundary())");
    }
    if (s.indices == nullptr) return;
    // Fast pass: the largest index read (phantom slots skipped); then name the first offender.
    std::uint32_t largest = 0;
    if (s.boundary_mask == nullptr) {
        const std::size_t total = s.count * per_patch;
        for (std::size_t i = 0; i < total; ++i) largest = std::max(largest, s.indices[i]);
    } else {
        for (std::size_t p = 0; p < s.count; ++p) {
            const std::uint32_t slots = real_slots(s.boundary_mask[p]);
            for (std::size_t k = 0; k < per_patch; ++k)
                largest = std::max(largest, (slots >> k) & 1u ? s.indices[per_patch * p + k] : 0u);
        }
    }
    if (largest < pts.point_count) return;
    for (std::size_t p = 0; p < s.count; ++p) {
        const std::uint32_t slots = s.boundary_mask ? real_slots(s.boundary_mask[p]) : 0xFFFFFFFFu;
        for (std::size_t k = 0; k < per_patch; ++k) {
            const std::uint32_t index = s.indices[per_patch * p + k];
            if (((slots >> k) & 1u) && index >= pts.point_count)
                fail("patch " + std::to_string(p) + ", point " + std::to_string(k) + ": index " +
                     std::to_string(index) + " is past points.point_count (" + std::to_string(pts.point_count) + ")");
        }
    }
}

void gather_bezier(const PatchSourceView& s, std::size_t first, std::size_t n, float* block) {
    n = std::min(n, kLanes);
    if (s.basis == PatchBasis::bezier) {
        (s.points.components == 4 ? gather_bezier_points<4> : gather_bezier_points<3>)(s, first, n, block);
    } else if (s.basis == PatchBasis::bspline) {
        (s.points.components == 4 ? gather_bspline<4> : gather_bspline<3>)(s, first, n, block);
    } else {
        n = 0;  // gregory: no Bezier form; the block is zeroed
    }
    if (n == kLanes) return;
    for (int a = 0; a < 4 * kPatchPoints; ++a)
        std::fill(block + static_cast<std::size_t>(a) * kLanes + n, block + static_cast<std::size_t>(a + 1) * kLanes,
                  0.0f);
}

BezierPatch source_bezier_patch(const PatchSourceView& s, std::size_t p) {
    alignas(64) float block[kBlockFloats];
    gather_bezier(s, p, 1, block);
    BezierPatch out;
    for (int k = 0; k < kPatchPoints; ++k) {
        const float* c = block + static_cast<std::size_t>(4 * k) * kLanes;
        out.cp[k] = {c[0], c[kLanes], c[2 * kLanes], c[3 * kLanes]};
    }
    return out;
}

}  // namespace patchcull
