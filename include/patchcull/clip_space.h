// patchcull/clip_space.h: the clip-space depth convention, made explicit.
//
// patchcull's kernels work in one clip space (math.h): GL with glClipControl(GL_LOWER_LEFT,
// GL_ZERO_TO_ONE), inside = -w <= x, y <= w and 0 <= z <= w (also Direct3D's and Vulkan's). A
// standard OpenGL projection (glFrustum, gluPerspective, glm::perspective without
// GLM_FORCE_DEPTH_ZERO_TO_ONE) maps depth to -w <= z <= w instead. No test on a matrix can tell
// the two apart: read in the other convention, an OpenGL projection is a valid frustum whose
// near plane lies at 2fn/(f+n), about twice as far as meant, so kernels that assumed the wrong
// one culled everything in front of that plane, silently (1146 of BigGuy's 1450 visible
// patches in one view). So every public entry whose decision depends on clip depth takes a
// ClipDepth argument with no default (make_frustum_planes, the frustum-disp and Hi-Z kernels,
// make_displaced_cull_view) and converts with to_zero_to_one; the caller has to say which
// convention its matrix uses.
//
// Convention-free entries take no ClipDepth: tcone/ncone (eye point only) and ptp (rows x, y and
// w of object_to_clip and the sign of the eye's clip z, the same in both conventions:
// backpatch.h). The OpenGL renderer (gl_renderer.h) draws with GL_ZERO_TO_ONE itself, so its
// RenderParams::projection must be a zero_to_one matrix (convert other ones first).
#pragma once

#include "patchcull/math.h"

namespace patchcull {

enum class ClipDepth {
    zero_to_one,       ///< 0 <= z <= w (patchcull's own, GL_ZERO_TO_ONE, Direct3D, Vulkan)
    minus_one_to_one,  ///< -w <= z <= w (OpenGL's default, glFrustum, gluPerspective)
};

/// "zero-to-one", "minus-one-to-one".
const char* clip_depth_name(ClipDepth depth);

/// The same matrix in zero_to_one form: rows x, y, w unchanged, row z replaced by (z + w) / 2
/// for minus_one_to_one (depth d in [-1, 1] becomes (d + 1) / 2, what glDepthRange(0, 1) writes
/// to the depth buffer, so Hi-Z pyramids of either kind of depth buffer match). Same camera,
/// same clip volume: the x, y and far planes (w - z' = (w - z) / 2) are unchanged up to a
/// positive factor, and the near plane z + w >= 0 becomes z' >= 0. One rounding per element.
Mat4 to_zero_to_one(const Mat4& object_to_clip, ClipDepth depth);

/// perspective() (math.h) in either convention: depth -1 (minus_one_to_one) or 0 at z_near, 1
/// at z_far. perspective(f, a, n, far) is perspective(f, a, n, far, ClipDepth::zero_to_one).
Mat4 perspective(float fovy_radians, float aspect, float z_near, float z_far, ClipDepth depth);

}  // namespace patchcull
