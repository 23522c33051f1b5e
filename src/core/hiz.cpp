// Hi-Z pyramid and the scalar occlusion test (patchcull/core/hiz.h; steps numbered as there).
// The SIMD kernel (hiz_simd.cpp) mirrors steps 2-6 of patch_bounds() below operation by operation:
// std::fma <-> MulAdd, `a < b ? a : b` / `a > b ? a : b` <-> Min/Max (x86 minps/maxps), IEEE
// division, floor; the build is ISO C++ (no -ffast-math, no contraction of a*b+c).
#include "patchcull/core/hiz.h"

#include <limits>
#include <string>

#include "patchcull/core/error.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>

#include "patchcull/core/frustum.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(__SANITIZE_ADDRESS__)
#define PATCHCULL_HIZ_CLONES __attribute__((target_clones("fma", "default")))
// The reduction is plain max over arrays, auto-vectorized; wider clones chosen once at load time.
#define PATCHCULL_HIZ_BUILD_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define PATCHCULL_HIZ_CLONES
#define PATCHCULL_HIZ_BUILD_CLONES
#endif

namespace patchcull {
namespace {

inline float min_like_simd(float a, float b) { return a < b ? a : b; }
inline float max_like_simd(float a, float b) { return a > b ? a : b; }

// Level sizes: W_l = ceil(W / 2^(l+1)), computed as ceil of the previous level's half.
inline int half_up(int n) { return (n + 1) / 2; }

// Reduces a src_w x src_h image (row-major, row 0 first) to ceil(src_w/2) x ceil(src_h/2): each output
// texel is the max of its (up to) 2x2 children; children outside the source are skipped.
PATCHCULL_HIZ_BUILD_CLONES
void reduce_max(const float* src, int src_w, int src_h, float* dst) {
    const int dst_w = half_up(src_w), dst_h = half_up(src_h);
    const int full_w = src_w / 2;  // output texels with two children per row
    for (int ty = 0; ty < dst_h; ++ty) {
        const float* a = src + static_cast<std::size_t>(2 * ty) * src_w;
        const float* b = 2 * ty + 1 < src_h ? a + src_w : a;  // single child row: read it twice
        float* out = dst + static_cast<std::size_t>(ty) * dst_w;
        for (int tx = 0; tx < full_w; ++tx) {
            const float m0 = max_like_simd(a[2 * tx], a[2 * tx + 1]);
            const float m1 = max_like_simd(b[2 * tx], b[2 * tx + 1]);
            out[tx] = max_like_simd(m0, m1);
        }
        if (full_w < dst_w) out[full_w] = max_like_simd(a[2 * full_w], b[2 * full_w]);  // odd width
    }
}

// Level 0 from a depth buffer of any element type: texel = max of key(pixel) over its children.
template <class T, class Key>
void reduce_first(const T* src, int src_w, int src_h, float* dst, Key key) {
    const int dst_w = half_up(src_w), dst_h = half_up(src_h);
    const int full_w = src_w / 2;
    for (int ty = 0; ty < dst_h; ++ty) {
        const T* a = src + static_cast<std::size_t>(2 * ty) * src_w;
        const T* b = 2 * ty + 1 < src_h ? a + src_w : a;
        float* out = dst + static_cast<std::size_t>(ty) * dst_w;
        for (int tx = 0; tx < full_w; ++tx) {
            const float m0 = max_like_simd(key(a[2 * tx]), key(a[2 * tx + 1]));
            const float m1 = max_like_simd(key(b[2 * tx]), key(b[2 * tx + 1]));
            out[tx] = max_like_simd(m0, m1);
        }
        if (full_w < dst_w) out[full_w] = max_like_simd(key(a[2 * full_w]), key(b[2 * full_w]));
    }
}

inline float clamp_like_simd(float v, float lo, float hi) { return min_like_simd(max_like_simd(v, lo), hi); }

// The key of 24-bit unsigned depth u (hiz.h): the far end of the depths that store u, rounded outward.
float unorm24_key(std::uint32_t u, bool reversed) {
    constexpr double kMax = 16777215.0;  // 2^24 - 1
    if (!reversed) {
        const float d = static_cast<float>((static_cast<double>(u) + 0.5) / kMax);
        return std::nextafter(d, std::numeric_limits<float>::infinity());
    }
    const float d = static_cast<float>((static_cast<double>(u) - 0.5) / kMax);
    return -std::nextafter(d, -std::numeric_limits<float>::infinity());
}

}  // namespace

// ---- pyramid ---------------------------------------------------------------------------------

int HiZPyramid::level_count(int depth_width, int depth_height) {
    const unsigned m = static_cast<unsigned>(std::max(depth_width, depth_height));
    // ceil(log2(m)) = bit_width(m - 1) for m >= 1.
    return std::max(1, static_cast<int>(std::bit_width(m - 1)));
}

void HiZPyramid::resize(int depth_width, int depth_height) {
    assert(depth_width >= 1 && depth_height >= 1);
    if (depth_width == width_ && depth_height == height_ && levels_ > 0) return;
    width_ = depth_width;
    height_ = depth_height;
    levels_ = level_count(depth_width, depth_height);
    std::size_t offset = 0;
    int w = depth_width, h = depth_height;
    for (int l = 0; l < levels_; ++l) {
        w = half_up(w);
        h = half_up(h);
        level_[l] = {w, h, offset};
        offset += static_cast<std::size_t>(w) * h;
    }
    assert(level_[levels_ - 1].width == 1 && level_[levels_ - 1].height == 1);
    if (data_.size() != offset) data_.assign(offset, 0.0f);
}

void HiZPyramid::build(const float* depth, int depth_width, int depth_height) {
    build(depth, depth_width, depth_height, ClipDepth::zero_to_one);
}

void HiZPyramid::build(const float* depth, int depth_width, int depth_height, ClipDepth convention) {
    resize(depth_width, depth_height);
    reversed_ = is_reversed(convention);
    if (reversed_)
        reduce_first(depth, width_, height_, data_.data() + level_[0].offset, [](float d) { return -d; });
    else
        reduce_max(depth, width_, height_, data_.data() + level_[0].offset);
    reduce_upper_levels();
}

void HiZPyramid::build_unorm24(const std::uint32_t* depth, int depth_width, int depth_height, int depth_shift,
                               ClipDepth convention) {
    resize(depth_width, depth_height);
    reversed_ = is_reversed(convention);
    const bool reversed = reversed_;
    reduce_first(depth, width_, height_, data_.data() + level_[0].offset, [depth_shift, reversed](std::uint32_t v) {
        return unorm24_key((v >> depth_shift) & 0xFFFFFFu, reversed);
    });
    reduce_upper_levels();
}

void HiZPyramid::reduce_upper_levels() {
    for (int l = 1; l < levels_; ++l) {
        const HiZLevel& src = level_[l - 1];
        reduce_max(data_.data() + src.offset, src.width, src.height, data_.data() + level_[l].offset);
    }
}

// ---- steps 6-8 --------------------------------------------------------------------------------

PixelRect hiz_rect_from_window_box(float xlo, float xhi, float ylo, float yhi, int width, int height) {
    const float wmax = static_cast<float>(width - 1), hmax = static_cast<float>(height - 1);
    PixelRect r;
    r.x0 = static_cast<int>(clamp_like_simd(std::floor(xlo), 0.0f, wmax));
    r.x1 = static_cast<int>(clamp_like_simd(std::floor(xhi), 0.0f, wmax));
    r.y0 = static_cast<int>(clamp_like_simd(std::floor(ylo), 0.0f, hmax));
    r.y1 = static_cast<int>(clamp_like_simd(std::floor(yhi), 0.0f, hmax));
    return r;
}

int hiz_select_level(const PixelRect& rect, int levels) {
    const int span = std::max(rect.x1 - rect.x0, rect.y1 - rect.y0);
    int level = span <= 2 ? 0 : static_cast<int>(std::bit_width(static_cast<unsigned>(span - 1))) - 1;
    if (level > 0) {
        const int s = level;  // shift of level - 1
        if ((rect.x1 >> s) - (rect.x0 >> s) <= 1 && (rect.y1 >> s) - (rect.y0 >> s) <= 1) --level;
    }
    return std::min(level, levels - 1);
}

float hiz_rect_max(const HiZPyramid& hiz, const PixelRect& rect) {
    const int l = hiz_select_level(rect, hiz.levels());
    const int s = l + 1;
    const int tx0 = rect.x0 >> s, tx1 = rect.x1 >> s, ty0 = rect.y0 >> s, ty1 = rect.y1 >> s;
    const HiZLevel& lv = hiz.level(l);
    const float* row0 = hiz.data() + lv.offset + static_cast<std::size_t>(ty0) * lv.width;
    const float* row1 = hiz.data() + lv.offset + static_cast<std::size_t>(ty1) * lv.width;
    return max_like_simd(max_like_simd(row0[tx0], row0[tx1]), max_like_simd(row1[tx0], row1[tx1]));
}

// ---- steps 2-6 --------------------------------------------------------------------------------

namespace {

struct ClipRows {
    float m[4][4];   // m[r][c] = M(r, c)
    float abs_w[4];  // |M(3, c)|
    float half_w, half_h;
};

ClipRows make_clip_rows(const Mat4& object_to_clip, int width, int height) {
    ClipRows cr;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) cr.m[r][c] = object_to_clip.at(r, c);
    for (int c = 0; c < 4; ++c) cr.abs_w[c] = std::fabs(cr.m[3][c]);
    cr.half_w = 0.5f * static_cast<float>(width);
    cr.half_h = 0.5f * static_cast<float>(height);
    return cr;
}

constexpr float kWSafety = 0x1p-20f;

inline bool patch_bounds(const PatchBatchView& v, std::size_t p, const ClipRows& cr, int width, int height,
                         PatchScreenBounds& out) {
    float nxmin = 0, nxmax = 0, nymin = 0, nymax = 0, zmin = 0;
    for (int k = 0; k < kPatchPoints; ++k) {
        const float X = v.at(p, k, 0), Y = v.at(p, k, 1);
        const float Z = v.at(p, k, 2), W = v.at(p, k, 3);
        float c[4];
        for (int r = 0; r < 4; ++r) {
            float t = cr.m[r][0] * X;
            t = std::fma(cr.m[r][1], Y, t);
            t = std::fma(cr.m[r][2], Z, t);
            c[r] = std::fma(cr.m[r][3], W, t);
        }
        float s = cr.abs_w[0] * std::fabs(X);
        s = std::fma(cr.abs_w[1], std::fabs(Y), s);
        s = std::fma(cr.abs_w[2], std::fabs(Z), s);
        s = std::fma(cr.abs_w[3], std::fabs(W), s);
        if (!(c[3] > kWSafety * s)) return false;  // step 3
        const float nx = c[0] / c[3], ny = c[1] / c[3], nz = c[2] / c[3];
        if (k == 0) {
            nxmin = nxmax = nx;
            nymin = nymax = ny;
            zmin = nz;
        } else {
            nxmin = min_like_simd(nxmin, nx);
            nxmax = max_like_simd(nxmax, nx);
            nymin = min_like_simd(nymin, ny);
            nymax = max_like_simd(nymax, ny);
            zmin = min_like_simd(zmin, nz);
        }
    }
    const float xlo = std::fma(nxmin, cr.half_w, cr.half_w), xhi = std::fma(nxmax, cr.half_w, cr.half_w);
    const float ylo = std::fma(nymin, cr.half_h, cr.half_h), yhi = std::fma(nymax, cr.half_h, cr.half_h);
    out.rect = hiz_rect_from_window_box(xlo, xhi, ylo, yhi, width, height);
    out.zmin = zmin;
    return true;
}

constexpr std::size_t kChunk = 256;  // patches per frustum pass (64 KiB of control points)

}  // namespace

PATCHCULL_HIZ_CLONES
bool patch_screen_bounds(const PatchBatchView& patches, std::size_t index, const Mat4& object_to_clip, ClipDepth depth,
                         int width, int height, PatchScreenBounds& out) {
    return patch_bounds(patches, index, make_clip_rows(to_depth_key(object_to_clip, depth), width, height), width,
                        height, out);
}

void check_hiz_convention(const HiZPyramid& hiz, ClipDepth depth, const char* what) {
    if (hiz.levels() == 0) throw Error(std::string(what) + ": the Hi-Z pyramid was never built");
    if (hiz.reversed() != is_reversed(depth))
        throw Error(std::string(what) + ": the matrix is declared " + clip_depth_name(depth) +
                    " but the Hi-Z pyramid was built from a " + (hiz.reversed() ? "reversed" : "forward") +
                    " depth buffer; build it with the same convention");
}

PATCHCULL_HIZ_CLONES
void cull_occlusion_scalar(const PatchBatchView& patches, const Mat4& any_object_to_clip, ClipDepth depth,
                           const HiZPyramid& hiz, std::uint8_t* decision) {
    check_hiz_convention(hiz, depth, "cull_occlusion_scalar");
    const FrustumPlanes planes = make_frustum_planes(any_object_to_clip, depth);
    const Mat4 object_to_clip = to_depth_key(any_object_to_clip, depth);
    const int width = hiz.depth_width(), height = hiz.depth_height();
    const ClipRows cr = make_clip_rows(object_to_clip, width, height);
    for (std::size_t first = 0; first < patches.count; first += kChunk) {
        const std::size_t n = std::min(kChunk, patches.count - first);
        // Step 1: exactly the frustum kernel (1 = culled, 0 = not), on a chunk still in L1/L2 below.
        cull_frustum_scalar(patches.subrange(first, n), nullptr, planes, decision + first);
        for (std::size_t i = first; i < first + n; ++i) {
            if (decision[i] != kHiZVisible) continue;
            PatchScreenBounds b;
            if (!patch_bounds(patches, i, cr, width, height, b)) continue;       // not projectable: visible
            if (hiz_rect_max(hiz, b.rect) < b.zmin) decision[i] = kHiZOccluded;  // step 9
        }
    }
}

}  // namespace patchcull
