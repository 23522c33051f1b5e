// shaders/api.h (GLSL only; included by pass_params.h): what differs between the two APIs the
// cull passes' compute shaders are compiled for, in one place. Every pass has one GLSL source
// (shaders/*.comp.glsl); the OpenGL layer (src/gl) compiles it at run time as it is, the Vulkan
// layer (src/vk) compiles it to SPIR-V at build time with glslangValidator -V and PC_VULKAN
// defined, plus PC_VK_PUSH_<Block> naming the one parameter block the pass reads.
//
// - Parameter blocks (pass_params.h's PC_PARAMS). OpenGL: a std140 uniform block at its binding
//   (kUniformPassParams). Vulkan: the pass's own block (PC_VK_PUSH_<Block>) is the push-constant
//   block (std140 layout, the same bytes as the C++ struct; a stage has at most one), and every
//   other block of pass_params.h becomes a plain global struct the shader never reads, so no
//   descriptor stands for it. The blocks above 128 bytes (maxPushConstantsSize's guaranteed
//   minimum) are refused by the Vulkan layer where the device's limit is smaller.
// - Storage buffers. Both APIs use shared.h's binding numbers; under Vulkan they are bindings
//   of descriptor set 0 (GLSL's default set), which the Vulkan passes fill with push descriptors.
//   No uniform block or sampler of a Vulkan pass shares set 0 with them.
// - Clip conventions. None in the shaders: the C++ side hands every pass its planes and rows
//   (FrustumPlanes, to_zero_to_one, to_depth_key of the caller's matrix in its ClipDepth), and a
//   Vulkan projection's y-down clip space (y negated) leaves the frustum planes' set unchanged
//   (w + y and w - y swap), so the decisions do not depend on it (docs/ENGINE.md, "Vulkan").
// - Not (yet) under Vulkan: the passes over a GpuPatchSource (a second parameter block) and the
//   passes that sample textures or write images (their units are not set-0 bindings here).
#ifndef PATCHCULL_SHADERS_API_H
#define PATCHCULL_SHADERS_API_H

#ifdef PC_VULKAN

#ifdef PC_PATCH_SOURCE
#error "api.h: the passes over a patch source are not compiled for Vulkan"
#endif

#define PC_PARAMS(name, slot) PC_VK_PARAMS_##name

#ifdef PC_VK_PUSH_FrustumParams
#define PC_VK_PARAMS_FrustumParams layout(push_constant, std140) uniform FrustumParams
#else
#define PC_VK_PARAMS_FrustumParams struct FrustumParams
#endif
#ifdef PC_VK_PUSH_FrustumDispParams
#define PC_VK_PARAMS_FrustumDispParams layout(push_constant, std140) uniform FrustumDispParams
#else
#define PC_VK_PARAMS_FrustumDispParams struct FrustumDispParams
#endif
#ifdef PC_VK_PUSH_OcclusionParams
#define PC_VK_PARAMS_OcclusionParams layout(push_constant, std140) uniform OcclusionParams
#else
#define PC_VK_PARAMS_OcclusionParams struct OcclusionParams
#endif
#ifdef PC_VK_PUSH_HiZBuildParams
#define PC_VK_PARAMS_HiZBuildParams layout(push_constant, std140) uniform HiZBuildParams
#else
#define PC_VK_PARAMS_HiZBuildParams struct HiZBuildParams
#endif
#ifdef PC_VK_PUSH_BackpatchConeParams
#define PC_VK_PARAMS_BackpatchConeParams layout(push_constant, std140) uniform BackpatchConeParams
#else
#define PC_VK_PARAMS_BackpatchConeParams struct BackpatchConeParams
#endif
#ifdef PC_VK_PUSH_BackpatchPtpParams
#define PC_VK_PARAMS_BackpatchPtpParams layout(push_constant, std140) uniform BackpatchPtpParams
#else
#define PC_VK_PARAMS_BackpatchPtpParams struct BackpatchPtpParams
#endif
#ifdef PC_VK_PUSH_DisplacedParams
#define PC_VK_PARAMS_DisplacedParams layout(push_constant, std140) uniform DisplacedParams
#else
#define PC_VK_PARAMS_DisplacedParams struct DisplacedParams
#endif
#ifdef PC_VK_PUSH_CullStatusParams
#define PC_VK_PARAMS_CullStatusParams layout(push_constant, std140) uniform CullStatusParams
#else
#define PC_VK_PARAMS_CullStatusParams struct CullStatusParams
#endif
#ifdef PC_VK_PUSH_CompactParams
#define PC_VK_PARAMS_CompactParams layout(push_constant, std140) uniform CompactParams
#else
#define PC_VK_PARAMS_CompactParams struct CompactParams
#endif
#ifdef PC_VK_PUSH_FusedCullParams
#define PC_VK_PARAMS_FusedCullParams layout(push_constant, std140) uniform FusedCullParams
#else
#define PC_VK_PARAMS_FusedCullParams struct FusedCullParams
#endif

#else  // OpenGL

#define PC_PARAMS(name, slot) layout(std140, binding = slot) uniform name

#endif

#endif  // PATCHCULL_SHADERS_API_H
