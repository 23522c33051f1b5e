// shaders/api.h (GLSL, included by pass_params.h; and C++, the Vulkan layer's numbers): what
// differs between the two APIs the cull passes' compute shaders are compiled for, in one place.
// Every pass has one GLSL source (shaders/*.comp.glsl); the OpenGL layer (src/gl) compiles it at
// run time as it is, the Vulkan layer (src/vk) compiles it to SPIR-V at build time with
// glslangValidator -V and PC_VULKAN defined, plus PC_VK_PUSH_<Block> or PC_VK_UNIFORM_<Block>
// naming the one parameter block the pass reads (src/vk/CMakeLists.txt's module list).
//
// - Parameter blocks (pass_params.h's PC_PARAMS). OpenGL: a std140 uniform block at its binding
//   (kUniformPassParams). Vulkan: the pass's own block is the push-constant block
//   (PC_VK_PUSH_<Block>: std140, the same bytes as the C++ struct; a stage has at most one) when
//   it fits the 128 bytes every device offers, else a std140 uniform buffer at set 0, binding
//   PC_VK_PARAMS_BINDING (PC_VK_UNIFORM_<Block>), which the pass writes with vkCmdUpdateBuffer;
//   every other block of pass_params.h becomes a plain global struct the shader never reads, so
//   no descriptor stands for it.
// - Storage buffers. Both APIs use shared.h's binding numbers; under Vulkan they are bindings
//   of descriptor set 0 (GLSL's default set), which the Vulkan passes fill with push descriptors.
// - Textures and images. GL's units (kTextureUnit*, kImageUnit*) share numbers with the storage
//   bindings; under Vulkan the Hi-Z pyramid's moves where a shader has both (below), in set 0.
// - Clip conventions. None in the shaders: the C++ side hands every pass its planes and rows
//   (FrustumPlanes, to_zero_to_one, to_depth_key of the caller's matrix in its ClipDepth), and a
//   Vulkan projection's y-down clip space (y negated) leaves the frustum planes' set unchanged
//   (w + y and w - y swap), so the decisions do not depend on it (docs/ENGINE.md, "Vulkan").
// - Draw parameters (draw_params.h: the patch and occluder draws of the renderers): plain uniforms
//   on OpenGL; on Vulkan one 128-byte push-constant block shared by every stage, gl_VertexIndex
//   for gl_VertexID, the displacement map at set-0 binding 31.
// - Not (yet) under Vulkan: the passes over a GpuPatchSource (a second parameter block).
#ifndef PATCHCULL_SHADERS_API_H
#define PATCHCULL_SHADERS_API_H

#ifdef __cplusplus
// The Vulkan layer's numbers for the C++ side (src/vk), the same as the GLSL macros below.
#include <cstdint>
namespace patchcull::vk::api {
inline constexpr std::uint32_t kParamsBinding = 4u;
inline constexpr std::uint32_t kTextureHiZBinding = 3u;  // occlusion, fused, displaced (not hiz_build)
}  // namespace patchcull::vk::api
#elif defined(PC_VULKAN)

#ifdef PC_PATCH_SOURCE
#error "api.h: the passes over a patch source are not compiled for Vulkan"
#endif

#define PC_PARAMS(name, slot) PC_VK_PARAMS_##name

// The binding of a parameter block read as a uniform buffer (PC_VK_UNIFORM_<Block>): a number no
// storage buffer or texture of those passes (occlusion, fused, displaced) uses.
#define PC_VK_PARAMS_BINDING 4

// Textures: in the passes with per-patch storage buffers (occlusion, fused, displaced) the Hi-Z
// pyramid's unit (2, kBindingMaxDisplacement's number in GL) becomes set-0 binding 3, which no
// storage buffer of theirs uses; the name then stands for it in the shader that follows (declared
// once in shared.h as a const). hiz_build.comp.glsl, with no buffers, keeps shared.h's units 0, 1
// and 2 (lavapipe 22.3 crashed recording its dispatch with them at 4, 5, 6 or 33, 34, 40).
#if defined(PC_VK_UNIFORM_OcclusionParams) || defined(PC_VK_UNIFORM_FusedCullParams) || \
    defined(PC_VK_UNIFORM_DisplacedParams)
#define kTextureUnitHiZ 3u
#endif

#if defined(PC_VK_PUSH_FrustumParams)
#define PC_VK_PARAMS_FrustumParams layout(push_constant, std140) uniform FrustumParams
#elif defined(PC_VK_UNIFORM_FrustumParams)
#define PC_VK_PARAMS_FrustumParams layout(std140, set = 0, binding = PC_VK_PARAMS_BINDING) uniform FrustumParams
#else
#define PC_VK_PARAMS_FrustumParams struct FrustumParams
#endif
#if defined(PC_VK_PUSH_FrustumDispParams)
#define PC_VK_PARAMS_FrustumDispParams layout(push_constant, std140) uniform FrustumDispParams
#elif defined(PC_VK_UNIFORM_FrustumDispParams)
#define PC_VK_PARAMS_FrustumDispParams layout(std140, set = 0, binding = PC_VK_PARAMS_BINDING) uniform FrustumDispParams
#else
#define PC_VK_PARAMS_FrustumDispParams struct FrustumDispParams
#endif
#if defined(PC_VK_PUSH_OcclusionParams)
#define PC_VK_PARAMS_OcclusionParams layout(push_constant, std140) uniform OcclusionParams
#elif defined(PC_VK_UNIFORM_OcclusionParams)
#define PC_VK_PARAMS_OcclusionParams layout(std140, set = 0, binding = PC_VK_PARAMS_BINDING) uniform OcclusionParams
#else
#define PC_VK_PARAMS_OcclusionParams struct OcclusionParams
#endif
#if defined(PC_VK_PUSH_HiZBuildParams)
#define PC_VK_PARAMS_HiZBuildParams layout(push_constant, std140) uniform HiZBuildParams
#elif defined(PC_VK_UNIFORM_HiZBuildParams)
#define PC_VK_PARAMS_HiZBuildParams layout(std140, set = 0, binding = PC_VK_PARAMS_BINDING) uniform HiZBuildParams
#else
#define PC_VK_PARAMS_HiZBuildParams struct HiZBuildParams
#endif
#if defined(PC_VK_PUSH_BackpatchConeParams)
#define PC_VK_PARAMS_BackpatchConeParams layout(push_constant, std140) uniform BackpatchConeParams
#elif defined(PC_VK_UNIFORM_BackpatchConeParams)
#define PC_VK_PARAMS_BackpatchConeParams layout(std140, set = 0, binding = PC_VK_PARAMS_BINDING) uniform BackpatchConeParams
#else
#define PC_VK_PARAMS_BackpatchConeParams struct BackpatchConeParams
#endif
#if defined(PC_VK_PUSH_BackpatchPtpParams)
#define PC_VK_PARAMS_BackpatchPtpParams layout(push_constant, std140) uniform BackpatchPtpParams
#elif defined(PC_VK_UNIFORM_BackpatchPtpParams)
#define PC_VK_PARAMS_BackpatchPtpParams layout(std140, set = 0, binding = PC_VK_PARAMS_BINDING) uniform BackpatchPtpParams
#else
#define PC_VK_PARAMS_BackpatchPtpParams struct BackpatchPtpParams
#endif
#if defined(PC_VK_PUSH_DisplacedParams)
#define PC_VK_PARAMS_DisplacedParams layout(push_constant, std140) uniform DisplacedParams
#elif defined(PC_VK_UNIFORM_DisplacedParams)
#define PC_VK_PARAMS_DisplacedParams layout(std140, set = 0, binding = PC_VK_PARAMS_BINDING) uniform DisplacedParams
#else
#define PC_VK_PARAMS_DisplacedParams struct DisplacedParams
#endif
#if defined(PC_VK_PUSH_CullStatusParams)
#define PC_VK_PARAMS_CullStatusParams layout(push_constant, std140) uniform CullStatusParams
#elif defined(PC_VK_UNIFORM_CullStatusParams)
#define PC_VK_PARAMS_CullStatusParams layout(std140, set = 0, binding = PC_VK_PARAMS_BINDING) uniform CullStatusParams
#else
#define PC_VK_PARAMS_CullStatusParams struct CullStatusParams
#endif
#if defined(PC_VK_PUSH_CompactParams)
#define PC_VK_PARAMS_CompactParams layout(push_constant, std140) uniform CompactParams
#elif defined(PC_VK_UNIFORM_CompactParams)
#define PC_VK_PARAMS_CompactParams layout(std140, set = 0, binding = PC_VK_PARAMS_BINDING) uniform CompactParams
#else
#define PC_VK_PARAMS_CompactParams struct CompactParams
#endif
#if defined(PC_VK_PUSH_FusedCullParams)
#define PC_VK_PARAMS_FusedCullParams layout(push_constant, std140) uniform FusedCullParams
#elif defined(PC_VK_UNIFORM_FusedCullParams)
#define PC_VK_PARAMS_FusedCullParams layout(std140, set = 0, binding = PC_VK_PARAMS_BINDING) uniform FusedCullParams
#else
#define PC_VK_PARAMS_FusedCullParams struct FusedCullParams
#endif

// The draw shaders' parameters (shaders/draw_params.h, compiled with PC_VK_GRAPHICS: the headless
// renderer's patch and occluder draws): one std140 push-constant block of every stage; the vertex
// index; the displacement map's binding, a number no storage buffer of the draws uses.
#define PC_DRAW_PARAMS_BEGIN layout(push_constant, std140) uniform DrawParams {
#define PC_DRAW_PARAMS_END };
#define PC_DRAW_PARAM
#define PC_VERTEX_INDEX gl_VertexIndex
#ifdef PC_VK_GRAPHICS
#define kTextureUnitDisplacement 31u
#endif

#else  // OpenGL

#define PC_PARAMS(name, slot) layout(std140, binding = slot) uniform name
// The draw shaders' parameters are plain uniforms, set by name; gl_VertexID counts from the draw's
// first vertex as gl_VertexIndex does.
#define PC_DRAW_PARAMS_BEGIN
#define PC_DRAW_PARAMS_END
#define PC_DRAW_PARAM uniform
#define PC_VERTEX_INDEX gl_VertexID

#endif

#endif  // PATCHCULL_SHADERS_API_H
