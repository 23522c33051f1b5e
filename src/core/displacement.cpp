// Displacement sampling and seed 002's per-patch maximum-displacement pre-processing step
// (patchcull/displacement.h; seed 002 "Pre-Processing Step", seed 000 §4.2's [D_min, D_max]).
#include "patchcull/displacement.h"

#include <algorithm>
#include <cmath>

namespace patchcull {
namespace {

int wrap(long i, int n) {
    long r = i % n;
    return static_cast<int>(r < 0 ? r + n : r);
}

}  // namespace

float DisplacementMap::sample(Vec2 st) const {
    if (empty()) return 0.0f;
    // Texel centres at (i + 0.5) / width: the same addressing as GL_LINEAR with GL_REPEAT.
    const double x = static_cast<double>(st.x) * width - 0.5;
    const double y = static_cast<double>(st.y) * height - 0.5;
    const double fx = std::floor(x), fy = std::floor(y);
    const float ax = static_cast<float>(x - fx), ay = static_cast<float>(y - fy);
    const int x0 = wrap(static_cast<long>(fx), width), x1 = wrap(static_cast<long>(fx) + 1, width);
    const int y0 = wrap(static_cast<long>(fy), height), y1 = wrap(static_cast<long>(fy) + 1, height);
    const float h00 = texels[y0 * width + x0], h10 = texels[y0 * width + x1];
    const float h01 = texels[y1 * width + x0], h11 = texels[y1 * width + x1];
    const float h = (h00 * (1 - ax) + h10 * ax) * (1 - ay) + (h01 * (1 - ax) + h11 * ax) * ay;
    return scale * (h - midlevel);
}

DisplacementRange DisplacementMap::patch_range(const Vec2 uv[4]) const {
    DisplacementRange range;
    if (empty()) return range;
    // The bilinear texcoord map keeps the patch's footprint inside the bounding box of its corner
    // texcoords; a bilinear texture sample blends the 2x2 texels around it, so the box's texel
    // range, widened by one texel on each side, holds every texel the patch can read.
    float s_min = uv[0].x, s_max = uv[0].x, t_min = uv[0].y, t_max = uv[0].y;
    for (int k = 1; k < 4; ++k) {
        s_min = std::min(s_min, uv[k].x); s_max = std::max(s_max, uv[k].x);
        t_min = std::min(t_min, uv[k].y); t_max = std::max(t_max, uv[k].y);
    }
    const long x_first = static_cast<long>(std::floor(static_cast<double>(s_min) * width - 0.5)) - 1;
    const long x_last = static_cast<long>(std::floor(static_cast<double>(s_max) * width - 0.5)) + 2;
    const long y_first = static_cast<long>(std::floor(static_cast<double>(t_min) * height - 0.5)) - 1;
    const long y_last = static_cast<long>(std::floor(static_cast<double>(t_max) * height - 0.5)) + 2;
    float h_min = 1e30f, h_max = -1e30f;
    const long nx = std::min<long>(x_last - x_first + 1, width);
    const long ny = std::min<long>(y_last - y_first + 1, height);
    for (long j = 0; j < ny; ++j) {
        const int y = wrap(y_first + j, height);
        for (long i = 0; i < nx; ++i) {
            const float h = texels[y * width + wrap(x_first + i, width)];
            h_min = std::min(h_min, h);
            h_max = std::max(h_max, h);
        }
    }
    // D = scale * (h - midlevel) is monotonic in h; scale may be negative.
    const float d0 = scale * (h_min - midlevel), d1 = scale * (h_max - midlevel);
    range.d_min = std::min({0.0f, d0, d1});
    range.d_max = std::max({0.0f, d0, d1});
    return range;
}

DisplacementMap make_procedural_displacement(int size, float scale, std::uint32_t seed) {
    DisplacementMap map;
    map.width = map.height = size;
    map.scale = scale;
    map.midlevel = 0.5f;
    map.texels.resize(static_cast<std::size_t>(size) * size);
    // A few periodic ridges and bumps (integer frequencies, so the map tiles under wrap-around).
    std::uint32_t state = seed * 2654435761u + 1;
    auto next = [&state]() {
        state ^= state << 13; state ^= state >> 17; state ^= state << 5;
        return (state & 0xffffff) / float(0x1000000);
    };
    struct Wave { float fx, fy, phase, amp; };
    Wave waves[6];
    for (Wave& w : waves)
        w = {float(1 + int(next() * 12)), float(1 + int(next() * 12)), next() * 6.2831853f, 0.5f + next()};
    float lo = 1e30f, hi = -1e30f;
    const float two_pi = 6.2831853f;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const float s = (x + 0.5f) / size, t = (y + 0.5f) / size;
            float h = 0;
            for (const Wave& w : waves) h += w.amp * std::sin(two_pi * (w.fx * s + w.fy * t) + w.phase);
            h += 1.5f * std::pow(std::max(0.0f, std::sin(two_pi * 8 * s) * std::sin(two_pi * 8 * t)), 4.0f);
            map.texels[y * size + x] = h;
            lo = std::min(lo, h);
            hi = std::max(hi, h);
        }
    for (float& h : map.texels) h = (h - lo) / (hi - lo);
    return map;
}

}  // namespace patchcull
