// Occlusion-query proxy vertex shader (gl_object_queries.h): box gl_VertexID / 36 of the query
// boxes, as 12 triangles (36 vertices, no index buffer), drawn with GL_LEQUAL and no writes so
// that a query counts the samples where the box is not behind what was drawn before it.
#version 450 core
#include "shared.h"

layout(std430, binding = kBindingQueryBoxes) readonly buffer QueryBoxes {
    vec4 query_boxes[];  // box k: min at 2k, max at 2k + 1
};

uniform mat4 u_world_to_clip;

// The 36 corners of the 12 triangles, each a bit mask over (x, y, z): bit set = max side. The
// winding does not matter (face culling is off: a query must see every face).
const uint kCorners[36] = uint[36](0u, 1u, 3u, 0u, 3u, 2u,   // x = min
                                   4u, 6u, 7u, 4u, 7u, 5u,   // x = max
                                   0u, 4u, 5u, 0u, 5u, 1u,   // y = min
                                   2u, 3u, 7u, 2u, 7u, 6u,   // y = max
                                   0u, 2u, 6u, 0u, 6u, 4u,   // z = min
                                   1u, 5u, 7u, 1u, 7u, 3u);  // z = max

void main() {
    const uint box = uint(gl_VertexID) / 36u;
    const uint corner = kCorners[uint(gl_VertexID) % 36u];
    const vec3 lo = query_boxes[2u * box].xyz;
    const vec3 hi = query_boxes[2u * box + 1u].xyz;
    // corner bits: 4 = x, 2 = y, 1 = z
    const vec3 p = vec3((corner & 4u) != 0u ? hi.x : lo.x, (corner & 2u) != 0u ? hi.y : lo.y, (corner & 1u) != 0u ? hi.z : lo.z);
    gl_Position = u_world_to_clip * vec4(p, 1.0);
}
