// Triangle-mesh occluder fragment shader: id = kIdOccluderBit | triangle index, colour a neutral
// grey shaded two-sided by the angle to the eye (flat normal from screen-space derivatives).
#version 450 core
#include "shared.h"
#include "draw_params.h"

in vec3 occ_position;
flat in uint occ_triangle;

layout(location = 0) out vec4 out_color;
layout(location = 1) out uint out_id;

void main() {
    const vec3 n = cross(dFdx(occ_position), dFdy(occ_position));
    const float len = length(n);
    const vec3 to_eye = normalize(u_eye - occ_position);
    const float facing = len > 0.0 ? abs(dot(n / len, to_eye)) : 1.0;
    out_color = vec4(vec3(0.55, 0.53, 0.5) * (0.35 + 0.65 * facing), 1.0);
    out_id = kIdOccluderBit | occ_triangle;
}
