// patchcull/patch.h: bicubic Bezier patches, their evaluation and 1-to-4 split, and the
// structure-of-arrays batches the cull kernels read.
//
// Control point (i, j) of a patch, i along u and j along v, is cp[4*j + i]; B(u,v) =
// sum_ij B_i(u) B_j(v) cp[4*j+i] with cubic Bernstein polynomials B_i. Control points are
// homogeneous (w*x, w*y, w*z, w): a polynomial patch has w = 1 everywhere, a rational patch has
// positive weights w (seed 001 §3 allows rational patches; the kernels assume w > 0).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "patchcull/math.h"

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

/// Structure-of-arrays patches: component c (0..3 = x,y,z,w) of control point k of patch p is
/// data[(4*k + c) * stride + p]. stride is a multiple of kBatchAlignment and >= count, so SIMD
/// kernels may load whole vectors past count (padding is zero).
struct PatchBatchView {
    const float* data = nullptr;
    std::size_t count = 0;
    std::size_t stride = 0;

    const float* component(int point, int c) const { return data + (4 * point + c) * stride; }
    /// Patches [first, first + n) of this view (same stride).
    PatchBatchView subrange(std::size_t first, std::size_t n) const { return {data + first, n, stride}; }
};

inline constexpr std::size_t kBatchAlignment = 16;  ///< floats; covers AVX-512 lanes

/// Owning structure-of-arrays patch batch (see PatchBatchView for the layout).
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

    void set(std::size_t index, const BezierPatch& patch);
    BezierPatch get(std::size_t index) const;
    PatchBatchView view() const { return {data_.data(), count_, stride_}; }

private:
    std::vector<float> data_;
    std::size_t count_ = 0;
    std::size_t stride_ = 0;
};

/// Builds a batch from an array of patches.
PatchBatch make_batch(const std::vector<BezierPatch>& patches);

}  // namespace patchcull
