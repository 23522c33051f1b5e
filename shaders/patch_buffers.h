// shaders/patch_buffers.h (GLSL only; include once, after shared.h, whose binding points it uses,
// and before the headers that use its blocks: flag_chain.h, patch_displaced.h, frustum_test.h):
// the std430 storage blocks of the per-patch buffers that the cull passes and the draws share,
// declared here once.
//
// A shader picks the blocks it uses by defining, before the include, each one's macro as the
// block's memory qualifier: `readonly`, `writeonly`, or nothing (read-write). A block whose macro
// is not defined is not declared. Example (a cull pass of the flag chain):
//     #define PC_CONTROL_POINTS readonly
//     #define PC_CULL_FLAGS
//     #define PC_MAX_DISPLACEMENT readonly
// The build inlines each include once per shader (cmake/GlShaders.cmake): a later include of this
// file is empty, so define every macro before the first.
// Blocks with a single user, or that are not per patch (counters, query boxes, occluder vertices,
// the passes' diagnostics and inputs), stay in their shaders, at their shared.h binding points.
#ifndef PATCHCULL_SHADERS_PATCH_BUFFERS_H
#define PATCHCULL_SHADERS_PATCH_BUFFERS_H

#ifdef PC_CONTROL_POINTS
layout(std430, binding = kBindingControlPoints) PC_CONTROL_POINTS buffer ControlPoints {
    vec4 control_points[];  // patch p's point k at 16p + k (patch.h order)
};
#endif
#ifdef PC_CULL_FLAGS
layout(std430, binding = kBindingCullFlags) PC_CULL_FLAGS buffer CullFlags {
    uint cull_flags[];  // the flag word per patch (cull_flags.h); a pass touches its own patch's only
};
#endif
#ifdef PC_MAX_DISPLACEMENT
layout(std430, binding = kBindingMaxDisplacement) PC_MAX_DISPLACEMENT buffer MaxDisplacement {
    float max_displacement[];  // margin per patch, >= 0 (a bound on |D|; 0 = not displaced)
};
#endif
#ifdef PC_PATCH_TEXCOORDS
layout(std430, binding = kBindingPatchTexcoords) PC_PATCH_TEXCOORDS buffer PatchTexcoords {
    vec2 patch_texcoords[];  // 4 per patch: (u,v) = (0,0), (1,0), (0,1), (1,1)
};
#endif
#ifdef PC_PLANE_VALUES
layout(std430, binding = kBindingPlaneValues) PC_PLANE_VALUES buffer PlaneValues {
    float plane_values[];  // frustum diagnostics: 6 per patch
};
#endif
#ifdef PC_PATCH_TANGENTS
layout(std430, binding = kBindingPatchTangents) PC_PATCH_TANGENTS buffer PatchTangents {
    vec4 patch_tangents[];  // kTangentVec4s per patch: du[12], dv[12]; [0].w = 1 when present
};
#endif
#ifdef PC_PATCH_MARKS
layout(std430, binding = kBindingPatchMarks) PC_PATCH_MARKS buffer PatchMarks {
    uint patch_marks[];  // 1 for each patch the draw (or the mark-front pass) marked
};
#endif
#ifdef PC_PATCH_TESS_SCALE
layout(std430, binding = kBindingPatchTessScale) PC_PATCH_TESS_SCALE buffer PatchTessScale {
    float patch_tess_scale[];  // uniform tessellation level scale per patch
};
#endif

#endif  // PATCHCULL_SHADERS_PATCH_BUFFERS_H
