// The frustum-disp box test of one patch, shared by cull_frustum_disp_scalar (frustum.cpp) and the
// Gregory patches of the patch-source entries (patch_source_cull.cpp); private to patchcull.
#pragma once

#include <cmath>

#include "patchcull/core/frustum.h"

namespace patchcull::frustum_detail {

/// True when the axis-aligned box of n points' Cartesian coordinates (X / W, exact IEEE
/// division), grown by d on every side, has all 8 corners outside one plane of planes, and every
/// raw coordinate is finite (a probe fma(x, 0, probe) per coordinate stays 0). point_at(k, a) is
/// component a (x, y, z, w) of homogeneous point k. The operations and their order are
/// frustum.cpp's (the SIMD kernel's): min/max as `a < b ? a : b`, the corners' clip rows as nested
/// fmas, the plane values as frustum_plane_values forms them and their maxima over the corners.
template <class PointAt>
inline bool box_outside_frustum(const FrustumPlanes& planes, int n, float d, const PointAt& point_at) {
    float lo[3] = {}, hi[3] = {};  // set by point 0
    float probe = 0;
    for (int k = 0; k < n; ++k) {
        const float W = point_at(k, 3);
        for (int a = 0; a < 4; ++a) probe = std::fma(point_at(k, a), 0.0f, probe);
        for (int a = 0; a < 3; ++a) {
            const float v = point_at(k, a) / W;
            lo[a] = k == 0 ? v : (lo[a] < v ? lo[a] : v);
            hi[a] = k == 0 ? v : (hi[a] > v ? hi[a] : v);
        }
    }
    float box[3][2];  // [axis][0 = low, 1 = high]
    for (int a = 0; a < 3; ++a) {
        box[a][0] = lo[a] - d;
        box[a][1] = hi[a] + d;
    }
    // Corner index i*4 + j*2 + s: x from box[0][i], y from box[1][j], z from box[2][s].
    float clip[4][8];
    for (int r = 0; r < 4; ++r) {
        const Vec4 m = planes.clip_rows[r];
        float tz[2], tyz[4];
        for (int s = 0; s < 2; ++s) tz[s] = std::fma(m.z, box[2][s], m.w);
        for (int j = 0; j < 2; ++j)
            for (int s = 0; s < 2; ++s) tyz[j * 2 + s] = std::fma(m.y, box[1][j], tz[s]);
        for (int i = 0; i < 2; ++i)
            for (int js = 0; js < 4; ++js) clip[r][i * 4 + js] = std::fma(m.x, box[0][i], tyz[js]);
    }
    const auto plane_values = [&clip, &planes](int corner, float v[6]) {
        const float cx = clip[0][corner], cy = clip[1][corner], cz = clip[2][corner], cw = clip[3][corner];
        v[0] = cw + cx;
        v[1] = cw - cx;
        v[2] = cw + cy;
        v[3] = cw - cy;
        v[4] = cz + planes.near_w * cw;
        v[5] = planes.far_w * cw - cz;
    };
    float mx[6], v[6];
    plane_values(0, mx);
    for (int corner = 1; corner < 8; ++corner) {
        plane_values(corner, v);
        for (int q = 0; q < 6; ++q) mx[q] = mx[q] > v[q] ? mx[q] : v[q];
    }
    bool out = mx[5] < planes.far_limit;
    for (int q = 0; q < 5; ++q) out |= mx[q] < 0.0f;
    return out && probe == 0.0f;
}

}  // namespace patchcull::frustum_detail
