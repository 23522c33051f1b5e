// Matrix helpers for patchcull/core/math.h (OpenGL column-major, depth in [0,1]).
#include "patchcull/core/math.h"

namespace patchcull {

Mat4 perspective(float fovy_radians, float aspect, float z_near, float z_far) {
    const float f = 1.0f / std::tan(0.5f * fovy_radians);
    Mat4 p;
    for (float& v : p.m) v = 0;
    p.at(0, 0) = f / aspect;
    p.at(1, 1) = f;
    // z_clip = A z + B, w_clip = -z: z_clip/w_clip is 0 at z = -near and 1 at z = -far.
    p.at(2, 2) = z_far / (z_near - z_far);
    p.at(2, 3) = z_far * z_near / (z_near - z_far);
    p.at(3, 2) = -1;
    return p;
}

Mat4 look_at(Vec3 eye, Vec3 target, Vec3 up) {
    const Vec3 f = normalize(target - eye);
    Vec3 s = normalize(cross(f, up));
    if (length(s) == 0) s = normalize(cross(f, Vec3{1, 0, 0}));  // up parallel to view direction
    if (length(s) == 0) s = normalize(cross(f, Vec3{0, 0, 1}));
    const Vec3 u = cross(s, f);
    Mat4 v;
    v.at(0, 0) = s.x;
    v.at(0, 1) = s.y;
    v.at(0, 2) = s.z;
    v.at(0, 3) = -dot(s, eye);
    v.at(1, 0) = u.x;
    v.at(1, 1) = u.y;
    v.at(1, 2) = u.z;
    v.at(1, 3) = -dot(u, eye);
    v.at(2, 0) = -f.x;
    v.at(2, 1) = -f.y;
    v.at(2, 2) = -f.z;
    v.at(2, 3) = dot(f, eye);
    return v;
}

bool invert_double(const double a[4][4], double out[4][4]) {
    double m[4][8];
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 8; ++c) m[r][c] = c < 4 ? a[r][c] : (c - 4 == r ? 1.0 : 0.0);
    for (int c = 0; c < 4; ++c) {
        int pivot = c;
        for (int r = c + 1; r < 4; ++r)
            if (std::fabs(m[r][c]) > std::fabs(m[pivot][c])) pivot = r;
        if (!(std::fabs(m[pivot][c]) > 0) || !std::isfinite(m[pivot][c])) return false;
        if (pivot != c)
            for (int k = 0; k < 8; ++k) std::swap(m[c][k], m[pivot][k]);
        const double inv = 1.0 / m[c][c];
        for (int k = 0; k < 8; ++k) m[c][k] *= inv;
        for (int r = 0; r < 4; ++r) {
            if (r == c) continue;
            const double f = m[r][c];
            if (f == 0) continue;
            for (int k = 0; k < 8; ++k) m[r][k] -= f * m[c][k];
        }
    }
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) {
            out[r][c] = m[r][c + 4];
            if (!std::isfinite(out[r][c])) return false;
        }
    return true;
}

bool invert_double(const Mat4& a, double out[4][4]) {
    double m[4][4];
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m[r][c] = a.at(r, c);
    return invert_double(m, out);
}

bool invert(const Mat4& a, Mat4& out) {
    double inv[4][4];
    if (!invert_double(a, inv)) return false;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) out.at(r, c) = static_cast<float>(inv[r][c]);
    return true;
}

}  // namespace patchcull
