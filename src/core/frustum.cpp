// View-frustum cull kernels: plane extraction and the scalar reference kernels
// (patchcull/core/frustum.h). The SIMD kernels live in frustum_simd.cpp.
//
// Bit-exact agreement with the SIMD kernels (tests/core/frustum_test.cpp) rests on three rules
// that both files follow operation by operation:
// - every multiply-add the SIMD code does with MulAdd is std::fma here (one rounding); every
//   other product and sum is a separate, individually rounded operation (the build passes
//   -ffp-contract=off: GCC would otherwise contract a*b+c on its own, even in ISO C++ mode);
// - min/max are written as `a < b ? a : b` / `a > b ? a : b`, which is what x86 minps/maxps
//   (Highway Min/Max) return for every input, signed zeros included;
// - the same order of accumulation (points 0..15, planes 0..5, corners in the same order).
// Decisions only look at the sign of the final values (< 0), so they are identical.
#include "patchcull/core/frustum.h"

#include <cmath>
#include <limits>

// The reference uses std::fma. Compiled for the x86-64 baseline that is a call into libm per
// multiply-add, which would make the reference look ~10x slower than it is. On GCC/Clang for
// x86-64 a second clone of each scalar kernel is compiled with FMA enabled (std::fma becomes one
// vfmadd instruction) and picked once at load time (ifunc). Results are identical by definition:
// fma is exactly rounded either way.
#include "core/frustum_box_internal.h"
#include "core/scalar_clones.h"

namespace patchcull {
FrustumPlanes make_frustum_planes(const Mat4& any_object_to_clip, ClipDepth depth) {
    check_clip_depth(any_object_to_clip, depth, "make_frustum_planes");
    const Mat4 object_to_clip = to_depth_key(any_object_to_clip, depth);
    const Vec4 x = object_to_clip.row(0);
    const Vec4 y = object_to_clip.row(1);
    const Vec4 k = object_to_clip.row(2);
    const Vec4 w = object_to_clip.row(3);
    FrustumPlanes planes;
    planes.depth = depth;
    planes.near_w = is_reversed(depth) ? 1.0f : 0.0f;
    planes.far_w = is_reversed(depth) ? 0.0f : 1.0f;
    planes.far_limit = has_far_plane(depth) ? 0.0f : -std::numeric_limits<float>::infinity();
    planes.rows[0] = w + x;                                              // left:   w + x >= 0
    planes.rows[1] = w - x;                                              // right:  w - x >= 0
    planes.rows[2] = w + y;                                              // bottom: w + y >= 0
    planes.rows[3] = w - y;                                              // top:    w - y >= 0
    planes.rows[4] = is_reversed(depth) ? k + w : k;                     // near: z >= 0, or w - z >= 0 (reversed)
    planes.rows[5] = is_reversed(depth) ? Vec4{0, 0, 0, 0} - k : w - k;  // far: w - z >= 0, or z >= 0
    if (!has_far_plane(depth)) planes.rows[5] = Vec4{0, 0, 0, 1};        // at infinity: every point passes
    planes.clip_rows[0] = x;
    planes.clip_rows[1] = y;
    planes.clip_rows[2] = k;
    planes.clip_rows[3] = w;
    for (int q = 0; q < 6; ++q) {
        const Vec4 r = planes.rows[q];
        const double xx = r.x, yy = r.y, zz = r.z;
        planes.normal_length[q] = static_cast<float>(std::sqrt(xx * xx + yy * yy + zz * zz));
    }
    return planes;
}

// frustum: culled when, for some plane q, every control point P_k has a plane value below 0
// (frustum_plane_values, frustum.h: clip coordinates once, then w +- x, w +- y, z, w - z; with
// margins, add_frustum_margins). The SIMD kernel does exactly these operations.
PATCHCULL_SCALAR_CLONES
void cull_frustum_scalar(const PatchBatchView& patches, const float* max_displacement, const FrustumPlanes& planes,
                         std::uint8_t* culled) {
    for (std::size_t p = 0; p < patches.count; ++p) {
        FrustumVerdict verdict;
        float v[6];
        for (int k = 0; k < kPatchPoints; ++k) {
            const float W = patches.at(p, k, 3);
            frustum_plane_values(planes, patches.at(p, k, 0), patches.at(p, k, 1), patches.at(p, k, 2), W, v);
            if (max_displacement) add_frustum_margins(planes, max_displacement[p], W, v);
            verdict.add(v);
        }
        culled[p] = verdict.culled(planes) ? 1 : 0;
    }
}

// frustum-disp: AABB of the Cartesian control points (X/W, Y/W, Z/W, exact IEEE division),
// grown by D on every side; the 8 corners go to clip space (the depth-key matrix of
// make_frustum_planes) with
//   clip_r = fma(m(r,0), x, fma(m(r,1), y, fma(m(r,2), z, m(r,3))))
// and the patch is culled when all 8 corners fail the same clip-plane inequality (plane values as
// frustum_plane_values forms them) and its probe over the raw coordinates X, Y, Z, W is still 0.
PATCHCULL_SCALAR_CLONES
void cull_frustum_disp_scalar(const PatchBatchView& patches, const float* max_displacement, const Mat4& object_to_clip,
                              ClipDepth depth, std::uint8_t* culled) {
    const FrustumPlanes planes = make_frustum_planes(object_to_clip, depth);
    for (std::size_t p = 0; p < patches.count; ++p) {
        const float d = max_displacement ? max_displacement[p] : 0.0f;
        const auto point_at = [&patches, p](int k, int a) { return patches.at(p, k, a); };
        culled[p] = frustum_detail::box_outside_frustum(planes, kPatchPoints, d, point_at) ? 1 : 0;
    }
}

}  // namespace patchcull
