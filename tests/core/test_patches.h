// Patches the core and GL tests share: the teapot split into smaller patches, the bounds of
// control points, a flat patch, a patch's copies with one coordinate made non-finite, and
// bit-for-bit comparison of points and patches.
#pragma once

#include <bit>
#include <cstdint>
#include <limits>
#include <vector>

#include "patchcull/core/mesh.h"
#include "patchcull/core/patch.h"
#include "patchcull/core/teapot.h"

namespace patchcull::test_patches {

/// The teapot's 32 patches after `levels` 1-to-4 splits (32 x 4^levels patches).
inline std::vector<BezierPatch> split_teapot(int levels) {
    std::vector<BezierPatch> patches = teapot_patches();
    for (int l = 0; l < levels; ++l) {
        std::vector<BezierPatch> next(patches.size() * 4);
        for (std::size_t i = 0; i < patches.size(); ++i) split_patch(patches[i], &next[4 * i]);
        patches.swap(next);
    }
    return patches;
}

/// The box of every control point (cartesian) of patches.
inline Bounds control_point_bounds(const std::vector<BezierPatch>& patches) {
    std::vector<Vec3> points;
    for (const BezierPatch& p : patches)
        for (const Vec4& c : p.cp) points.push_back(cartesian(c));
    return compute_bounds(points);
}

/// A flat 1 x 1 patch at depth z (object = world space) from (x0, y0), weights 1, its normal
/// du x dv along +z, or -z when flipped.
inline BezierPatch flat_patch(float x0, float y0, float z, bool flipped) {
    BezierPatch p;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) p.cp[4 * j + i] = {x0 + i / 3.0f, flipped ? y0 - j / 3.0f : y0 + j / 3.0f, z, 1.0f};
    return p;
}

/// The base patch followed by one copy per (point, component, value) with that coordinate
/// replaced by NaN, +Inf or -Inf: 1 + 16 x 4 x 3 patches (weights included).
inline std::vector<BezierPatch> poisoned_copies(const BezierPatch& base) {
    const float bad[3] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                          -std::numeric_limits<float>::infinity()};
    std::vector<BezierPatch> out{base};
    for (int k = 0; k < kPatchPoints; ++k)
        for (int c = 0; c < 4; ++c)
            for (float v : bad) {
                BezierPatch p = base;
                float* component[4] = {&p.cp[k].x, &p.cp[k].y, &p.cp[k].z, &p.cp[k].w};
                *component[c] = v;
                out.push_back(p);
            }
    return out;
}

/// Whether a and b are the same bit for bit, coordinate by coordinate (0 and -0 differ, a NaN
/// equals the same NaN): what a memcmp of the structs checked, said per float.
inline bool bit_identical(float a, float b) {
    return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b);
}
inline bool bit_identical(const Vec3& a, const Vec3& b) {
    return bit_identical(a.x, b.x) && bit_identical(a.y, b.y) && bit_identical(a.z, b.z);
}
inline bool bit_identical(const Vec4& a, const Vec4& b) {
    return bit_identical(a.x, b.x) && bit_identical(a.y, b.y) && bit_identical(a.z, b.z) && bit_identical(a.w, b.w);
}
inline bool bit_identical(const BezierPatch& a, const BezierPatch& b) {
    for (int k = 0; k < kPatchPoints; ++k)
        if (!bit_identical(a.cp[k], b.cp[k])) return false;
    return true;
}

}  // namespace patchcull::test_patches
