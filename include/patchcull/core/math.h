// patchcull/core/math.h: small vector and matrix types shared by every layer.
//
// Conventions (fixed once, used everywhere):
// - Points on patches are homogeneous float4 (x*w, y*w, z*w, w); rational patches are allowed.
// - Matrices are column-major as in OpenGL: element (row r, column c) is m[4*c + r].
// - Clip space is OpenGL's with glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE): a point is inside
//   the view volume when -w <= x <= w, -w <= y <= w and 0 <= z <= w. Depth z/w lies in [0,1],
//   larger is farther.
// - View space is right-handed, the camera looks down -z (OpenGL).
#pragma once

#include <cmath>

namespace patchcull {

struct Vec2 {
    float x = 0, y = 0;
};

struct Vec3 {
    float x = 0, y = 0, z = 0;
};

struct Vec4 {
    float x = 0, y = 0, z = 0, w = 0;
};

inline Vec2 operator+(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
inline Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
inline Vec2 operator*(Vec2 a, float s) { return {a.x * s, a.y * s}; }

inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
inline Vec3 operator*(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline Vec3 operator*(float s, Vec3 a) { return a * s; }
inline Vec3& operator+=(Vec3& a, Vec3 b) { return a = a + b; }
inline float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline float length(Vec3 a) { return std::sqrt(dot(a, a)); }
/// Returns a / |a|, or the zero vector when |a| is zero (degenerate normals stay detectable).
inline Vec3 normalize(Vec3 a) {
    float len = length(a);
    return len > 0 ? a * (1.0f / len) : Vec3{};
}

inline Vec4 operator+(Vec4 a, Vec4 b) { return {a.x + b.x, a.y + b.y, a.z + b.z, a.w + b.w}; }
inline Vec4 operator-(Vec4 a, Vec4 b) { return {a.x - b.x, a.y - b.y, a.z - b.z, a.w - b.w}; }
inline Vec4 operator*(Vec4 a, float s) { return {a.x * s, a.y * s, a.z * s, a.w * s}; }
inline Vec4 operator*(float s, Vec4 a) { return a * s; }
inline Vec4& operator+=(Vec4& a, Vec4 b) { return a = a + b; }
inline float dot(Vec4 a, Vec4 b) { return a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w; }
inline Vec4 homogeneous(Vec3 p, float w = 1.0f) { return {p.x * w, p.y * w, p.z * w, w}; }
/// Cartesian point of a homogeneous point (w must be non-zero).
inline Vec3 cartesian(Vec4 p) { return {p.x / p.w, p.y / p.w, p.z / p.w}; }
inline Vec3 xyz(Vec4 p) { return {p.x, p.y, p.z}; }

inline bool is_finite(Vec3 a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }

/// 4x4 column-major matrix: element (row r, column c) is m[4*c + r].
struct Mat4 {
    float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

    float& at(int row, int col) { return m[4 * col + row]; }
    float at(int row, int col) const { return m[4 * col + row]; }
    /// Row r as a vector: dot(row(r), p) is component r of (*this) * p.
    Vec4 row(int r) const { return {m[r], m[4 + r], m[8 + r], m[12 + r]}; }
};

inline Vec4 operator*(const Mat4& a, Vec4 p) {
    return {dot(a.row(0), p), dot(a.row(1), p), dot(a.row(2), p), dot(a.row(3), p)};
}

inline Mat4 operator*(const Mat4& a, const Mat4& b) {
    Mat4 r;
    for (int c = 0; c < 4; ++c)
        for (int i = 0; i < 4; ++i) {
            float s = 0;
            for (int k = 0; k < 4; ++k) s += a.at(i, k) * b.at(k, c);
            r.at(i, c) = s;
        }
    return r;
}

/// Perspective projection to the clip space above (depth 0 at z_near, 1 at z_far).
/// fovy_radians is the full vertical field of view; aspect = width / height.
Mat4 perspective(float fovy_radians, float aspect, float z_near, float z_far);

/// View matrix of a camera at eye looking at target, with up roughly upwards.
Mat4 look_at(Vec3 eye, Vec3 target, Vec3 up);

/// Inverse of an affine or projective matrix; returns false when singular.
bool invert(const Mat4& a, Mat4& out);
/// The inverse of a (taken as exact) in double precision, out[r][c] its row r, column c
/// (Gauss-Jordan with partial pivoting); false when a is singular or the result not finite.
bool invert_double(const double a[4][4], double out[4][4]);
/// The same for a Mat4's entries.
bool invert_double(const Mat4& a, double out[4][4]);

}  // namespace patchcull
