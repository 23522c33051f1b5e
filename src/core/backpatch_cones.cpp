// Back-patch cull kernels tcone and ncone, scalar reference (patchcull/core/backpatch.h). Per patch:
// rational (any w != 1) -> not culled; else the cone (TCONE: Sederberg & Meyers from the tangent
// and bitangent control vectors; NCONE: the 36 control vectors of the normal patch), the
// control-point sphere and the perspective back-facing test, all from cones_internal.h (formulas
// and derivations in cones.cpp). backpatch_cones_simd.cpp repeats this operation by operation.
#include <cstddef>
#include <cstdint>

#include "core/cones_internal.h"
#include "patchcull/core/backpatch.h"

// std::fma is a libm call on the x86-64 baseline: as in frustum.cpp, an FMA clone of each scalar
// kernel is compiled and picked once at load time (results are identical, fma is exactly rounded
// either way). The cone functions are always_inline, so they are compiled into each clone.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(__SANITIZE_ADDRESS__)
#define PATCHCULL_CONES_CLONES __attribute__((target_clones("fma", "default")))
#else
#define PATCHCULL_CONES_CLONES
#endif

namespace patchcull {
namespace {

PATCHCULL_CONES_INLINE BezierPatch load_patch(const PatchBatchView& v, std::size_t p) {
    BezierPatch patch;
    for (int k = 0; k < kPatchPoints; ++k) patch.cp[k] = {v.at(p, k, 0), v.at(p, k, 1), v.at(p, k, 2), v.at(p, k, 3)};
    return patch;
}

}  // namespace

PATCHCULL_CONES_CLONES
void cull_tcone_scalar(const PatchBatchView& patches, Vec3 eye, std::uint8_t* culled) {
    for (std::size_t p = 0; p < patches.count; ++p) {
        const BezierPatch patch = load_patch(patches, p);
        const NormalCone cone = cones_detail::tangent_cone_polynomial(patch);
        const PatchSphere sphere = cones_detail::sphere_of_points<false>(patch);
        const bool out = cones_detail::is_polynomial(patch) && cones_detail::back_facing(cone, sphere, eye);
        culled[p] = out ? 1 : 0;
    }
}

PATCHCULL_CONES_CLONES
void cull_ncone_scalar(const PatchBatchView& patches, Vec3 eye, std::uint8_t* culled) {
    for (std::size_t p = 0; p < patches.count; ++p) {
        const BezierPatch patch = load_patch(patches, p);
        const NormalCone cone = cones_detail::normal_cone_polynomial(patch);
        const PatchSphere sphere = cones_detail::sphere_of_points<false>(patch);
        const bool out = cones_detail::is_polynomial(patch) && cones_detail::back_facing(cone, sphere, eye);
        culled[p] = out ? 1 : 0;
    }
}

}  // namespace patchcull
