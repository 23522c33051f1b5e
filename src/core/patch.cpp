// Bezier patch evaluation, de Casteljau split, plain (SoA) and blocked batches (patchcull/core/patch.h).
#include "patchcull/core/patch.h"

#include <cstdio>
#include <string>

#include "patchcull/core/error.h"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace patchcull {
namespace {

void bernstein3(float t, float b[4]) {
    const float s = 1 - t;
    b[0] = s * s * s;
    b[1] = 3 * t * s * s;
    b[2] = 3 * t * t * s;
    b[3] = t * t * t;
}

// Derivatives of the cubic Bernstein basis.
void bernstein3_derivative(float t, float d[4]) {
    const float s = 1 - t;
    d[0] = -3 * s * s;
    d[1] = 3 * s * s - 6 * t * s;
    d[2] = 6 * t * s - 3 * t * t;
    d[3] = 3 * t * t;
}

void bernstein2(float t, float b[3]) {
    const float s = 1 - t;
    b[0] = s * s;
    b[1] = 2 * t * s;
    b[2] = t * t;
}

// One de Casteljau halving of a curve of degree n (n+1 points, given with a stride) in place:
// writes the left half to left[] and the right half to right[].
template <typename P>
void halve_curve(const P* points, int n, int stride, P* left, P* right, int out_stride) {
    P tmp[4];
    for (int i = 0; i <= n; ++i) tmp[i] = points[i * stride];
    left[0] = tmp[0];
    right[n * out_stride] = tmp[n];
    for (int level = 1; level <= n; ++level) {
        for (int i = 0; i <= n - level; ++i) tmp[i] = (tmp[i] + tmp[i + 1]) * 0.5f;
        left[level * out_stride] = tmp[0];
        right[(n - level) * out_stride] = tmp[n - level];
    }
}

// Splits a tensor-product patch of degree (nu, nv), points[(nu+1)*j + i], into four children.
template <typename P>
void split_tensor(const P* points, int nu, int nv, P* out[4]) {
    const int cu = nu + 1;
    P low_u[16], high_u[16];
    for (int j = 0; j <= nv; ++j) halve_curve(points + cu * j, nu, 1, low_u + cu * j, high_u + cu * j, 1);
    for (int i = 0; i <= nu; ++i) {
        halve_curve(low_u + i, nv, cu, out[0] + i, out[2] + i, cu);
        halve_curve(high_u + i, nv, cu, out[1] + i, out[3] + i, cu);
    }
}

}  // namespace

Vec4 evaluate_homogeneous(const BezierPatch& patch, float u, float v) {
    float bu[4], bv[4];
    bernstein3(u, bu);
    bernstein3(v, bv);
    Vec4 p{};
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) p += patch.cp[4 * j + i] * (bu[i] * bv[j]);
    return p;
}

Vec3 evaluate_position(const BezierPatch& patch, float u, float v) {
    return cartesian(evaluate_homogeneous(patch, u, v));
}

SurfacePoint evaluate_surface(const BezierPatch& patch, float u, float v) {
    float bu[4], bv[4], du[4], dv[4];
    bernstein3(u, bu);
    bernstein3(v, bv);
    bernstein3_derivative(u, du);
    bernstein3_derivative(v, dv);
    Vec4 p{}, pu{}, pv{};
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            const Vec4 c = patch.cp[4 * j + i];
            p += c * (bu[i] * bv[j]);
            pu += c * (du[i] * bv[j]);
            pv += c * (bu[i] * dv[j]);
        }
    SurfacePoint s;
    s.position = cartesian(p);
    // Quotient rule: d(P/w) = (dP - (dw) P/w) / w.
    const float inv_w = 1.0f / p.w;
    s.du = (xyz(pu) - s.position * pu.w) * inv_w;
    s.dv = (xyz(pv) - s.position * pv.w) * inv_w;
    s.normal = cross(s.du, s.dv);
    return s;
}

Vec3 evaluate_tangent_normal(const TangentPatches& t, float u, float v) {
    float b2u[3], b3u[4], b2v[3], b3v[4];
    bernstein2(u, b2u);
    bernstein3(u, b3u);
    bernstein2(v, b2v);
    bernstein3(v, b3v);
    Vec3 du{}, dv{};
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 3; ++i) du += t.du[3 * j + i] * (b2u[i] * b3v[j]);
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 4; ++i) dv += t.dv[4 * j + i] * (b3u[i] * b2v[j]);
    return cross(du, dv);
}

void split_patch(const BezierPatch& patch, BezierPatch out[4]) {
    Vec4* children[4] = {out[0].cp, out[1].cp, out[2].cp, out[3].cp};
    split_tensor(patch.cp, 3, 3, children);
}

void split_tangents(const TangentPatches& t, TangentPatches out[4]) {
    Vec3* du_children[4] = {out[0].du, out[1].du, out[2].du, out[3].du};
    Vec3* dv_children[4] = {out[0].dv, out[1].dv, out[2].dv, out[3].dv};
    split_tensor(t.du, 2, 3, du_children);
    split_tensor(t.dv, 3, 2, dv_children);
    // A child's parameter runs twice as fast as the parent's: d/du_child = 0.5 d/du_parent.
    for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 12; ++k) {
            out[c].du[k] = out[c].du[k] * 0.5f;
            out[c].dv[k] = out[c].dv[k] * 0.5f;
        }
}

void PatchBatch::resize(std::size_t count) {
    count_ = count;
    stride_ = std::max<std::size_t>(kBatchAlignment, (count + kBatchAlignment - 1) / kBatchAlignment * kBatchAlignment);
    data_.assign(stride_ * 4 * kPatchPoints, 0.0f);
}

void check_patch_weights(const BezierPatch& patch, std::size_t index) {
    for (int k = 0; k < kPatchPoints; ++k) {
        if (!(patch.cp[k].w <= 0.0f)) continue;  // positive, or NaN / +Inf (never culled: frustum.h)
        char weight[32];
        std::snprintf(weight, sizeof weight, "%g", static_cast<double>(patch.cp[k].w));
        throw Error("patch " + std::to_string(index) + ": control point " + std::to_string(k) + " has weight " +
                    weight +
                    "; weights must be positive (negate every coordinate of a patch whose weights "
                    "are all negative: the same surface)");
    }
}

void PatchBatch::set(std::size_t index, const BezierPatch& patch) {
    check_patch_weights(patch, index);
    for (int k = 0; k < kPatchPoints; ++k) {
        component(k, 0)[index] = patch.cp[k].x;
        component(k, 1)[index] = patch.cp[k].y;
        component(k, 2)[index] = patch.cp[k].z;
        component(k, 3)[index] = patch.cp[k].w;
    }
}

BezierPatch PatchBatch::get(std::size_t index) const {
    BezierPatch p;
    for (int k = 0; k < kPatchPoints; ++k)
        p.cp[k] = {component(k, 0)[index], component(k, 1)[index], component(k, 2)[index], component(k, 3)[index]};
    return p;
}

PatchBatch make_batch(const std::vector<BezierPatch>& patches) {
    PatchBatch batch(patches.size());
    for (std::size_t i = 0; i < patches.size(); ++i) batch.set(i, patches[i]);
    return batch;
}

PatchBatch copy_to_batch(const PatchBatchView& patches) {
    PatchBatch batch(patches.count);
    for (std::size_t i = 0; i < patches.count; ++i) batch.set(i, get_patch(patches, i));
    return batch;
}

BezierPatch get_patch(const PatchBatchView& v, std::size_t p) {
    BezierPatch patch;
    for (int k = 0; k < kPatchPoints; ++k) patch.cp[k] = {v.at(p, k, 0), v.at(p, k, 1), v.at(p, k, 2), v.at(p, k, 3)};
    return patch;
}

// ---- blocked batches ---------------------------------------------------------------------------

PatchBlocks::PatchBlocks(const PatchBatchView& patches) {
    resize(patches.count);
    for (std::size_t p = 0; p < patches.count; ++p) {
        check_patch_weights(get_patch(patches, p), p);
        float* lane = data_.data() + (p / kBlockPatches) * kBlockFloats + p % kBlockPatches;
        for (int a = 0; a < 4 * kPatchPoints; ++a) lane[a * kBlockPatches] = patches.at(p, a / 4, a % 4);
    }
}

void PatchBlocks::resize(std::size_t count) {
    count_ = count;
    data_.assign(blocks() * kBlockFloats, 0.0f);
}

void PatchBlocks::set(std::size_t index, const BezierPatch& patch) {
    check_patch_weights(patch, index);
    float* lane = data_.data() + (index / kBlockPatches) * kBlockFloats + index % kBlockPatches;
    for (int k = 0; k < kPatchPoints; ++k) {
        lane[(4 * k + 0) * kBlockPatches] = patch.cp[k].x;
        lane[(4 * k + 1) * kBlockPatches] = patch.cp[k].y;
        lane[(4 * k + 2) * kBlockPatches] = patch.cp[k].z;
        lane[(4 * k + 3) * kBlockPatches] = patch.cp[k].w;
    }
}

BezierPatch PatchBlocks::get(std::size_t index) const { return get_patch(view(), index); }

// ---- storage -----------------------------------------------------------------------------------

namespace detail {
namespace {
constexpr std::size_t kHugePage = std::size_t{2} << 20;
constexpr std::size_t kHugeFrom = std::size_t{4} << 20;
}  // namespace

void* allocate_batch_storage(std::size_t bytes) {
    if (bytes < kHugeFrom) return ::operator new (bytes, std::align_val_t{64});
    const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* p = std::aligned_alloc(kHugePage, rounded);
    if (!p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    madvise(p, rounded, MADV_HUGEPAGE);  // a hint: without THP the pages stay 4 KiB
#endif
    return p;
}

void free_batch_storage(void* p, std::size_t bytes) {
    if (bytes < kHugeFrom)
        ::operator delete (p, std::align_val_t{64});
    else
        std::free(p);
}
}  // namespace detail

// ---- prefetch distances ------------------------------------------------------------------------

namespace {
std::atomic<std::size_t> g_plain_prefetch{kDefaultPlainPrefetch};
std::atomic<std::size_t> g_blocked_prefetch{kDefaultBlockedPrefetch};
}  // namespace

void set_plain_prefetch_distance(std::size_t patches) { g_plain_prefetch.store(patches, std::memory_order_relaxed); }
std::size_t plain_prefetch_distance() { return g_plain_prefetch.load(std::memory_order_relaxed); }
void set_blocked_prefetch_distance(std::size_t patches) {
    g_blocked_prefetch.store(patches, std::memory_order_relaxed);
}
std::size_t blocked_prefetch_distance() { return g_blocked_prefetch.load(std::memory_order_relaxed); }

}  // namespace patchcull
