// Hi-Z test of a screen box: hiz.h steps 5-9 (Niessner & Loop §4.1.1), the GPU twin of
// hiz_rect_from_window_box, hiz_select_level and hiz_rect_max (src/core/hiz.cpp), operation by
// operation (pc_fma = std::fma, `a < b ? a : b` min/max, floor, integer shifts), so the decisions
// equal the CPU's; and steps 3-4 per control point (hiz_add_point). Shared by occlusion.comp.glsl
// and fused_cull.comp.glsl (a patch's control-point box) and displaced.comp.glsl (a displaced
// patch's bound). The including shader includes exact_fma.h
// first and declares the pyramid: uniform ivec2 u_screen (W, H: its depth buffer, viewport
// 0,0,W,H), uniform int u_hiz_levels (HiZPyramid::level_count(W, H)), sampler2D u_hiz.

float hiz_min(float a, float b) {
    precise float r = a < b ? a : b;
    return r;
}
float hiz_max(float a, float b) {
    precise float r = a > b ? a : b;
    return r;
}

// a / b correctly rounded (IEEE), as the CPU's float division. GLSL allows 2.5 ulp for float
// division, so it is computed in double and rounded once to float: for float a, b the exact
// quotient lies at least 2^-49 (relative) from every midpoint between two floats (a/b = midpoint
// m would need m*b, with m's odd 25-bit significand, to fit a 24-bit significand), farther than
// the error of any double division within 16 double ulps (2^-48 relative); so the float nearest
// to the double quotient is the float nearest to a/b.
float hiz_div(float a, float b) {
    precise double q = double(a) / double(b);
    return float(q);
}

// 2^-20: step 3's safety factor (hiz.cpp kWSafety).
const float kHiZWSafety = 9.5367431640625e-07;

// The NDC box and front plane of a patch's control points (steps 3-4), point by point.
struct HiZPointBox {
    float nxmin, nxmax, nymin, nymax, zmin;
};

// Steps 3-4 for control point P (object space) with clip coordinates c (step 2, pc_clip_point's
// operations), w_row being the clip matrix's w row: false when P is not provably in front of the
// eye (the patch is then not screen-tested: step 3); else P's NDC point joins box (starts it
// when first). The CPU's patch_bounds (src/core/hiz.cpp), operation by operation.
bool hiz_add_point(const vec4 P, const vec4 c, const vec4 w_row, bool first, inout HiZPointBox box) {
    precise float s = abs(w_row.x) * abs(P.x);
    s = pc_fma(abs(w_row.y), abs(P.y), s);
    s = pc_fma(abs(w_row.z), abs(P.z), s);
    s = pc_fma(abs(w_row.w), abs(P.w), s);
    precise float bound = kHiZWSafety * s;
    if (!(c.w > bound)) return false;
    const float nx = hiz_div(c.x, c.w);
    const float ny = hiz_div(c.y, c.w);
    const float nz = hiz_div(c.z, c.w);
    if (first) {
        box.nxmin = nx;
        box.nxmax = nx;
        box.nymin = ny;
        box.nymax = ny;
        box.zmin = nz;
    } else {
        box.nxmin = hiz_min(box.nxmin, nx);
        box.nxmax = hiz_max(box.nxmax, nx);
        box.nymin = hiz_min(box.nymin, ny);
        box.nymax = hiz_max(box.nymax, ny);
        box.zmin = hiz_min(box.zmin, nz);
    }
    return true;
}

// True when the NDC box [ndc_xmin, ndc_xmax] x [ndc_ymin, ndc_ymax] at depth depth_near (its
// nearest point) lies behind the pyramid: every texel of its (at most 2x2) footprint is strictly
// nearer.
bool hiz_box_occluded(float ndc_xmin, float ndc_xmax, float ndc_ymin, float ndc_ymax, float depth_near) {
    // Step 5: window box.
    const float half_w = 0.5 * float(u_screen.x), half_h = 0.5 * float(u_screen.y);
    precise float xlo = pc_fma(ndc_xmin, half_w, half_w);
    precise float xhi = pc_fma(ndc_xmax, half_w, half_w);
    precise float ylo = pc_fma(ndc_ymin, half_h, half_h);
    precise float yhi = pc_fma(ndc_ymax, half_h, half_h);
    // Step 6: pixel rectangle, clamped in float (hiz_rect_from_window_box).
    const float wmax = float(u_screen.x - 1), hmax = float(u_screen.y - 1);
    const int x0 = int(hiz_min(hiz_max(floor(xlo), 0.0), wmax));
    const int x1 = int(hiz_min(hiz_max(floor(xhi), 0.0), wmax));
    const int y0 = int(hiz_min(hiz_max(floor(ylo), 0.0), hmax));
    const int y1 = int(hiz_min(hiz_max(floor(yhi), 0.0), hmax));
    // Step 7: level (hiz_select_level): Lc = bit_width(span - 1) - 1 = findMSB(span - 1).
    const int span = max(x1 - x0, y1 - y0);
    int level = span <= 2 ? 0 : findMSB(uint(span - 1));
    if (level > 0) {
        const int sh = level;  // shift of level - 1
        if ((x1 >> sh) - (x0 >> sh) <= 1 && (y1 >> sh) - (y0 >> sh) <= 1) --level;
    }
    level = min(level, u_hiz_levels - 1);
    // Step 8: max of the (at most) 2x2 texels, in hiz_rect_max's order.
    const int sh = level + 1;
    const int tx0 = x0 >> sh, tx1 = x1 >> sh, ty0 = y0 >> sh, ty1 = y1 >> sh;
    const float t00 = texelFetch(u_hiz, ivec2(tx0, ty0), level).r;
    const float t10 = texelFetch(u_hiz, ivec2(tx1, ty0), level).r;
    const float t01 = texelFetch(u_hiz, ivec2(tx0, ty1), level).r;
    const float t11 = texelFetch(u_hiz, ivec2(tx1, ty1), level).r;
    const float h = hiz_max(hiz_max(t00, t10), hiz_max(t01, t11));
    // Step 9: strictly nearer everywhere.
    return h < depth_near;
}
