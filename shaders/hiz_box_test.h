// Hi-Z test of a screen box: hiz.h steps 5-9 (seed 000 §4.1.1), the GPU twin of
// hiz_rect_from_window_box, hiz_select_level and hiz_rect_max (src/core/hiz.cpp), operation by
// operation (pc_fma = std::fma, `a < b ? a : b` min/max, floor, integer shifts), so the decisions
// equal the CPU's. Shared by occlusion.comp.glsl (a patch's control-point box) and
// displaced.comp.glsl (a displaced patch's bound). The including shader includes exact_fma.h
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
