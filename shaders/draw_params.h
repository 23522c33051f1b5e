// shaders/draw_params.h (GLSL only; include after shared.h): the parameters of the patch and
// occluder draws (patch.*.glsl, occluder.*.glsl), declared once for every stage and both APIs.
// api.h says how each API holds them: plain uniforms on OpenGL (set by name:
// src/gl/renderer_internal.h's DrawUniforms); on Vulkan (compiled with PC_VULKAN and
// PC_VK_GRAPHICS, src/vk/CMakeLists.txt) one std140 push-constant block of exactly 128 bytes, the
// same in every stage, whose C++ twin is src/vk/draw_pipelines.h's DrawPushConstants (offsets in
// the comments). api.h also gives PC_VERTEX_INDEX (gl_VertexID / gl_VertexIndex) and, on Vulkan,
// the displacement map's binding.
#ifndef PATCHCULL_SHADERS_DRAW_PARAMS_H
#define PATCHCULL_SHADERS_DRAW_PARAMS_H

#include "api.h"

PC_DRAW_PARAMS_BEGIN
PC_DRAW_PARAM mat4 u_object_to_clip;          // 0
PC_DRAW_PARAM vec3 u_eye;                     // 64: object-space eye position
PC_DRAW_PARAM float u_tess_level;             // 76: uniform level (or the adaptive maximum), in [1, 64]
PC_DRAW_PARAM uint u_draw_mask;               // 80: drawn iff (flag word & mask) == value
PC_DRAW_PARAM uint u_draw_value;              // 84
PC_DRAW_PARAM bool u_adaptive;                // 88
PC_DRAW_PARAM float u_tess_reference;         // 92: distance at which the adaptive level is u_tess_level
PC_DRAW_PARAM bool u_mark_drawn;              // 96: record drawn patches in patch_marks
PC_DRAW_PARAM bool u_has_tangents;            // 100
PC_DRAW_PARAM float u_displacement_scale;     // 104
PC_DRAW_PARAM float u_displacement_midlevel;  // 108
PC_DRAW_PARAM uint u_color_mode;              // 112
PC_DRAW_PARAM bool u_discard_back_facing;     // 116
PC_DRAW_PARAM bool u_displace;                // 120
PC_DRAW_PARAM bool u_has_margins;             // 124
PC_DRAW_PARAMS_END

#endif  // PATCHCULL_SHADERS_DRAW_PARAMS_H
