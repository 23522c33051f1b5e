// patchcull/core/clip_space.h: the clip-space depth convention, made explicit.
//
// patchcull's kernels work in one clip space (math.h): GL with glClipControl(GL_LOWER_LEFT,
// GL_ZERO_TO_ONE), inside = -w <= x, y <= w and 0 <= z <= w (also Direct3D's and Vulkan's). Engines
// use four depth conventions, and every public entry whose decision depends on clip depth takes
// one as a ClipDepth argument with no default (make_frustum_planes, the frustum-disp, Hi-Z and
// fused kernels, HiZPyramid::build, the GPU passes, the object level):
// - zero_to_one: near 0, far 1 (patchcull's own, Direct3D, Vulkan, glm with
//   GLM_FORCE_DEPTH_ZERO_TO_ONE);
// - minus_one_to_one: near -1, far 1 (glFrustum, gluPerspective, glm::perspective). No test on a
//   matrix can tell it from zero_to_one: read in the other convention, an OpenGL projection is a
//   valid frustum whose near plane lies at 2fn/(f+n), about twice as far as meant, so kernels that
//   assumed the wrong one culled everything in front of that plane, silently (1146 of BigGuy's
//   1450 visible patches in one view);
// - reversed: near 1, far 0 with a finite far plane, and reversed_infinite: near 1, depth n/t -> 0
//   at infinity with no far plane (what most current engines draw: GL_GREATER, depth cleared to
//   0, float depth buffers). A reversed matrix declared as a forward one (or the other way) is
//   detected from the sign of the eye's clip z and refused (check_clip_depth), never culled.
// Plane tests convert with to_zero_to_one (and skip the far plane for reversed_infinite); depth
// comparisons work on depth keys (to_depth_key), larger = farther in every convention.
//
// Convention-free entries take no ClipDepth: tcone/ncone (eye point only) and ptp (rows x, y and
// w of object_to_clip and the sign of the eye's clip z, taken from the same matrix: backpatch.h).
// The OpenGL renderer (gl_renderer.h) draws in the convention of its RenderParams.
#pragma once

#include <string_view>

#include "patchcull/core/math.h"

namespace patchcull {

enum class ClipDepth {
    zero_to_one,        ///< near 0, far 1: 0 <= z <= w (patchcull's own, GL_ZERO_TO_ONE, Direct3D, Vulkan)
    minus_one_to_one,   ///< near -1, far 1: -w <= z <= w (OpenGL's default, glFrustum, gluPerspective)
    reversed,           ///< near 1, far 0: 0 <= z <= w with a finite far plane (GL_GREATER, cleared to 0)
    reversed_infinite,  ///< near 1, far plane at infinity (depth -> 0): z <= w only, no far plane test
};

/// "zero-to-one", "minus-one-to-one", "reversed", "reversed-infinite".
const char* clip_depth_name(ClipDepth depth);
/// The ClipDepth named text (clip_depth_name's spelling); false for any other text.
bool parse_clip_depth(std::string_view text, ClipDepth& out);
/// Near maps to depth 1 and the far end to 0: the depth buffer keeps the largest value.
inline bool is_reversed(ClipDepth depth) {
    return depth == ClipDepth::reversed || depth == ClipDepth::reversed_infinite;
}
/// False for reversed_infinite: every point in front of the eye passes the far "plane".
inline bool has_far_plane(ClipDepth depth) { return depth != ClipDepth::reversed_infinite; }

/// The same matrix in zero_to_one form, for plane tests: rows x, y, w unchanged, row z replaced by
/// (z + w) / 2 for minus_one_to_one (depth d in [-1, 1] becomes (d + 1) / 2, what glDepthRange(0,
/// 1) writes to the depth buffer) and by w - z for the reversed conventions (near z = w becomes
/// 0). Same camera, same clip volume: the x, y and far planes are unchanged up to a positive
/// factor, and the near plane becomes z' >= 0. One rounding per element (computed in double).
/// For reversed_infinite the far plane of the result, w - z' = z >= 0, holds at every point in
/// front of the eye mathematically but not after rounding far away: plane tests skip it
/// (FrustumPlanes, frustum.h, does).
Mat4 to_zero_to_one(const Mat4& object_to_clip, ClipDepth depth);

/// The depth-key form of a matrix, what the Hi-Z tests transform by: rows x, y, w unchanged, row
/// z replaced by the key row K: z (zero_to_one), (z + w) / 2 (minus_one_to_one, rounded once) or
/// -z (reversed conventions, exact). K / w is the window depth written by glDepthRange(0, 1) for
/// the forward conventions and minus it for the reversed ones, so in every convention a larger
/// key is farther, and a pyramid of keys (hiz.h) keeps the farthest depth of its footprint in the
/// declared convention (the max of depths, or the min for reversed).
Mat4 to_depth_key(const Mat4& object_to_clip, ClipDepth depth);

/// The key of a window depth d in [0, 1]: d, or -d for the reversed conventions (exact).
inline float depth_key(float window_depth, ClipDepth depth) {
    return is_reversed(depth) ? -window_depth : window_depth;
}

/// Refuses a perspective matrix whose depth row contradicts depth: throws Error("<what>: ...",
/// one line) when the eye's clip z has the wrong sign. In every forward convention the eye
/// (the object-space point that x, y and w map to 0) has clip z < 0 (the near plane maps to
/// depth 0 or -1, in front of it); in the reversed ones clip z > 0 (near maps to 1). The sign is
/// that of element (3, 2) of the inverse of object_to_clip, the same for every affine view and
/// model matrix (mirrored ones too). Orthographic matrices (the eye at infinity) and singular
/// ones cannot be told apart and are accepted. Zero_to_one and minus_one_to_one cannot be told
/// apart either (see above). Every entry that takes a ClipDepth calls it before its loop.
void check_clip_depth(const Mat4& object_to_clip, ClipDepth depth, const char* what);

/// perspective() (math.h) in any convention: depth 0 (zero_to_one), -1 (minus_one_to_one) or 1
/// (reversed ones) at z_near; 1, 1 or 0 at z_far; reversed_infinite ignores z_far (depth
/// z_near / distance). perspective(f, a, n, far) is perspective(f, a, n, far, ClipDepth::zero_to_one).
Mat4 perspective(float fovy_radians, float aspect, float z_near, float z_far, ClipDepth depth);

}  // namespace patchcull
