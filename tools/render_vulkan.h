// `patchcull render --api vulkan`: the render command's frames on Vulkan (vk/vk_renderer.h's
// CullRenderer on a headless device, lavapipe without a GPU), with the same scene, cameras,
// camera-relative frames, tests and --verify as the OpenGL pipeline, one object per frame (the
// whole scene). Output: cmd_render.cpp's JSON keys that apply, with "api":"vulkan",
// "renderer" (the device's name) and "validation_messages" (--vk-validation: the Khronos
// validation layer's messages; any fails the run with exit status 1, each printed on stderr).
#pragma once

#include <string>
#include <vector>

#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/camera.h"
#include "patchcull/core/clip_space.h"
#include "patchcull/import/scene_model.h"
#include "render_options.h"

namespace patchcull::cli {

/// What cmd_render.cpp hands over once the scene is loaded (and rebased when its frames move).
struct VulkanRenderJob {
    Scene* scene = nullptr;            ///< in the float frame of frame 0
    const Scene* world = nullptr;      ///< the placements in world coordinates, when frames move (else null)
    std::vector<DVec3> frame_origins;  ///< per frame
    std::vector<Camera> cameras;       ///< per frame, in its frame (depth set)
    int width = 0, height = 0, tess = 8, frames = 1;
    TessMode tess_mode;
    std::uint32_t tests = 0;  ///< the applied cull mode's kCull* bits
    std::string cull_name, backpatch_name;
    BackpatchMethod backpatch = BackpatchMethod::tcone;
    DisplacedBoundKind bound = DisplacedBoundKind::caf;
    NormalConeKind cone = NormalConeKind::acon;
    std::string bound_name, cone_name, frustum_name, draw_name, compact_name;
    bool frustum_aabb = false, fused_pass = false, indirect = true, scan = true;
    bool aggressive = false, verify = false, json = false, validation = false;
    bool prefer_gpu = false;                               ///< --vk-device gpu
    DriverThreads driver_threads = DriverThreads::spread;  ///< --driver-threads
    std::string out;                                       ///< PNG of the last frame's colour, or empty
};

/// Runs the frames; returns the exit status (1 on a false cull or a validation message).
/// Throws patchcull::Error (one line) when Vulkan is missing or a call fails.
int run_vulkan_render(const VulkanRenderJob& job);

}  // namespace patchcull::cli
