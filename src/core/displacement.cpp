// Displacement sampling and Sathe's per-patch maximum-displacement pre-processing step
// (patchcull/core/displacement.h; Sathe, "View Frustum Culling of Catmull-Clark Patches in
// DirectX 11", pre-processing step; the [D_min, D_max] of Niessner & Loop, "Patch-Based Occlusion
// Culling for Hardware Tessellation", §4.2).
//
// Why a pyramid: the exact range scans every texel of a patch's footprint, and a face whose
// texcoords span a 4096^2 map costs 16M reads per patch (56 s for BigGuy, docs/PERFORMANCE.md). A min/max
// pyramid of blocks makes every query a bounded number of reads, built once per map.
#include "patchcull/core/displacement.h"

#include <algorithm>
#include <cmath>
#include <memory>

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

namespace {

// The texels a patch can read along one axis (see displacement.h): up to two intervals of texel
// indices in [0, n) after wrap-around, the whole axis when the window is as wide as the map.
struct AxisWindow {
    int first[2] = {0, 0};
    int last[2] = {-1, -1};  // empty when last < first
    int intervals = 0;
};

AxisWindow axis_window(float lo, float hi, int n) {
    AxisWindow w;
    const double a = std::floor(static_cast<double>(lo) * n - 0.5) - 1;  // first texel of a 2x2
    const double b = std::floor(static_cast<double>(hi) * n - 0.5) + 2;  // second texel, + 1
    constexpr double kHuge = 1099511627776.0;                            // 2^40
    if (!(std::fabs(a) <= kHuge && std::fabs(b) <= kHuge) || b - a + 1 >= n) {
        w.first[0] = 0;
        w.last[0] = n - 1;
        w.intervals = 1;
        return w;
    }
    const long first = static_cast<long>(a), count = static_cast<long>(b - a) + 1;
    const int start = wrap(first, n);
    const long end = start + count - 1;  // may pass n - 1 once: then the window wraps
    w.first[0] = start;
    w.last[0] = static_cast<int>(std::min<long>(end, n - 1));
    w.intervals = 1;
    if (end >= n) {
        w.first[1] = 0;
        w.last[1] = static_cast<int>(end - n);
        w.intervals = 2;
    }
    return w;
}

void corner_box(const Vec2 uv[4], float& s_min, float& s_max, float& t_min, float& t_max) {
    s_min = s_max = uv[0].x;
    t_min = t_max = uv[0].y;
    for (int k = 1; k < 4; ++k) {
        s_min = std::min(s_min, uv[k].x);
        s_max = std::max(s_max, uv[k].x);
        t_min = std::min(t_min, uv[k].y);
        t_max = std::max(t_max, uv[k].y);
    }
    // std::min/max drop a NaN in some argument orders: make a NaN corner poison the box.
    for (int k = 0; k < 4; ++k)
        if (!std::isfinite(uv[k].x) || !std::isfinite(uv[k].y)) s_min = t_min = -INFINITY, s_max = t_max = INFINITY;
}

// D = scale * (h - midlevel) is monotonic in h; scale may be negative.
DisplacementRange to_range(float h_min, float h_max, float scale, float midlevel) {
    const float d0 = scale * (h_min - midlevel), d1 = scale * (h_max - midlevel);
    DisplacementRange range;
    range.d_min = std::min({0.0f, d0, d1});
    range.d_max = std::max({0.0f, d0, d1});
    return range;
}

// Blocks (texels at level 0) an axis window touches at a level with block size 2^shift.
int block_count(const AxisWindow& w, int shift) {
    int count = 0;
    for (int i = 0; i < w.intervals; ++i) count += (w.last[i] >> shift) - (w.first[i] >> shift) + 1;
    return count;
}

constexpr int kLookupBudget = 36;  // blocks per query (6x6), see DisplacementMap::patch_range
constexpr int kFirstShift = 2;     // the first pyramid level has 4x4-texel blocks

}  // namespace

namespace detail {

// Min/max pyramid: level k (k = 0, 1, ...) has blocks of 2^(kFirstShift + k) texels a side,
// ceil(width / 2^shift) x ceil(height / 2^shift) of them, each the min and max of the texels
// (clipped at the map's edge) it covers; the last level is 1x1. Level 0 of the map (the texels)
// is not copied: queries read it from the map.
struct RangePyramid {
    struct Level {
        int shift = 0, width = 0, height = 0;
        std::vector<float> lo, hi;  // [y * width + x]
    };
    const float* key_texels = nullptr;
    std::size_t key_count = 0;
    int key_width = 0, key_height = 0;
    std::vector<Level> levels;

    void build(const float* texels, int width, int height) {
        levels.clear();
        int shift = kFirstShift;
        do {
            Level l;
            l.shift = shift;
            l.width = ((width - 1) >> shift) + 1;
            l.height = ((height - 1) >> shift) + 1;
            l.lo.assign(static_cast<std::size_t>(l.width) * l.height, INFINITY);
            l.hi.assign(l.lo.size(), -INFINITY);
            if (levels.empty()) {
                for (int y = 0; y < height; ++y) {
                    const float* row = texels + static_cast<std::size_t>(y) * width;
                    float* lo = &l.lo[static_cast<std::size_t>(y >> shift) * l.width];
                    float* hi = &l.hi[static_cast<std::size_t>(y >> shift) * l.width];
                    for (int x = 0; x < width; ++x) {
                        lo[x >> shift] = std::min(lo[x >> shift], row[x]);
                        hi[x >> shift] = std::max(hi[x >> shift], row[x]);
                    }
                }
            } else {
                const Level& f = levels.back();
                for (int y = 0; y < f.height; ++y)
                    for (int x = 0; x < f.width; ++x) {
                        const std::size_t src = static_cast<std::size_t>(y) * f.width + x;
                        const std::size_t dst = static_cast<std::size_t>(y >> 1) * l.width + (x >> 1);
                        l.lo[dst] = std::min(l.lo[dst], f.lo[src]);
                        l.hi[dst] = std::max(l.hi[dst], f.hi[src]);
                    }
            }
            levels.push_back(std::move(l));
            ++shift;
        } while (levels.back().width > 1 || levels.back().height > 1);
    }
};

RangePyramidCache::RangePyramidCache() = default;
RangePyramidCache::~RangePyramidCache() = default;
RangePyramidCache::RangePyramidCache(const RangePyramidCache&) {}
RangePyramidCache& RangePyramidCache::operator=(const RangePyramidCache& other) {
    if (this != &other) reset();
    return *this;
}

void RangePyramidCache::reset() {
    const std::lock_guard<std::mutex> lock(mutex_);
    pyramid_.reset();
}

const RangePyramid& RangePyramidCache::get(const float* texels, std::size_t count, int width, int height) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (!pyramid_ || pyramid_->key_texels != texels || pyramid_->key_count != count || pyramid_->key_width != width ||
        pyramid_->key_height != height) {
        auto p = std::make_unique<RangePyramid>();
        p->build(texels, width, height);
        p->key_texels = texels;
        p->key_count = count;
        p->key_width = width;
        p->key_height = height;
        pyramid_ = std::move(p);
    }
    return *pyramid_;
}

}  // namespace detail

DisplacementRange DisplacementMap::patch_range_exact(const Vec2 uv[4]) const {
    if (empty()) return {};
    float s_min, s_max, t_min, t_max;
    corner_box(uv, s_min, s_max, t_min, t_max);
    const AxisWindow wx = axis_window(s_min, s_max, width), wy = axis_window(t_min, t_max, height);
    float h_min = INFINITY, h_max = -INFINITY;
    for (int iy = 0; iy < wy.intervals; ++iy)
        for (int y = wy.first[iy]; y <= wy.last[iy]; ++y)
            for (int ix = 0; ix < wx.intervals; ++ix)
                for (int x = wx.first[ix]; x <= wx.last[ix]; ++x) {
                    const float h = texels[static_cast<std::size_t>(y) * width + x];
                    h_min = std::min(h_min, h);
                    h_max = std::max(h_max, h);
                }
    return to_range(h_min, h_max, scale, midlevel);
}

DisplacementRange DisplacementMap::patch_range(const Vec2 uv[4]) const {
    if (empty()) return {};
    float s_min, s_max, t_min, t_max;
    corner_box(uv, s_min, s_max, t_min, t_max);
    const AxisWindow wx = axis_window(s_min, s_max, width), wy = axis_window(t_min, t_max, height);
    if (block_count(wx, 0) * block_count(wy, 0) <= kLookupBudget) return patch_range_exact(uv);

    const detail::RangePyramid& pyramid = range_pyramid_.get(texels.data(), texels.size(), width, height);
    // The coarsest level is 1x1, where each axis counts at most 2 (one per interval): always in budget.
    const detail::RangePyramid::Level* level = &pyramid.levels.back();
    for (const auto& l : pyramid.levels)
        if (block_count(wx, l.shift) * block_count(wy, l.shift) <= kLookupBudget) {
            level = &l;
            break;
        }
    float h_min = INFINITY, h_max = -INFINITY;
    for (int iy = 0; iy < wy.intervals; ++iy)
        for (int y = wy.first[iy] >> level->shift; y <= wy.last[iy] >> level->shift; ++y)
            for (int ix = 0; ix < wx.intervals; ++ix)
                for (int x = wx.first[ix] >> level->shift; x <= wx.last[ix] >> level->shift; ++x) {
                    const std::size_t i = static_cast<std::size_t>(y) * level->width + x;
                    h_min = std::min(h_min, level->lo[i]);
                    h_max = std::max(h_max, level->hi[i]);
                }
    return to_range(h_min, h_max, scale, midlevel);
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
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        return (state & 0xffffff) / float(0x1000000);
    };
    struct Wave {
        float fx, fy, phase, amp;
    };
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
