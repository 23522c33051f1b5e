// Test helpers shared by cones_test.cpp and backpatch_cones_test.cpp: random bicubic patches of
// several kinds and double-precision evaluation of B, B_u, B_v.
#pragma once

#include <cmath>
#include <random>

#include "patchcull/core/patch.h"

namespace patchcull::cone_test {

/// The sanitizer build (Debug, ASan + UBSan, run by scripts/test.sh) is ~20x slower: the long
/// randomized tests run a fraction of their iterations there (the Release suite runs them all).
#if defined(__SANITIZE_ADDRESS__)
inline constexpr int kSanitizerDivisor = 8;
#else
inline constexpr int kSanitizerDivisor = 1;
#endif

struct D3 {
    double x = 0, y = 0, z = 0;
};
inline D3 operator+(D3 a, D3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline D3 operator-(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline D3 operator*(D3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline double dot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline D3 cross(D3 a, D3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline double len(D3 a) { return std::sqrt(dot(a, a)); }
inline D3 d3(Vec3 v) { return {v.x, v.y, v.z}; }

inline void bernstein3(double t, double b[4], double db[4]) {
    const double s = 1 - t;
    b[0] = s * s * s;
    b[1] = 3 * t * s * s;
    b[2] = 3 * t * t * s;
    b[3] = t * t * t;
    db[0] = -3 * s * s;
    db[1] = 3 * s * s - 6 * t * s;
    db[2] = 6 * t * s - 3 * t * t;
    db[3] = 3 * t * t;
}

/// Position, B_u, B_v of a polynomial patch (w ignored) in double precision.
struct SurfaceD {
    D3 p, du, dv;
    D3 normal() const { return cross(du, dv); }
};
inline SurfaceD evaluate_d(const BezierPatch& patch, double u, double v) {
    double bu[4], dbu[4], bv[4], dbv[4];
    bernstein3(u, bu, dbu);
    bernstein3(v, bv, dbv);
    SurfaceD s;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            const D3 c{patch.cp[4 * j + i].x, patch.cp[4 * j + i].y, patch.cp[4 * j + i].z};
            s.p = s.p + c * (bu[i] * bv[j]);
            s.du = s.du + c * (dbu[i] * bv[j]);
            s.dv = s.dv + c * (bu[i] * dbv[j]);
        }
    return s;
}

/// Random patches. kinds: sheets (a random frame, a 4x4 grid with jitter, bumps of relative height
/// `bump` along the frame normal and a random bend), point clouds, sheets with a collapsed edge.
class PatchGen {
public:
    explicit PatchGen(unsigned seed) : rng_(seed) {}

    double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }
    int integer(int a, int b) { return std::uniform_int_distribution<int>(a, b)(rng_); }

    D3 unit() {
        for (;;) {
            const D3 v{uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)};
            const double l = len(v);
            if (l > 0.1 && l <= 1) return v * (1 / l);
        }
    }

    BezierPatch sheet(double bump, double size = 1, D3 centre = {}) {
        const D3 n = unit();
        D3 t = cross(n, unit());
        t = t * (1 / len(t));
        const D3 b = cross(n, t);
        const double ax = uniform(0.5, 1.5), ay = uniform(0.5, 1.5), shear = uniform(-0.4, 0.4);
        const double bend_u = uniform(-1, 1) * bump, bend_v = uniform(-1, 1) * bump;
        BezierPatch patch;
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                const double x = (i / 3.0 - 0.5) * ax + uniform(-0.05, 0.05);
                const double y = (j / 3.0 - 0.5) * ay + shear * x + uniform(-0.05, 0.05);
                const double h = bump * 0.3 * uniform(-1, 1) + bend_u * x * x + bend_v * y * y;
                const D3 p = centre + (t * x + b * y + n * h) * size;
                patch.cp[4 * j + i] = {float(p.x), float(p.y), float(p.z), 1.0f};
            }
        return patch;
    }

    BezierPatch cloud(double size = 1, D3 centre = {}) {
        BezierPatch patch;
        for (auto& c : patch.cp) {
            const D3 p = centre + D3{uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)} * size;
            c = {float(p.x), float(p.y), float(p.z), 1.0f};
        }
        return patch;
    }

    /// Collapses row v = 0 (or column u = 0) to one point, like the teapot's lid and bottom.
    static BezierPatch collapse(BezierPatch patch, bool row) {
        for (int k = 1; k < 4; ++k) patch.cp[row ? k : 4 * k] = patch.cp[0];
        return patch;
    }

    /// A mix: mostly gently curved sheets at random scales and offsets, some wavy ones, clouds and
    /// collapsed edges.
    BezierPatch any() {
        const double size = std::pow(10.0, uniform(-2, 2));
        const D3 centre = D3{uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)} * (size * uniform(0, 20));
        const int kind = integer(0, 19);
        if (kind < 12) return sheet(std::pow(10.0, uniform(-3, -0.5)), size, centre);
        if (kind < 15) return sheet(uniform(0.3, 1.5), size, centre);
        if (kind < 17) return collapse(sheet(std::pow(10.0, uniform(-3, -0.5)), size, centre), kind == 15);
        return cloud(size, centre);
    }

    std::mt19937& rng() { return rng_; }

private:
    std::mt19937 rng_;
};

}  // namespace patchcull::cone_test
