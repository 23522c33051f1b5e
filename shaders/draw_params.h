// shaders/draw_params.h (GLSL only; include after shared.h): the parameters of the patch and
// occluder draws (patch.*.glsl, occluder.*.glsl), declared once for every stage and both APIs.
// OpenGL: plain uniforms, set by name (src/gl/renderer_internal.h's DrawUniforms). Vulkan (the
// shaders compiled with PC_VULKAN and PC_VK_GRAPHICS, src/vk/CMakeLists.txt): one std140
// push-constant block of exactly 128 bytes, the same in every stage, whose C++ twin is
// src/vk/draw_params.h's DrawPushConstants. Also the vertex index (gl_VertexID in OpenGL,
// gl_VertexIndex in Vulkan: both count from the draw's first vertex) and, under Vulkan, the
// displacement map's binding (a number no storage buffer of the draws uses).
#ifndef PATCHCULL_SHADERS_DRAW_PARAMS_H
#define PATCHCULL_SHADERS_DRAW_PARAMS_H

#ifdef PC_VULKAN

#define PC_VERTEX_INDEX gl_VertexIndex
#define kTextureUnitDisplacement 31u

layout(push_constant, std140) uniform DrawParams {
    mat4 u_object_to_clip;          // offset 0
    vec3 u_eye;                     // 64: object-space eye position
    float u_tess_level;             // 76: uniform level (or the adaptive maximum), in [1, 64]
    uint u_draw_mask;               // 80
    uint u_draw_value;              // 84
    bool u_adaptive;                // 88
    float u_tess_reference;         // 92: distance at which the adaptive level is u_tess_level
    bool u_mark_drawn;              // 96: record drawn patches in patch_marks
    bool u_has_tangents;            // 100
    float u_displacement_scale;     // 104
    float u_displacement_midlevel;  // 108
    uint u_color_mode;              // 112
    bool u_discard_back_facing;     // 116
    bool u_displace;                // 120
    bool u_has_margins;             // 124
};

#else  // OpenGL

#define PC_VERTEX_INDEX gl_VertexID

uniform mat4 u_object_to_clip;
uniform vec3 u_eye;
uniform float u_tess_level;
uniform uint u_draw_mask;
uniform uint u_draw_value;
uniform bool u_adaptive;
uniform float u_tess_reference;
uniform bool u_mark_drawn;
uniform bool u_has_tangents;
uniform float u_displacement_scale;
uniform float u_displacement_midlevel;
uniform uint u_color_mode;
uniform bool u_discard_back_facing;
uniform bool u_displace;
uniform bool u_has_margins;

#endif

#endif  // PATCHCULL_SHADERS_DRAW_PARAMS_H
