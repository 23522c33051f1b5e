// Clip-depth conventions (patchcull/core/clip_space.h).
#include "patchcull/core/clip_space.h"

#include <cmath>
#include <string>

#include "patchcull/core/error.h"

namespace patchcull {

const char* clip_depth_name(ClipDepth depth) {
    switch (depth) {
        case ClipDepth::zero_to_one:
            return "zero-to-one";
        case ClipDepth::minus_one_to_one:
            return "minus-one-to-one";
        case ClipDepth::reversed:
            return "reversed";
        case ClipDepth::reversed_infinite:
            return "reversed-infinite";
    }
    return "unknown";
}

bool parse_clip_depth(std::string_view text, ClipDepth& out) {
    for (ClipDepth d :
         {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one, ClipDepth::reversed, ClipDepth::reversed_infinite}) {
        if (text == clip_depth_name(d)) {
            out = d;
            return true;
        }
    }
    return false;
}

Mat4 to_zero_to_one(const Mat4& m, ClipDepth depth) {
    if (depth == ClipDepth::zero_to_one) return m;
    Mat4 out = m;
    for (int c = 0; c < 4; ++c) {
        const double z = m.at(2, c), w = m.at(3, c);
        // minus_one_to_one: z' = (z + w) / 2; reversed: z' = w - z. In double, rounded once.
        out.at(2, c) = static_cast<float>(is_reversed(depth) ? w - z : 0.5 * (z + w));
    }
    return out;
}

Mat4 to_depth_key(const Mat4& m, ClipDepth depth) {
    if (depth == ClipDepth::minus_one_to_one) return to_zero_to_one(m, depth);
    Mat4 out = m;
    if (is_reversed(depth))
        for (int c = 0; c < 4; ++c) out.at(2, c) = -m.at(2, c);
    return out;
}

void check_clip_depth(const Mat4& object_to_clip, ClipDepth depth, const char* what) {
    double inv[4][4];
    if (!invert_double(object_to_clip, inv)) return;  // singular: cannot tell
    const double eye_w = inv[3][2];                   // the eye's weight; its clip z has this sign
    double scale = 0;
    for (int c = 0; c < 4; ++c) scale = std::fmax(scale, std::fabs(inv[3][c]));
    if (!(std::fabs(eye_w) > 1e-6 * scale)) return;  // orthographic (eye at infinity): cannot tell
    const bool reversed_matrix = eye_w > 0;
    if (reversed_matrix == is_reversed(depth)) return;
    throw Error(
        std::string(what) + ": the matrix maps the near plane to depth " + (reversed_matrix ? "1" : "0 or -1") +
        " (a " + (reversed_matrix ? "reversed" : "forward") + " projection) but was declared " +
        clip_depth_name(depth) +
        (reversed_matrix ? "; declare reversed or reversed-infinite" : "; declare zero-to-one or minus-one-to-one"));
}

Mat4 perspective(float fovy_radians, float aspect, float z_near, float z_far, ClipDepth depth) {
    if (depth == ClipDepth::zero_to_one) return perspective(fovy_radians, aspect, z_near, z_far);
    const float f = 1.0f / std::tan(0.5f * fovy_radians);
    Mat4 p;
    for (float& v : p.m) v = 0;
    p.at(0, 0) = f / aspect;
    p.at(1, 1) = f;
    p.at(3, 2) = -1;
    switch (depth) {
        case ClipDepth::minus_one_to_one:
            // glFrustum's depth rows: z_clip/w_clip is -1 at z = -near and 1 at z = -far.
            p.at(2, 2) = (z_far + z_near) / (z_near - z_far);
            p.at(2, 3) = 2 * z_far * z_near / (z_near - z_far);
            break;
        case ClipDepth::reversed:
            // z_clip/w_clip is 1 at z = -near and 0 at z = -far: n (f + z) / ((f - n) (-z)).
            p.at(2, 2) = z_near / (z_far - z_near);
            p.at(2, 3) = z_far * z_near / (z_far - z_near);
            break;
        case ClipDepth::reversed_infinite:
            // z_clip = near, w_clip = -z: depth near / distance, 1 at the near plane, -> 0 far away.
            // z_far is ignored (it may be infinite).
            p.at(2, 3) = z_near;
            break;
        case ClipDepth::zero_to_one:
            break;
    }
    return p;
}

}  // namespace patchcull
