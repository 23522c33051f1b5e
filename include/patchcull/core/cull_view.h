// patchcull/core/cull_view.h: everything a cull test needs from one view, made once per view
// and taken by the kernels' registry (backpatch_methods.h), the evaluation and the GPU passes.
#pragma once

#include "patchcull/core/clip_space.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/math.h"

namespace patchcull {

/// One view of the patches (object space = the space of the control points).
struct CullView {
    Mat4 view;                                 ///< object -> view (look_at, times any model matrix)
    Mat4 projection;                           ///< view -> clip, written in `depth`
    ClipDepth depth = ClipDepth::zero_to_one;  ///< the depth convention of projection (clip_space.h)
    Mat4 object_to_clip;                       ///< projection * view
    FrustumPlanes planes;                      ///< make_frustum_planes(object_to_clip, depth)
    /// The eye in object space (the inverse view's translation); (0, 0, 0) when the view is
    /// singular, and then has_eye is false and no test that needs the eye may cull.
    Vec3 eye{0, 0, 0};
    bool has_eye = false;
    float alpha = 0;  ///< clip_space_eye_alpha(projection): the eye's clip-space z (backpatch.h)
    /// ptp_orientation_sign(object_to_clip, alpha): -1 or 1, or 0 when ptp may cull nothing.
    int orientation = 0;
};

/// Makes the view's value. Throws Error when projection contradicts depth (check_clip_depth).
CullView make_cull_view(const Mat4& view, const Mat4& projection, ClipDepth depth);
/// The same with the eye given (e.g. Camera::eye, where the view was placed), used as it is
/// instead of the inverse view's translation, which equals it up to rounding.
CullView make_cull_view(const Mat4& view, const Mat4& projection, ClipDepth depth, Vec3 eye);

}  // namespace patchcull
