// Clip-depth conventions (patchcull/clip_space.h).
#include "patchcull/clip_space.h"

namespace patchcull {

const char* clip_depth_name(ClipDepth depth) {
    return depth == ClipDepth::zero_to_one ? "zero-to-one" : "minus-one-to-one";
}

Mat4 to_zero_to_one(const Mat4& m, ClipDepth depth) {
    if (depth == ClipDepth::zero_to_one) return m;
    Mat4 out = m;
    // z' = (z + w) / 2: computed in double, rounded once to float.
    for (int c = 0; c < 4; ++c)
        out.at(2, c) = static_cast<float>(0.5 * (double(m.at(2, c)) + double(m.at(3, c))));
    return out;
}

Mat4 perspective(float fovy_radians, float aspect, float z_near, float z_far, ClipDepth depth) {
    if (depth == ClipDepth::zero_to_one) return perspective(fovy_radians, aspect, z_near, z_far);
    const float f = 1.0f / std::tan(0.5f * fovy_radians);
    Mat4 p;
    for (float& v : p.m) v = 0;
    p.at(0, 0) = f / aspect;
    p.at(1, 1) = f;
    // glFrustum's depth rows: z_clip/w_clip is -1 at z = -near and 1 at z = -far.
    p.at(2, 2) = (z_far + z_near) / (z_near - z_far);
    p.at(2, 3) = 2 * z_far * z_near / (z_near - z_far);
    p.at(3, 2) = -1;
    return p;
}

}  // namespace patchcull
