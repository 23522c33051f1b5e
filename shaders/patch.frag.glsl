// Patch fragment shader: colour = a per-patch hue shaded two-sided by the angle to the eye;
// patch id = patch index + 1 (0 is the background).
#version 450 core
#include "shared.h"

uniform vec3 u_eye;  // object-space eye position

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

void main() {
    const float len = length(tes_normal);
    const vec3 to_eye = normalize(u_eye - tes_position);
    const float facing = len > 0.0 ? abs(dot(tes_normal / len, to_eye)) : 1.0;
    out_color = vec4(patch_hue(tes_patch) * (0.25 + 0.75 * facing), 1.0);
    out_id = tes_patch + 1u;
}
