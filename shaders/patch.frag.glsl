// Patch fragment shader: patch id = patch index + 1 (0 is the background); colour = a per-patch
// hue (kColorPatch) or the patch's status in its flag word (kColorStatus, the legend of
// gl_renderer.h's render_status_image), shaded two-sided by the angle to the eye.
#version 450 core
#include "shared.h"

layout(std430, binding = kBindingCullFlags) readonly buffer CullFlags {
    uint cull_flags[];
};

uniform vec3 u_eye;  // object-space eye position
uniform uint u_color_mode;

in vec3 tes_position;
in vec3 tes_normal;
flat in uint tes_patch;

layout(location = 0) out vec4 out_color;
layout(location = 1) out uint out_id;

vec3 patch_hue(uint p) {
    uint h = p * 0x9E3779B9u;
    h ^= h >> 16;
    h *= 0x85EBCA6Bu;
    h ^= h >> 13;
    return 0.35 + 0.65 * vec3(float(h & 255u), float((h >> 8) & 255u), float((h >> 16) & 255u)) / 255.0;
}

vec3 status_color(uint word) {
    if ((word & kCullFrustum) != 0u) return vec3(0.25, 0.45, 1.0);    // blue: frustum-culled
    if ((word & kCullBackPatch) != 0u) return vec3(0.85, 0.3, 0.9);   // magenta: back-patch-culled
    if ((word & kCullOcclusion) != 0u) return vec3(1.0, 0.2, 0.15);   // red: occlusion-culled
    if ((word & kStatusNewlyVisible) != 0u) return vec3(1.0, 0.85, 0.1);  // yellow: newly visible
    if ((word & kStatusVisible) != 0u) return vec3(0.2, 0.85, 0.3);   // green: visible
    return vec3(0.6, 0.6, 0.6);                                        // grey: no status yet
}

void main() {
    const float len = length(tes_normal);
    const vec3 to_eye = normalize(u_eye - tes_position);
    const float facing = len > 0.0 ? abs(dot(tes_normal / len, to_eye)) : 1.0;
    const vec3 base = u_color_mode == kColorStatus ? status_color(cull_flags[tes_patch]) : patch_hue(tes_patch);
    out_color = vec4(base * (0.25 + 0.75 * facing), 1.0);
    out_id = tes_patch + 1u;
}
