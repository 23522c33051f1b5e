// patchcull/core/patch.h: bicubic Bezier patches, their evaluation and 1-to-4 split, and the
// batches the cull kernels read (plain structure of arrays, or blocked in 16-patch blocks).
//
// Control point (i, j) of a patch, i along u and j along v, is cp[4*j + i]; B(u,v) =
// sum_ij B_i(u) B_j(v) cp[4*j+i] with cubic Bernstein polynomials B_i. Control points are
// homogeneous (w*x, w*y, w*z, w): a polynomial patch has w = 1 everywhere, a rational patch has
// positive weights w (Loop, Niessner and Eisenacher allow rational patches). Weights must be positive: the cull
// tests rest on the convex hull of the homogeneous control points, which holds only when every
// weight has the same sign, and test it for positive ones. PatchBatch, PatchBlocks and the GL
// renderer's uploads refuse a weight <= 0 (check_patch_weights: Error naming the patch and point);
// a patch whose weights are all negative is the same surface with every coordinate negated, so
// negate it first. Views over the caller's own memory (PatchBatchView, the GPU passes' buffers)
// are not checked: their contract is the same. A NaN or infinite coordinate (weights included) is
// accepted and never culled by any kernel or pass.
#pragma once

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "patchcull/core/math.h"

namespace patchcull {

inline constexpr int kPatchPoints = 16;

struct BezierPatch {
    Vec4 cp[kPatchPoints];
};

/// ACC tangent patches of an extraordinary patch (Loop & Schaefer 2008): du is a Bezier patch of
/// degree 2 in u and 3 in v, du[3*j + i] (i < 3, j < 4); dv has degree 3 in u and 2 in v,
/// dv[4*j + i] (i < 4, j < 3). Their cross product gives the patch's continuous normal field.
/// Points are Cartesian vectors (derivatives of a polynomial patch).
struct TangentPatches {
    Vec3 du[12];
    Vec3 dv[12];
};

/// Position, partial derivatives and (unnormalized) normal of a patch at (u, v).
struct SurfacePoint {
    Vec3 position;
    Vec3 du, dv;
    Vec3 normal;  ///< du x dv (outward for counter-clockwise faces); may be zero at degenerate points.
};

/// Cartesian position of patch at (u, v) in [0,1]^2.
Vec3 evaluate_position(const BezierPatch& patch, float u, float v);

/// Homogeneous position of patch at (u, v): the polynomial numerator and weight.
Vec4 evaluate_homogeneous(const BezierPatch& patch, float u, float v);

/// Position and Cartesian partial derivatives (quotient rule for rational patches).
SurfacePoint evaluate_surface(const BezierPatch& patch, float u, float v);

/// Normal du x dv from ACC tangent patches at (u, v).
Vec3 evaluate_tangent_normal(const TangentPatches& tangents, float u, float v);

/// Splits patch at u = v = 1/2 into four patches, written to out[0..3] in the order
/// (u low, v low), (u high, v low), (u low, v high), (u high, v high). Exact (de Casteljau in
/// homogeneous space), so the four children cover the parent exactly.
void split_patch(const BezierPatch& patch, BezierPatch out[4]);

/// Splits tangent patches the same way; derivatives are rescaled to the child's parameters.
void split_tangents(const TangentPatches& tangents, TangentPatches out[4]);

inline constexpr std::size_t kBatchAlignment = 16;  ///< floats; covers AVX-512 lanes

/// Patches per block of the blocked layout (see PatchBatchView). Every x86 SIMD width Highway
/// targets (4, 8 or 16 float lanes) divides it, so a SIMD group never straddles two blocks.
inline constexpr std::size_t kBlockPatches = 16;
/// Floats in one full block: 16 points x 4 components x kBlockPatches lanes (4 KiB).
inline constexpr std::size_t kBlockFloats = 4 * kPatchPoints * kBlockPatches;

/// A batch of patches as the cull kernels read it, in one of two layouts:
///
/// - plain structure of arrays (block_stride == 0, what PatchBatch holds): component c
///   (0..3 = x,y,z,w) of control point k of patch p is data[(4*k + c) * stride + p]. stride is a
///   multiple of kBatchAlignment and >= count, so SIMD kernels may load whole vectors past count
///   (padding is zero). A group of 16 patches touches 64 arrays a whole stride apart: 64 memory
///   streams, more than the hardware prefetchers follow, so large plain batches run far below the
///   memory bandwidth (docs/PERFORMANCE.md, "Batches at the memory roof").
/// - blocked, "array of structures of arrays" (block_stride != 0, what PatchBlocks holds): patches
///   in blocks of kBlockPatches; block b starts at data + b * block_stride and, inside it,
///   component (k, c) of lane j (patch b * kBlockPatches + j) is at (4*k + c) * stride + j, with
///   stride == kBlockPatches. block_stride >= kBlockFloats (== packs the blocks). A block is one
///   contiguous 4 KiB run, so a kernel reads one sequential stream. The last block is padded to
///   kBlockPatches lanes (PatchBlocks zeroes the padding).
///
/// at() reads either layout; component() is the plain layout's array and must not be called on a
/// blocked view. Kernels outside src/core (GL upload, evaluation, posing) take plain views only.
struct PatchBatchView {
    const float* data = nullptr;
    std::size_t count = 0;
    std::size_t stride = 0;
    std::size_t block_stride = 0;  ///< 0: plain SoA; else blocked (see above)

    bool blocked() const { return block_stride != 0; }

    /// Component c of control point `point` of every patch: plain views only (block_stride == 0).
    const float* component(int point, int c) const {
        assert(block_stride == 0 && "component() on a blocked view: use at()");
        return data + (4 * point + c) * stride;
    }

    /// Component c of control point k of patch p (p < count), in either layout.
    float at(std::size_t p, int k, int c) const {
        const std::size_t a = static_cast<std::size_t>(4 * k + c) * stride;
        if (block_stride == 0) return data[a + p];
        return data[(p / kBlockPatches) * block_stride + a + p % kBlockPatches];
    }

    /// Patches [first, first + n) of this view (same layout and strides). For a blocked view first
    /// must be a multiple of kBlockPatches (asserted in debug builds): a view starts at a block.
    PatchBatchView subrange(std::size_t first, std::size_t n) const {
        if (block_stride == 0) return {data + first, n, stride, 0};
        assert(first % kBlockPatches == 0 && "blocked subrange must start at a block");
        return {data + first / kBlockPatches * block_stride, n, stride, block_stride};
    }
};

namespace detail {
/// Batch storage: 64-byte (cache line) aligned, so each SoA array and each block starts on a line
/// and a 16-lane group reads exactly one line per component; from 4 MiB on, 2 MiB aligned and
/// backed by transparent huge pages where the OS offers them (Linux madvise), so streaming a large
/// batch does not walk a page table every 4 KiB (a nested walk under a hypervisor).
void* allocate_batch_storage(std::size_t bytes);
void free_batch_storage(void* p, std::size_t bytes);

template <class T>
struct CacheAlignedAllocator {
    using value_type = T;
    CacheAlignedAllocator() = default;
    template <class U>
    CacheAlignedAllocator(const CacheAlignedAllocator<U>&) {}
    T* allocate(std::size_t n) { return static_cast<T*>(allocate_batch_storage(n * sizeof(T))); }
    void deallocate(T* p, std::size_t n) { free_batch_storage(p, n * sizeof(T)); }
    template <class U>
    bool operator==(const CacheAlignedAllocator<U>&) const {
        return true;
    }
};
using AlignedFloats = std::vector<float, CacheAlignedAllocator<float>>;
}  // namespace detail

/// Owning plain structure-of-arrays patch batch (see PatchBatchView for the layout). Storage is
/// 64-byte aligned.
class PatchBatch {
public:
    PatchBatch() = default;
    explicit PatchBatch(std::size_t count) { resize(count); }

    /// Sets the patch count; contents are zeroed.
    void resize(std::size_t count);
    std::size_t size() const { return count_; }
    std::size_t stride() const { return stride_; }

    float* component(int point, int c) { return data_.data() + (4 * point + c) * stride_; }
    const float* component(int point, int c) const { return data_.data() + (4 * point + c) * stride_; }

    /// Writes patch index; throws Error for a weight <= 0 (check_patch_weights).
    void set(std::size_t index, const BezierPatch& patch);
    BezierPatch get(std::size_t index) const;
    PatchBatchView view() const { return {data_.data(), count_, stride_, 0}; }

private:
    detail::AlignedFloats data_;
    std::size_t count_ = 0;
    std::size_t stride_ = 0;
};

/// Owning blocked patch batch (the blocked layout of PatchBatchView, blocks packed:
/// block_stride == kBlockFloats). Storage is 64-byte aligned; ceil(count / kBlockPatches) blocks,
/// the last one's unused lanes zero. Same interface as PatchBatch, plus a copy of any view.
class PatchBlocks {
public:
    PatchBlocks() = default;
    explicit PatchBlocks(std::size_t count) { resize(count); }
    /// A blocked copy of `patches` (either layout), patch for patch.
    explicit PatchBlocks(const PatchBatchView& patches);

    /// Sets the patch count; contents are zeroed.
    void resize(std::size_t count);
    std::size_t size() const { return count_; }
    std::size_t blocks() const { return (count_ + kBlockPatches - 1) / kBlockPatches; }

    void set(std::size_t index, const BezierPatch& patch);
    BezierPatch get(std::size_t index) const;
    PatchBatchView view() const { return {data_.data(), count_, kBlockPatches, kBlockFloats}; }

private:
    detail::AlignedFloats data_;
    std::size_t count_ = 0;
};

/// Patch p of a view (either layout).
BezierPatch get_patch(const PatchBatchView& patches, std::size_t p);

/// Process-wide software prefetch distances of the memory-bound SIMD kernels (those whose groups
/// go through simd_groups' ForEachGroup with prefetching: frustum, frustum-disp), in patches ahead
/// of the group being read; 0 = off. Plain views: the 64 lines (one per component array) of the
/// patch `distance` ahead, every 16 patches; default kDefaultPlainPrefetch. Blocked views: the
/// head (8 lines) of the block holding the patch `distance` ahead, once per block; default
/// kDefaultBlockedPrefetch. The hardware prefetchers follow neither: 64 streams are more than
/// they track, and they stop at each 4 KiB page, which is one block. Read once per kernel call;
/// thread-safe (relaxed atomics). Meant for benchmarks; the defaults are the distances measured
/// in docs/PERFORMANCE.md, "Batches at the memory roof".
inline constexpr std::size_t kDefaultPlainPrefetch = 128;
inline constexpr std::size_t kDefaultBlockedPrefetch = 2 * kBlockPatches;
void set_plain_prefetch_distance(std::size_t patches);
std::size_t plain_prefetch_distance();
void set_blocked_prefetch_distance(std::size_t patches);
std::size_t blocked_prefetch_distance();

/// Throws Error("patch <index>: control point k has weight w; weights must be positive ...") when
/// a weight of patch is <= 0 (NaN and +Inf pass: the kernels never cull them).
void check_patch_weights(const BezierPatch& patch, std::size_t index);

/// Builds a batch from an array of patches (check_patch_weights on each), in the plain layout.
/// The layout is the caller's choice, measured (docs/PERFORMANCE.md, "The parallel entries at three
/// sizes" and "Batches at the memory roof"): at 1450 patches both run alike; beyond the L2 the
/// blocked layout (PatchBlocks) is faster for every kernel on an AMD EPYC with AVX2 (one thread,
/// 65536 / 1M patches: frustum 2.2x / 3.1x, tcone 1.5x / 2.3x, occlusion 1.5x / 2.0x, fused
/// 1.6x / 2.1x), and for the memory-bound frustum kernels on a Sapphire Rapids with AVX-512
/// (1.6x / 1.2x; the compute-bound kernels there gained nothing). Copy a large batch to
/// PatchBlocks once when it is culled every frame.
PatchBatch make_batch(const std::vector<BezierPatch>& patches);

/// A plain copy of `patches` (either layout), patch for patch.
PatchBatch copy_to_batch(const PatchBatchView& patches);

}  // namespace patchcull
