// examples/06_vulkan/common.glsl: what the example's four patch shaders share (included with
// GL_GOOGLE_include_directive; compiled by glslangValidator at build time, examples/CMakeLists.txt).
// None of it is patchcull's: the engine's own draw of the patches the passes left.

// One push-constant block for every stage (88 bytes; the program pushes it before each draw).
layout(push_constant) uniform DrawParams {
    mat4 object_to_clip;  // the y-DOWN Vulkan projection (its y row negated) * view
    vec4 eye_level;       // xyz: the eye in the patches' (world) space; w: the tessellation level
    uvec2 one_sided;      // the patches [x, y) are drawn one-sided (the closed, back-patch-tested object)
} u;

// Set 0, pushed by vkCmdPushDescriptorSetKHR. The patch buffer is the one the passes read (16 vec4
// per patch, 256 bytes); the draw list is CompactPass's (or, for the unculled reference, 0..n-1).
layout(std430, set = 0, binding = 0) readonly buffer ControlPoints { vec4 control_points[]; };
layout(std430, set = 0, binding = 1) readonly buffer DrawList { uint draw_list[]; };

// The bicubic rational Bezier patch at (u, v), control point (i, j) (i along u) at cp[4 j + i]
// (patchcull/core/patch.h's order): its point p and its derivatives pu, pv. The TES positions the
// tessellated vertices with it; the fragment shader re-evaluates it for the one-sided rule.
void bernstein(float t, out vec4 b, out vec4 db) {
    float s = 1.0 - t;
    b = vec4(s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t);
    db = vec4(-3.0 * s * s, 3.0 * s * s - 6.0 * t * s, 6.0 * t * s - 3.0 * t * t, 3.0 * t * t);
}

void evaluate_patch(vec4 cp[16], vec2 uv, out vec3 p, out vec3 pu, out vec3 pv) {
    vec4 bu, dbu, bv, dbv;
    bernstein(uv.x, bu, dbu);
    bernstein(uv.y, bv, dbv);
    vec4 h = vec4(0.0), hu = vec4(0.0), hv = vec4(0.0);
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            vec4 c = cp[4 * j + i];
            h += bu[i] * bv[j] * c;
            hu += dbu[i] * bv[j] * c;
            hv += bu[i] * dbv[j] * c;
        }
    p = h.xyz / h.w;
    pu = (hu.xyz - p * hu.w) / h.w;
    pv = (hv.xyz - p * hv.w) / h.w;
}
