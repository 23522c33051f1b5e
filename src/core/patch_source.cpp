// Views over the caller's control points (patchcull/core/patch_source.h): the one check of a view
// and the gather of 16 patches into a blocked block, converting B-spline spans to Bezier form.
#include "patchcull/core/patch_source.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <string>

#include "patchcull/core/error.h"

namespace patchcull {

namespace {

constexpr std::size_t kLanes = kBlockPatches;

constexpr std::array<std::uint32_t, 16> kRealSlots = [] {
    std::array<std::uint32_t, 16> t{};
    for (unsigned m = 0; m < 16; ++m) t[m] = bspline_real_slots(m);
    return t;
}();

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

// One direction of the B-spline -> Bezier change of basis on the 16 lanes of 4 points, in place:
// b0..b3 become the Bezier points e0..e3. lo[j] / hi[j] (0 or all ones): lane j has a boundary at the
// first / last end, where the phantom point b0 = 2 b1 - b2 (b3 = 2 b2 - b1) makes the end point b1
// (b2): the phantom drops out, and its slot (zero here) is never read into the result.
inline void bspline_to_bezier(float* __restrict b0, float* __restrict b1, float* __restrict b2, float* __restrict b3,
                              const std::uint32_t* __restrict lo, const std::uint32_t* __restrict hi) {
    constexpr float kSixth = 1.0f / 6.0f, kThird = 1.0f / 3.0f;
    // Selects as bit masks (all ones: take the boundary point), so that the loop vectorizes.
    const auto select = [](std::uint32_t m, float a, float b) {
        return std::bit_cast<float>((std::bit_cast<std::uint32_t>(a) & m) | (std::bit_cast<std::uint32_t>(b) & ~m));
    };
    for (std::size_t j = 0; j < kLanes; ++j) {
        const float p0 = b0[j], p1 = b1[j], p2 = b2[j], p3 = b3[j];
        b0[j] = select(lo[j], p1, (p0 + 4.0f * p1 + p2) * kSixth);
        b1[j] = (2.0f * p1 + p2) * kThird;
        b2[j] = (p1 + 2.0f * p2) * kThird;
        b3[j] = select(hi[j], p2, (p1 + 4.0f * p2 + p3) * kSixth);
    }
}

// The points of patches [first, first + n) as they are, lane j = patch first + j; a point whose
// slot bit is clear in slots(j) (a B-spline phantom) is written as (0, 0, 0, w = 1 or 0).
template <int C, class Slots>
void gather_raw(const PatchSourceView& s, std::size_t first, std::size_t n, float* block, const Slots& slots) {
    const char* base = static_cast<const char*>(s.points.data) + s.points.offset_bytes;
    const std::size_t stride = s.points.stride_bytes;
    for (std::size_t j = 0; j < n; ++j) {
        const std::size_t p = first + j;
        const std::uint32_t* idx = s.indices ? s.indices + kPatchPoints * p : nullptr;
        const std::uint32_t real = slots(p);
        for (int k = 0; k < kPatchPoints; ++k) {
            float v[4] = {0.0f, 0.0f, 0.0f, C == 3 ? 1.0f : 0.0f};
            if ((real >> k) & 1u)
                load_point<C>(base, stride, idx ? idx[k] : kPatchPoints * p + static_cast<std::size_t>(k), v);
            for (int c = 0; c < 4; ++c) block[static_cast<std::size_t>(4 * k + c) * kLanes + j] = v[c];
        }
    }
}

template <int C>
void gather_bezier_points(const PatchSourceView& s, std::size_t first, std::size_t n, float* block) {
    gather_raw<C>(s, first, n, block, [](std::size_t) { return 0xFFFFu; });
}

// B-spline patches: their points gathered as they are (phantoms zero), then converted to Bezier
// form lane-parallel: along u within each row (columns 0 / 3 phantom: mask bits 3 / 1), then along
// v (rows 0 / 3: bits 0 / 2). With 3 components w stays 1 (the exact result).
template <int C>
void gather_bspline(const PatchSourceView& s, std::size_t first, std::size_t n, float* block) {
    const std::uint8_t* mask = s.boundary_mask;
    gather_raw<C>(s, first, n, block, [&](std::size_t p) { return mask ? kRealSlots[mask[p] & 15u] : 0xFFFFu; });
    for (int a = 0; a < 4 * kPatchPoints; ++a)  // lanes past n: zero, converted to zero
        std::fill(block + static_cast<std::size_t>(a) * kLanes + n, block + static_cast<std::size_t>(a + 1) * kLanes,
                  0.0f);
    std::uint32_t u0[kLanes] = {}, u1[kLanes] = {}, v0[kLanes] = {}, v1[kLanes] = {};
    if (mask)
        for (std::size_t j = 0; j < n; ++j) {
            const unsigned m = mask[first + j];
            v0[j] = 0u - (m & 1u);
            u1[j] = 0u - ((m >> 1) & 1u);
            v1[j] = 0u - ((m >> 2) & 1u);
            u0[j] = 0u - ((m >> 3) & 1u);
        }
    const auto at = [&](int k, int c) { return block + static_cast<std::size_t>(4 * k + c) * kLanes; };
    for (int c = 0; c < C; ++c) {
        for (int r = 0; r < 4; ++r)
            bspline_to_bezier(at(4 * r, c), at(4 * r + 1, c), at(4 * r + 2, c), at(4 * r + 3, c), u0, u1);
        for (int i = 0; i < 4; ++i) bspline_to_bezier(at(i, c), at(4 + i, c), at(8 + i, c), at(12 + i, c), v0, v1);
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
            const std::uint32_t slots = kRealSlots[s.boundary_mask[p]];
            for (std::size_t k = 0; k < per_patch; ++k)
                largest = std::max(largest, (slots >> k) & 1u ? s.indices[per_patch * p + k] : 0u);
        }
    }
    if (largest < pts.point_count) return;
    for (std::size_t p = 0; p < s.count; ++p) {
        const std::uint32_t slots = s.boundary_mask ? kRealSlots[s.boundary_mask[p]] : 0xFFFFFFFFu;
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
