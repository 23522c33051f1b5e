// make_cull_view (patchcull/core/cull_view.h).
#include "patchcull/core/cull_view.h"

#include <cmath>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/fused_cull.h"
#include "patchcull/core/hiz.h"

namespace patchcull {

CullView make_cull_view(const Mat4& view, const Mat4& projection, ClipDepth depth) {
    CullView v;
    v.view = view;
    v.projection = projection;
    v.depth = depth;
    v.object_to_clip = projection * view;
    v.planes = make_frustum_planes(v.object_to_clip, depth);
    Mat4 inverse;
    if (invert(view, inverse)) {
        const Vec4 e = inverse * Vec4{0, 0, 0, 1};
        const Vec3 eye = cartesian(e);
        v.has_eye = e.w != 0.0f && std::isfinite(eye.x) && std::isfinite(eye.y) && std::isfinite(eye.z);
        if (v.has_eye) v.eye = eye;
    }
    v.alpha = clip_space_eye_alpha(projection);
    v.orientation = ptp_orientation_sign(v.object_to_clip, v.alpha);
    return v;
}

CullView make_cull_view(const Mat4& view, const Mat4& projection, ClipDepth depth, Vec3 eye) {
    CullView v = make_cull_view(view, projection, depth);
    v.eye = eye;
    v.has_eye = std::isfinite(eye.x) && std::isfinite(eye.y) && std::isfinite(eye.z);
    return v;
}

// The kernels' CullView entry points (declared in their own headers).
void cull_frustum(const PatchBatchView& patches, const float* max_displacement, const CullView& view,
                  std::uint8_t* culled) {
    cull_frustum_simd(patches, max_displacement, view.planes, culled);
}
void cull_frustum_disp(const PatchBatchView& patches, const float* max_displacement, const CullView& view,
                       std::uint8_t* culled) {
    cull_frustum_disp_simd(patches, max_displacement, view.object_to_clip, view.depth, culled);
}
void cull_occlusion(const PatchBatchView& patches, const CullView& view, const HiZPyramid& hiz,
                    std::uint8_t* decision) {
    cull_occlusion_simd(patches, view.object_to_clip, view.depth, hiz, decision);
}
FusedCullSetup make_fused_setup(const CullView& view, BackPatchCone cone, const HiZPyramid* hiz) {
    return make_fused_setup(view.object_to_clip, view.depth, view.eye, cone, hiz);
}
DisplacedCullView make_displaced_cull_view(const CullView& view) {
    return make_displaced_cull_view(view.view, view.projection, view.depth);
}

}  // namespace patchcull
