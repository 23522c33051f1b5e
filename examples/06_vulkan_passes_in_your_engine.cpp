// examples/06_vulkan_passes_in_your_engine.cpp: patchcull's Vulkan cull passes
// (patchcull/vk/vk_passes.h, library patchcull_vk) in a program that is NOT patchcull's renderer:
// it creates its own VkInstance and VkDevice (headless, no window), owns every VkBuffer, VkImage,
// command buffer and pipeline, draws with its own tessellation shaders (examples/06_vulkan/*.glsl,
// compiled to SPIR-V at build time) and records only the passes into its command buffer. This is
// what an engine on Vulkan does to adopt them (docs/ENGINE.md, "Vulkan").
//
// The device: the first physical device with Vulkan 1.3 (dynamic rendering), VK_KHR_push_descriptor
// (the passes push their descriptors), shaderFloat64 (the passes' exact fma, bit-identical to the
// CPU kernels' std::fma), tessellationShader, multiDrawIndirect and drawIndirectCount (our draw of
// the survivors). VK_LAYER_KHRONOS_validation with synchronization validation, when installed, and
// a debug messenger: any warning or error it reports is printed and fails the run.
//
// The scene, one patch buffer with two objects, each a range [first, first + count) that the
// passes are given separately (PatchBuffers::first/count):
//   teapot   the Utah teapot split twice (512 patches): an OPEN surface (the lid sits loose in the
//            rim), drawn two-sided, never back-patch tested;
//   bigguy   BigGuy (data/models, ACC patches through patchcull's import layer): a CLOSED,
//            outward-oriented surface, drawn ONE-SIDED by the exact surface (our fragment shader,
//            patch.frag.glsl) and back-patch tested (Loop, Niessner & Eisenacher, "Effective
//            Back-Patch Culling for Hardware Tessellation": tcone).
//
// Per frame, one command buffer records Niessner & Loop's two-pass occlusion-culling frame
// ("Patch-Based Occlusion Culling for Hardware Tessellation", §3):
//   1. CompactPass lists the patches the previous frame tagged visible (kStatusVisible) into OUR
//      list + VkDrawIndirectCommand + draw-count buffers; our pipeline draws them
//      (vkCmdDrawIndirectCount) into OUR R32_UINT id image and D32_SFLOAT depth image
//   2. HiZBuildPass builds the pyramid (OUR image) from that depth image
//   3. the flag chain: CullStatusPass::begin; FrustumPass (all); BackpatchConePass (tcone, bigguy
//      only); OcclusionPass (all, against the pyramid); CullStatusPass::end
//   4. CompactPass lists the patches that became visible in step 3 (kStatusNewlyVisible) and our
//      pipeline draws them into the same images
// and then, in the same command buffer, the same pipeline draws EVERY patch (a list 0..n-1) into
// the same images for the check: every patch whose id shows in that unculled image must have been
// drawn in step 1 or 4 (else a false cull), and the id and depth images must be equal (bar exact
// depth ties between two drawn patches, which the draw order decides).
//
// Vulkan's conventions: a y-DOWN projection (patchcull's perspective(), its y row negated) and
// ClipDepth::zero_to_one, in a CullView made from it (make_cull_view); the frustum and back-patch
// decisions do not depend on the flip, and the pyramid's row r is the depth image's row r
// (vk_passes.h, "Clip conventions").
//
// Usage: 06_vulkan_passes_in_your_engine [--frames N] [--size WxH] [--no-validation]
//            [--aggressive] [--backpatch-open]
//   --frames N    frames per camera position (3 positions, the camera moving), N in 1..1000, default 2
//   --size WxH    image size, each in 1..4096, default 320x240
//   --no-validation  do not enable VK_LAYER_KHRONOS_validation (it is enabled when installed)
//   --aggressive  skip step 4 (Niessner & Loop §3.1's aggressive variant). NOT conservative: the
//                 patches newly visible in a frame are missing; shows that the check catches it.
//   --backpatch-open  give the OPEN teapot to BackpatchConePass too. NOT conservative (from above,
//                 the inside of its far side shows through the lid gap): shows that the check
//                 catches a back-patch test on a surface it does not hold for.
// Prints one line per frame (patches culled per pass, from the flag words; patches drawn; whether
// the ids match). Exit status: 0 every frame matched; 1 a frame did not, a validation message, or
// a cull pass that culled nothing over the run (the check would prove nothing about it); 2 a setup
// error (bad option, no suitable Vulkan device, a model file missing), with one line on stderr.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <functional>
#include <string>
#include <vector>

#include "patchcull/core/cull_flags.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/error.h"
#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"
#include "patchcull/core/teapot.h"
#include "patchcull/import/model_loader.h"
#include "patchcull/vk/vk_passes.h"  // includes <vulkan/vulkan.h>

namespace pc = patchcull;

// The SPIR-V of examples/06_vulkan/patch.{vert,tesc,tese,frag}.glsl, in that order: words and byte
// sizes, defined by a source file examples/CMakeLists.txt generates from glslangValidator's output.
namespace example06 {
extern const std::uint32_t* const kSpirvWords[4];
extern const std::size_t kSpirvBytes[4];
}  // namespace example06

namespace {

// ---- setup errors: one line, exit status 2 ---------------------------------------------------

struct SetupError {
    std::string message;
};

[[noreturn]] void setup_error(const std::string& message) { throw SetupError{message}; }

void check(VkResult result, const char* call) {
    if (result != VK_SUCCESS)
        setup_error(std::string("Vulkan: ") + call + " failed (VkResult " + std::to_string(result) + ")");
}

// Strict decimal integer in [lo, hi]: digits only, the whole text, no overflow.
bool parse_int(const std::string& text, int lo, int hi, int& out) {
    if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) return false;
    int value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc() || end != text.data() + text.size() || value < lo || value > hi) return false;
    out = value;
    return true;
}

struct Options {
    int frames = 2;  // per camera position
    int width = 320, height = 240;
    bool validation = true;
    bool aggressive = false;
    bool backpatch_open = false;
};

Options parse_options(int argc, char** argv) {
    const std::string usage = "(usage: [--frames N] [--size WxH] [--no-validation] [--aggressive] [--backpatch-open])";
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "--no-validation") {
            o.validation = false;
        } else if (flag == "--aggressive") {
            o.aggressive = true;
        } else if (flag == "--backpatch-open") {
            o.backpatch_open = true;
        } else if (flag == "--frames" || flag == "--size") {
            if (i + 1 >= argc) setup_error(flag + ": missing value");
            const std::string value = argv[++i];
            if (flag == "--frames") {
                if (!parse_int(value, 1, 1000, o.frames))
                    setup_error("--frames: expected an integer in 1..1000, got " + pc::quote_input(value));
            } else {
                const std::size_t x = value.find('x');
                if (x == std::string::npos || !parse_int(value.substr(0, x), 1, 4096, o.width) ||
                    !parse_int(value.substr(x + 1), 1, 4096, o.height))
                    setup_error("--size: expected WIDTHxHEIGHT, each in 1..4096, got " + pc::quote_input(value));
            }
        } else {
            setup_error("unknown option " + pc::quote_input(flag) + " " + usage);
        }
    }
    return o;
}

// ---- the engine's scene ------------------------------------------------------------------------

struct Object {
    std::size_t first = 0, count = 0;
};

// The scene in world space (z up), patches in patch.h's layout (the passes' 256 bytes per patch).
struct Scene {
    std::vector<pc::BezierPatch> patches;
    Object teapot, bigguy;
};

// Appends patches moved by p -> scale * R (p - base) + position, R a PROPER rotation (y up -> z
// up, then a turn of yaw degrees about z): a reflection would turn the closed surface inside out,
// and its back-patch test and one-sided drawing with it. Homogeneous points (w x, w y, w z, w)
// move as w (scale * R (x - base) + position).
void add_patches(Scene& s, const std::vector<pc::BezierPatch>& patches, bool y_up, pc::Vec3 base, float scale,
                 float yaw_degrees, pc::Vec3 position) {
    const float a = yaw_degrees * 3.14159265f / 180, c = std::cos(a), sn = std::sin(a);
    for (pc::BezierPatch patch : patches) {
        for (pc::Vec4& q : patch.cp) {
            const pc::Vec3 p = (pc::Vec3{q.x, q.y, q.z} * (1 / q.w) - base) * scale;
            const pc::Vec3 up = y_up ? pc::Vec3{p.x, -p.z, p.y} : p;
            const pc::Vec3 w = pc::Vec3{c * up.x - sn * up.y, sn * up.x + c * up.y, up.z} + position;
            q = {w.x * q.w, w.y * q.w, w.z * q.w, q.w};
        }
        s.patches.push_back(patch);
    }
}

Scene make_scene() {
    Scene s;
    // The teapot's 32 patches, each split twice (4^2 children), in its own z-up frame.
    std::vector<pc::BezierPatch> teapot = pc::teapot_patches();
    for (int level = 0; level < 2; ++level) {
        std::vector<pc::BezierPatch> children(teapot.size() * 4);
        for (std::size_t i = 0; i < teapot.size(); ++i) pc::split_patch(teapot[i], &children[4 * i]);
        teapot.swap(children);
    }
    s.teapot.count = teapot.size();
    add_patches(s, teapot, false, {0, 0, 0}, 1, 0, {0, 0, 0});
    // BigGuy beside the teapot, 4 units tall, standing on z = 0. Back-patch culling needs a closed,
    // outward-oriented surface: load_model reports it (LoadedModel::closed) after orienting it.
    const pc::LoadedModel bigguy = pc::load_model(pc::shipped_model_path("bigguy.obj"), pc::Scheme::acc, 0);
    if (!bigguy.closed) setup_error("bigguy.obj: not a closed surface (the back-patch tests need one)");
    const pc::Bounds b = pc::patch_bounds(bigguy.rest);  // y up
    const pc::Vec3 base{0.5f * (b.min.x + b.max.x), b.min.y, 0.5f * (b.min.z + b.max.z)};
    s.bigguy.first = s.patches.size();
    s.bigguy.count = bigguy.rest.patches.size();
    add_patches(s, bigguy.rest.patches, true, base, 4.0f / (b.max.y - b.min.y), 200, {0.5f, -5.0f, 0});
    return s;
}

struct View {
    pc::Mat4 view, projection;  // projection: y-down, zero-to-one depth
    pc::Vec3 eye;
};

// Three camera positions, each orbiting 4 degrees per frame: the whole scene from the side (each
// object hides its own far half); close to the teapot's spout (most of the scene leaves the
// frustum); steep from above, behind BigGuy (the teapot's inside shows through the lid gap).
View camera(int frame, int frames_per_position, float aspect) {
    struct Position {
        float azimuth, elevation, distance;
        pc::Vec3 target;
    };
    const Position positions[] = {
        {15, 12, 13, {-1.5f, -1.2f, 1.3f}}, {-10, 10, 3.5f, {0.2f, 0, 1.5f}}, {-120, 55, 12, {-1.5f, -2.0f, 1.0f}}};
    const Position& p = positions[frame / frames_per_position];
    const float deg = 3.14159265f / 180;
    const float azimuth = (p.azimuth + 4.0f * static_cast<float>(frame % frames_per_position)) * deg;
    const float elevation = p.elevation * deg;
    const pc::Vec3 eye = p.target + pc::Vec3{std::cos(elevation) * std::cos(azimuth),
                                             std::cos(elevation) * std::sin(azimuth), std::sin(elevation)} *
                                        p.distance;
    // patchcull's perspective() is y-up with zero-to-one depth (clip_space.h). Vulkan's framebuffer
    // y points down: negate the y row (clip y' = -y), the usual Vulkan projection.
    pc::Mat4 projection = pc::perspective(0.9f, aspect, 0.1f, 60.0f);
    for (int c = 0; c < 4; ++c) projection.at(1, c) = -projection.at(1, c);
    return {pc::look_at(eye, p.target, {0, 0, 1}), projection, eye};
}

// ---- the engine's Vulkan device ------------------------------------------------------------------

int g_validation_messages = 0;

// Every warning or error the layers or the loader report is printed and counted (exit status 1).
VKAPI_ATTR VkBool32 VKAPI_CALL on_vulkan_message(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                                 VkDebugUtilsMessageTypeFlagsEXT,
                                                 const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
    ++g_validation_messages;
    std::printf("VALIDATION: %s\n", pc::printable_line(data->pMessage ? data->pMessage : "(no text)").c_str());
    std::fflush(stdout);
    return VK_FALSE;
}

bool has_instance_layer(const char* name) {
    std::uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> layers(count);
    vkEnumerateInstanceLayerProperties(&count, layers.data());
    for (const VkLayerProperties& l : layers)
        if (std::strcmp(l.layerName, name) == 0) return true;
    return false;
}

bool has_device_extension(VkPhysicalDevice device, const char* name) {
    std::uint32_t count = 0;
    vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> extensions(count);
    vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data());
    for (const VkExtensionProperties& e : extensions)
        if (std::strcmp(e.extensionName, name) == 0) return true;
    return false;
}

// The engine's instance, device, queue and command pool, and the objects made on them (destroyed in
// reverse order by the destructor, after the device is idle). The PassContext is made by run() on
// this device and destroyed before it.
struct Gpu {
    VkInstance instance = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    std::uint32_t family = 0;
    VkCommandPool pool = VK_NULL_HANDLE;
    VkPhysicalDeviceMemoryProperties memory{};
    PFN_vkCmdPushDescriptorSetKHR push_descriptor_set = nullptr;
    std::vector<std::function<void()>> destroy;  // in reverse order
    std::string name;

    explicit Gpu(bool want_validation);
    ~Gpu();
    Gpu(const Gpu&) = delete;
    Gpu& operator=(const Gpu&) = delete;

    std::uint32_t memory_type(std::uint32_t bits, VkMemoryPropertyFlags wanted) const {
        for (std::uint32_t i = 0; i < memory.memoryTypeCount; ++i)
            if ((bits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
        setup_error("Vulkan: no memory type with the properties needed");
    }
    // Records record(cmd) into a fresh command buffer, then a barrier to host reads; submits it
    // and waits for it (the frames here are checked one by one).
    void submit(const std::function<void(VkCommandBuffer)>& record);
};

Gpu::Gpu(bool want_validation) {
    const char* layer = "VK_LAYER_KHRONOS_validation";
    const bool validation = want_validation && has_instance_layer(layer);
    if (want_validation && !validation)
        std::printf("note: VK_LAYER_KHRONOS_validation is not installed, running without validation\n");
    VkApplicationInfo app{};
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "06_vulkan_passes_in_your_engine";
    app.apiVersion = VK_API_VERSION_1_3;
    VkDebugUtilsMessengerCreateInfoEXT messenger_info{};
    messenger_info.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    messenger_info.messageSeverity =
        VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    messenger_info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                                 VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                                 VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    messenger_info.pfnUserCallback = on_vulkan_message;
    // Synchronization validation too: a barrier missing between our draws, the passes and our
    // copies is reported like any other error.
    const VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
    VkValidationFeaturesEXT features{};
    features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
    features.pNext = &messenger_info;  // messages of vkCreateInstance itself too
    features.enabledValidationFeatureCount = 1;
    features.pEnabledValidationFeatures = enables;
    const char* debug_utils = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    VkInstanceCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    info.pApplicationInfo = &app;
    if (validation) {
        info.pNext = &features;
        info.enabledLayerCount = 1;
        info.ppEnabledLayerNames = &layer;
        info.enabledExtensionCount = 1;
        info.ppEnabledExtensionNames = &debug_utils;
    }
    const VkResult created = vkCreateInstance(&info, nullptr, &instance);
    if (created != VK_SUCCESS)
        setup_error("Vulkan: vkCreateInstance failed (VkResult " + std::to_string(created) +
                    "): no Vulkan driver? (install mesa-vulkan-drivers for lavapipe)");
    if (validation) {
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
        check(create(instance, &messenger_info, nullptr, &messenger), "vkCreateDebugUtilsMessengerEXT");
    }

    // The first physical device with everything the passes and our draw need.
    std::uint32_t count = 0;
    vkEnumeratePhysicalDevices(instance, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    vkEnumeratePhysicalDevices(instance, &count, devices.data());
    for (VkPhysicalDevice d : devices) {
        VkPhysicalDeviceProperties p{};
        vkGetPhysicalDeviceProperties(d, &p);
        VkPhysicalDeviceVulkan13Features f13{};
        f13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
        VkPhysicalDeviceVulkan12Features f12{};
        f12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
        f12.pNext = &f13;
        VkPhysicalDeviceFeatures2 f{};
        f.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
        f.pNext = &f12;
        if (p.apiVersion < VK_API_VERSION_1_3) continue;
        vkGetPhysicalDeviceFeatures2(d, &f);
        if (!f.features.shaderFloat64 || !f.features.tessellationShader || !f.features.multiDrawIndirect ||
            !f12.drawIndirectCount || !f13.dynamicRendering ||
            !has_device_extension(d, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME))
            continue;
        std::uint32_t families = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(d, &families, nullptr);
        std::vector<VkQueueFamilyProperties> family_properties(families);
        vkGetPhysicalDeviceQueueFamilyProperties(d, &families, family_properties.data());
        for (std::uint32_t i = 0; i < families && !physical; ++i)
            if ((family_properties[i].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) ==
                (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) {
                physical = d;
                family = i;
                name = p.deviceName;
            }
        if (physical) break;
    }
    if (!physical)
        setup_error(
            "Vulkan: no device with Vulkan 1.3, VK_KHR_push_descriptor, shaderFloat64, tessellationShader, "
            "multiDrawIndirect and drawIndirectCount (install mesa-vulkan-drivers for lavapipe)");
    vkGetPhysicalDeviceMemoryProperties(physical, &memory);

    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info{};
    queue_info.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    queue_info.queueFamilyIndex = family;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    VkPhysicalDeviceVulkan13Features enable13{};
    enable13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
    enable13.dynamicRendering = VK_TRUE;
    VkPhysicalDeviceVulkan12Features enable12{};
    enable12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
    enable12.pNext = &enable13;
    enable12.drawIndirectCount = VK_TRUE;
    VkPhysicalDeviceFeatures2 enable{};
    enable.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    enable.pNext = &enable12;
    enable.features.shaderFloat64 = VK_TRUE;  // the passes' exact fma (PassContextOptions::Fma)
    enable.features.tessellationShader = VK_TRUE;
    enable.features.multiDrawIndirect = VK_TRUE;
    const char* extension = VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME;  // the passes' descriptors (ours too)
    VkDeviceCreateInfo device_info{};
    device_info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    device_info.pNext = &enable;
    device_info.queueCreateInfoCount = 1;
    device_info.pQueueCreateInfos = &queue_info;
    device_info.enabledExtensionCount = 1;
    device_info.ppEnabledExtensionNames = &extension;
    check(vkCreateDevice(physical, &device_info, nullptr, &device), "vkCreateDevice");
    vkGetDeviceQueue(device, family, 0, &queue);
    push_descriptor_set =
        reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(vkGetDeviceProcAddr(device, "vkCmdPushDescriptorSetKHR"));
    VkCommandPoolCreateInfo pool_info{};
    pool_info.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pool_info.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
    pool_info.queueFamilyIndex = family;
    check(vkCreateCommandPool(device, &pool_info, nullptr, &pool), "vkCreateCommandPool");
}

Gpu::~Gpu() {
    if (device) vkDeviceWaitIdle(device);
    for (auto it = destroy.rbegin(); it != destroy.rend(); ++it) (*it)();
    if (pool) vkDestroyCommandPool(device, pool, nullptr);
    if (device) vkDestroyDevice(device, nullptr);
    if (messenger) {
        auto destroy_messenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
        destroy_messenger(instance, messenger, nullptr);
    }
    if (instance) vkDestroyInstance(instance, nullptr);
}

void Gpu::submit(const std::function<void(VkCommandBuffer)>& record) {
    VkCommandBufferAllocateInfo allocate{};
    allocate.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    allocate.commandPool = pool;
    allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    allocate.commandBufferCount = 1;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    check(vkAllocateCommandBuffers(device, &allocate, &cmd), "vkAllocateCommandBuffers");
    VkCommandBufferBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
    try {
        record(cmd);
    } catch (...) {
        vkEndCommandBuffer(cmd);
        vkFreeCommandBuffers(device, pool, 1, &cmd);
        throw;
    }
    VkMemoryBarrier to_host{};
    to_host.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    to_host.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
    to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0,
                         nullptr, 0, nullptr);
    check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
    VkFenceCreateInfo fence_info{};
    fence_info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    VkFence fence = VK_NULL_HANDLE;
    check(vkCreateFence(device, &fence_info, nullptr, &fence), "vkCreateFence");
    VkSubmitInfo submit_info{};
    submit_info.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    submit_info.commandBufferCount = 1;
    submit_info.pCommandBuffers = &cmd;
    VkResult result = vkQueueSubmit(queue, 1, &submit_info, fence);
    if (result == VK_SUCCESS) result = vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX);
    vkDestroyFence(device, fence, nullptr);
    vkFreeCommandBuffers(device, pool, 1, &cmd);
    check(result, "vkQueueSubmit");
}

// A buffer in host-visible, coherent memory, mapped for its life: the uploads are memcpy and the
// read-backs are reads. (On a discrete GPU an engine keeps these device-local and uploads through
// a staging buffer; the passes take any VkBuffer made with VK_BUFFER_USAGE_STORAGE_BUFFER_BIT.)
struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceSize size = 0;
    void* mapped = nullptr;
    pc::vk::BufferRange range() const { return {buffer, 0, size}; }
    template <class T>
    T* data() const {
        return static_cast<T*>(mapped);
    }
};

Buffer make_buffer(Gpu& gpu, VkDeviceSize size, VkBufferUsageFlags usage) {
    Buffer b;
    b.size = size;
    VkBufferCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    info.size = size;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    check(vkCreateBuffer(gpu.device, &info, nullptr, &b.buffer), "vkCreateBuffer");
    const VkDevice device = gpu.device;
    const VkBuffer buffer = b.buffer;
    gpu.destroy.push_back([device, buffer] { vkDestroyBuffer(device, buffer, nullptr); });
    VkMemoryRequirements requirements{};
    vkGetBufferMemoryRequirements(gpu.device, b.buffer, &requirements);
    VkMemoryAllocateInfo allocate{};
    allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    allocate.allocationSize = requirements.size;
    allocate.memoryTypeIndex = gpu.memory_type(
        requirements.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    VkDeviceMemory memory = VK_NULL_HANDLE;
    check(vkAllocateMemory(gpu.device, &allocate, nullptr, &memory), "vkAllocateMemory");
    gpu.destroy.push_back([device, memory] { vkFreeMemory(device, memory, nullptr); });
    check(vkBindBufferMemory(gpu.device, b.buffer, memory, 0), "vkBindBufferMemory");
    check(vkMapMemory(gpu.device, memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
    std::memset(b.mapped, 0, size);
    return b;
}

VkImage make_image(Gpu& gpu, const VkImageCreateInfo& info) {
    VkImage image = VK_NULL_HANDLE;
    check(vkCreateImage(gpu.device, &info, nullptr, &image), "vkCreateImage");
    const VkDevice device = gpu.device;
    gpu.destroy.push_back([device, image] { vkDestroyImage(device, image, nullptr); });
    VkMemoryRequirements requirements{};
    vkGetImageMemoryRequirements(gpu.device, image, &requirements);
    VkMemoryAllocateInfo allocate{};
    allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    allocate.allocationSize = requirements.size;
    allocate.memoryTypeIndex = gpu.memory_type(requirements.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VkDeviceMemory memory = VK_NULL_HANDLE;
    check(vkAllocateMemory(gpu.device, &allocate, nullptr, &memory), "vkAllocateMemory");
    gpu.destroy.push_back([device, memory] { vkFreeMemory(device, memory, nullptr); });
    check(vkBindImageMemory(gpu.device, image, memory, 0), "vkBindImageMemory");
    return image;
}

VkImageView make_view(Gpu& gpu, VkImage image, VkFormat format, VkImageAspectFlags aspect, std::uint32_t level,
                      std::uint32_t levels) {
    VkImageViewCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    info.image = image;
    info.viewType = VK_IMAGE_VIEW_TYPE_2D;
    info.format = format;
    info.subresourceRange = {aspect, level, levels, 0, 1};
    VkImageView view = VK_NULL_HANDLE;
    check(vkCreateImageView(gpu.device, &info, nullptr, &view), "vkCreateImageView");
    const VkDevice device = gpu.device;
    gpu.destroy.push_back([device, view] { vkDestroyImageView(device, view, nullptr); });
    return view;
}

VkImageCreateInfo image_2d(VkFormat format, int width, int height, VkImageUsageFlags usage) {
    VkImageCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height), 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    return info;
}

void image_barrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, std::uint32_t levels,
                   VkImageLayout from, VkImageLayout to, VkPipelineStageFlags src_stages, VkAccessFlags src_access,
                   VkPipelineStageFlags dst_stages, VkAccessFlags dst_access) {
    VkImageMemoryBarrier b{};
    b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    b.srcAccessMask = src_access;
    b.dstAccessMask = dst_access;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {aspect, 0, levels, 0, 1};
    vkCmdPipelineBarrier(cmd, src_stages, dst_stages, 0, 0, nullptr, 0, nullptr, 1, &b);
}

// ---- the engine's renderer ---------------------------------------------------------------------

// The push constants of common.glsl's DrawParams (std430 layout of a push-constant block).
struct DrawParams {
    float object_to_clip[16];
    float eye_level[4];
    std::uint32_t one_sided[2];
};

constexpr VkPipelineStageFlags kDrawStages = VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_VERTEX_SHADER_BIT |
                                             VK_PIPELINE_STAGE_TESSELLATION_CONTROL_SHADER_BIT |
                                             VK_PIPELINE_STAGE_TESSELLATION_EVALUATION_SHADER_BIT |
                                             VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT;
constexpr VkPipelineStageFlags kDepthStages =
    VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;

struct Renderer {
    Gpu* gpu = nullptr;
    int width = 0, height = 0;
    float level = 6;
    VkImage ids = VK_NULL_HANDLE, depth = VK_NULL_HANDLE;
    VkImageView ids_view = VK_NULL_HANDLE, depth_view = VK_NULL_HANDLE;
    VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
    Buffer patches;  // 16 vec4 per patch: our draw reads it, the passes too

    // Patches per draw command. llvmpipe emits garbage when one 4096-vertex chunk yields more
    // than 65536 tessellated vertices (patchcull/gl/gl_renderer.h), and lavapipe draws with the
    // same gallium module: here one unsplit draw of all 1962 patches at level 16 changed thousands
    // of id pixels. Commands of at most 65536 / (level + 1)^2 patches (CompactPass's
    // patches_per_command; the reference draw likewise) avoid it.
    std::size_t per_command() const {
        return std::max<std::size_t>(1, 65536 / static_cast<std::size_t>((level + 1) * (level + 1)));
    }

    void create_pipeline() {
        VkDescriptorSetLayoutBinding bindings[2] = {};
        for (std::uint32_t b = 0; b < 2; ++b) {
            bindings[b].binding = b;
            bindings[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            bindings[b].descriptorCount = 1;
            bindings[b].stageFlags = VK_SHADER_STAGE_ALL_GRAPHICS;
        }
        VkDescriptorSetLayoutCreateInfo set_info{};
        set_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
        set_info.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
        set_info.bindingCount = 2;
        set_info.pBindings = bindings;
        const VkDevice device = gpu->device;
        check(vkCreateDescriptorSetLayout(device, &set_info, nullptr, &set_layout), "vkCreateDescriptorSetLayout");
        gpu->destroy.push_back([device, l = set_layout] { vkDestroyDescriptorSetLayout(device, l, nullptr); });
        const VkPushConstantRange push{VK_SHADER_STAGE_ALL_GRAPHICS, 0, sizeof(DrawParams)};
        VkPipelineLayoutCreateInfo layout_info{};
        layout_info.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
        layout_info.setLayoutCount = 1;
        layout_info.pSetLayouts = &set_layout;
        layout_info.pushConstantRangeCount = 1;
        layout_info.pPushConstantRanges = &push;
        check(vkCreatePipelineLayout(device, &layout_info, nullptr, &layout), "vkCreatePipelineLayout");
        gpu->destroy.push_back([device, l = layout] { vkDestroyPipelineLayout(device, l, nullptr); });

        const VkShaderStageFlagBits stages[4] = {VK_SHADER_STAGE_VERTEX_BIT, VK_SHADER_STAGE_TESSELLATION_CONTROL_BIT,
                                                 VK_SHADER_STAGE_TESSELLATION_EVALUATION_BIT,
                                                 VK_SHADER_STAGE_FRAGMENT_BIT};
        VkPipelineShaderStageCreateInfo stage_info[4] = {};
        VkShaderModule modules[4] = {};
        for (int s = 0; s < 4; ++s) {
            VkShaderModuleCreateInfo module_info{};
            module_info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
            module_info.codeSize = example06::kSpirvBytes[s];
            module_info.pCode = example06::kSpirvWords[s];
            check(vkCreateShaderModule(device, &module_info, nullptr, &modules[s]), "vkCreateShaderModule");
            stage_info[s].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
            stage_info[s].stage = stages[s];
            stage_info[s].module = modules[s];
            stage_info[s].pName = "main";
        }
        VkPipelineVertexInputStateCreateInfo vertex_input{};  // none: the vertex shader pulls the points
        vertex_input.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
        VkPipelineInputAssemblyStateCreateInfo assembly{};
        assembly.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
        assembly.topology = VK_PRIMITIVE_TOPOLOGY_PATCH_LIST;
        VkPipelineTessellationStateCreateInfo tessellation{};
        tessellation.sType = VK_STRUCTURE_TYPE_PIPELINE_TESSELLATION_STATE_CREATE_INFO;
        tessellation.patchControlPoints = 16;
        VkPipelineViewportStateCreateInfo viewport{};
        viewport.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
        viewport.viewportCount = 1;
        viewport.scissorCount = 1;
        VkPipelineRasterizationStateCreateInfo raster{};
        raster.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
        raster.polygonMode = VK_POLYGON_MODE_FILL;
        // No face culling: the teapot is two-sided, and BigGuy is made one-sided by its EXACT
        // surface in the fragment shader, not by the orientation of its secant triangles.
        raster.cullMode = VK_CULL_MODE_NONE;
        raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
        raster.lineWidth = 1.0f;
        VkPipelineMultisampleStateCreateInfo multisample{};
        multisample.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
        multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
        VkPipelineDepthStencilStateCreateInfo depth_state{};
        depth_state.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
        depth_state.depthTestEnable = VK_TRUE;
        depth_state.depthWriteEnable = VK_TRUE;
        depth_state.depthCompareOp = VK_COMPARE_OP_LESS;  // zero-to-one depth, cleared to 1
        VkPipelineColorBlendAttachmentState blend_attachment{};
        blend_attachment.colorWriteMask = VK_COLOR_COMPONENT_R_BIT;
        VkPipelineColorBlendStateCreateInfo blend{};
        blend.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
        blend.attachmentCount = 1;
        blend.pAttachments = &blend_attachment;
        const VkDynamicState dynamic_states[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
        VkPipelineDynamicStateCreateInfo dynamic{};
        dynamic.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO;
        dynamic.dynamicStateCount = 2;
        dynamic.pDynamicStates = dynamic_states;
        const VkFormat id_format = VK_FORMAT_R32_UINT;
        VkPipelineRenderingCreateInfo rendering{};  // dynamic rendering: no render pass object
        rendering.sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO;
        rendering.colorAttachmentCount = 1;
        rendering.pColorAttachmentFormats = &id_format;
        rendering.depthAttachmentFormat = VK_FORMAT_D32_SFLOAT;
        VkGraphicsPipelineCreateInfo info{};
        info.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
        info.pNext = &rendering;
        info.stageCount = 4;
        info.pStages = stage_info;
        info.pVertexInputState = &vertex_input;
        info.pInputAssemblyState = &assembly;
        info.pTessellationState = &tessellation;
        info.pViewportState = &viewport;
        info.pRasterizationState = &raster;
        info.pMultisampleState = &multisample;
        info.pDepthStencilState = &depth_state;
        info.pColorBlendState = &blend;
        info.pDynamicState = &dynamic;
        info.layout = layout;
        const VkResult result = vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline);
        for (VkShaderModule m : modules) vkDestroyShaderModule(device, m, nullptr);
        check(result, "vkCreateGraphicsPipelines");
        gpu->destroy.push_back([device, p = pipeline] { vkDestroyPipeline(device, p, nullptr); });
    }

    // Begins rendering into the id and depth images (both in attachment layouts), clearing them
    // (id 0, depth 1) or keeping them, and sets the whole pipeline state: the passes leave their
    // compute state bound, never the graphics state, but a draw sets everything it needs itself.
    void begin(VkCommandBuffer cmd, bool clear, const View& v, const Object& one_sided,
               const pc::vk::BufferRange& list) const {
        VkRenderingAttachmentInfo color{};
        color.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
        color.imageView = ids_view;
        color.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        color.loadOp = clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
        color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        color.clearValue.color.uint32[0] = 0;  // the background id
        VkRenderingAttachmentInfo depth_attachment{};
        depth_attachment.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
        depth_attachment.imageView = depth_view;
        depth_attachment.imageLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
        depth_attachment.loadOp = color.loadOp;
        depth_attachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        depth_attachment.clearValue.depthStencil = {1.0f, 0};  // the far plane of zero-to-one depth
        VkRenderingInfo info{};
        info.sType = VK_STRUCTURE_TYPE_RENDERING_INFO;
        info.renderArea = {{0, 0}, {static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height)}};
        info.layerCount = 1;
        info.colorAttachmentCount = 1;
        info.pColorAttachments = &color;
        info.pDepthAttachment = &depth_attachment;
        vkCmdBeginRendering(cmd, &info);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
        const VkViewport viewport{0, 0, static_cast<float>(width), static_cast<float>(height), 0, 1};
        vkCmdSetViewport(cmd, 0, 1, &viewport);
        vkCmdSetScissor(cmd, 0, 1, &info.renderArea);
        const VkDescriptorBufferInfo buffers[2] = {{patches.buffer, 0, patches.size}, {list.buffer, 0, list.size}};
        VkWriteDescriptorSet writes[2] = {};
        for (std::uint32_t b = 0; b < 2; ++b) {
            writes[b].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
            writes[b].dstBinding = b;
            writes[b].descriptorCount = 1;
            writes[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            writes[b].pBufferInfo = &buffers[b];
        }
        gpu->push_descriptor_set(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout, 0, 2, writes);
        DrawParams params{};
        const pc::Mat4 object_to_clip = v.projection * v.view;  // the scene is in world space: model = I
        std::memcpy(params.object_to_clip, object_to_clip.m, sizeof params.object_to_clip);
        params.eye_level[0] = v.eye.x;
        params.eye_level[1] = v.eye.y;
        params.eye_level[2] = v.eye.z;
        params.eye_level[3] = level;
        params.one_sided[0] = static_cast<std::uint32_t>(one_sided.first);
        params.one_sided[1] = static_cast<std::uint32_t>(one_sided.first + one_sided.count);
        vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_ALL_GRAPHICS, 0, sizeof params, &params);
    }
};

// ---- the check ---------------------------------------------------------------------------------

struct Comparison {
    std::size_t differing = 0;    // pixels whose id or depth differs and that are no verified tie
    std::size_t ties = 0;         // exact depth ties between two drawn patches
    std::size_t false_culls = 0;  // patches visible in the unculled image but drawn in neither pass
};

// The culled frame against the unculled draw. Where the ids agree the depths must too. Where they
// differ, the only legitimate cause is an exact depth tie (two patches with fragments at exactly
// the same depth, e.g. where the spout enters the body; VK_COMPARE_OP_LESS keeps whichever was
// drawn first, and the two frames draw in different orders): the depths are then bit-identical
// AND the unculled winner was drawn in the culled frame too. A visible patch that was not drawn is
// a false cull.
Comparison compare(const std::uint32_t* ids, const float* depth, const std::uint32_t* ref_ids, const float* ref_depth,
                   std::size_t pixels, const std::vector<bool>& drawn) {
    Comparison c;
    std::vector<bool> counted(drawn.size(), false);
    for (std::size_t i = 0; i < pixels; ++i) {
        const std::uint32_t winner = ref_ids[i];
        if (winner != 0 && !drawn[winner - 1] && !counted[winner - 1]) {
            counted[winner - 1] = true;
            ++c.false_culls;
        }
        if (ids[i] == winner && depth[i] == ref_depth[i]) continue;
        if (ids[i] != 0 && winner != 0 && depth[i] == ref_depth[i] && drawn[winner - 1])
            ++c.ties;
        else
            ++c.differing;
    }
    return c;
}

int run(const Options& options) {
    // 0. The engine's scene (a model file missing is a setup error before any Vulkan object).
    const Scene scene = make_scene();
    const std::size_t n = scene.patches.size();

    // 1. The engine's instance and device (headless).
    Gpu gpu(options.validation);
    for (VkFormat format : {VK_FORMAT_R32_UINT, VK_FORMAT_D32_SFLOAT}) {
        VkFormatProperties properties{};
        vkGetPhysicalDeviceFormatProperties(gpu.physical, format, &properties);
        const VkFormatFeatureFlags needed =
            format == VK_FORMAT_R32_UINT ? VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT
                                         : VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT |
                                               VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT;
        if ((properties.optimalTilingFeatures & needed) != needed)
            setup_error("Vulkan: the device cannot render and read back R32_UINT ids and D32_SFLOAT depth");
    }

    // 2. The engine's buffers. Patch buffer: 16 vec4 per patch, patch p's point k at 16 p + k
    //    (BezierPatch's memory layout). Flag buffer: one uint per patch. CompactPass's outputs:
    //    a list entry per patch, the VkDrawIndirectCommands of the whole range, one draw count,
    //    and its scratch. A list 0..n-1 for the unculled reference draw. One read-back buffer for
    //    the id and depth images of the culled and the unculled frame.
    Renderer r;
    r.gpu = &gpu;
    r.width = options.width;
    r.height = options.height;
    const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    r.patches = make_buffer(gpu, n * sizeof(pc::BezierPatch), storage);
    std::memcpy(r.patches.mapped, scene.patches.data(), n * sizeof(pc::BezierPatch));
    const Buffer flags = make_buffer(gpu, n * 4, storage);
    // First frame: no previous frame tagged anything, so tag the even-indexed patches visible
    // (Niessner & Loop §3, as patchcull's own pipeline does): pass 1 draws half, pass 2 the rest.
    for (std::size_t p = 0; p < n; p += 2) flags.data<std::uint32_t>()[p] = pc::kStatusVisible;
    const std::size_t per_command = r.per_command();
    const std::size_t commands = pc::vk::compact_command_count(n, per_command);
    const Buffer list = make_buffer(gpu, n * 4, storage);
    const Buffer command_buffer =
        make_buffer(gpu, commands * sizeof(VkDrawIndirectCommand), storage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
    const Buffer draw_count = make_buffer(gpu, 4, storage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
    const Buffer scratch =
        make_buffer(gpu, pc::vk::compact_scratch_bytes(n, pc::vk::CompactMethod::prefix_scan), storage);
    const Buffer all_list = make_buffer(gpu, n * 4, storage);
    for (std::size_t p = 0; p < n; ++p) all_list.data<std::uint32_t>()[p] = static_cast<std::uint32_t>(p);
    const std::size_t pixels = static_cast<std::size_t>(r.width) * static_cast<std::size_t>(r.height);
    const Buffer readback = make_buffer(gpu, 4 * pixels * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);

    // 3. The engine's images: R32_UINT ids and D32_SFLOAT depth (an attachment the Hi-Z build
    //    samples), and the Hi-Z pyramid, made from hiz_image_create_info with a view of all its
    //    levels (sampled) and one per level (storage), as HiZImage asks.
    r.ids = make_image(gpu, image_2d(VK_FORMAT_R32_UINT, r.width, r.height,
                                     VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT));
    r.depth = make_image(gpu, image_2d(VK_FORMAT_D32_SFLOAT, r.width, r.height,
                                       VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                                           VK_IMAGE_USAGE_TRANSFER_SRC_BIT));
    r.ids_view = make_view(gpu, r.ids, VK_FORMAT_R32_UINT, VK_IMAGE_ASPECT_COLOR_BIT, 0, 1);
    r.depth_view = make_view(gpu, r.depth, VK_FORMAT_D32_SFLOAT, VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1);
    const VkImageCreateInfo hiz_info = pc::vk::hiz_image_create_info(r.width, r.height);
    pc::vk::HiZImage hiz;
    hiz.image = make_image(gpu, hiz_info);
    hiz.all_levels = make_view(gpu, hiz.image, VK_FORMAT_R32_SFLOAT, VK_IMAGE_ASPECT_COLOR_BIT, 0, hiz_info.mipLevels);
    for (std::uint32_t l = 0; l < hiz_info.mipLevels; ++l)
        hiz.level_views[l] = make_view(gpu, hiz.image, VK_FORMAT_R32_SFLOAT, VK_IMAGE_ASPECT_COLOR_BIT, l, 1);
    hiz.width = r.width;
    hiz.height = r.height;
    // The depth image as HiZBuildPass reads it: the layout we put it in for the build.
    const pc::vk::DepthImage depth_image{r.depth_view, VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL,
                                         VK_FORMAT_D32_SFLOAT};
    gpu.submit([&](VkCommandBuffer cmd) {  // the pyramid stays in GENERAL while the passes use it
        image_barrier(cmd, hiz.image, VK_IMAGE_ASPECT_COLOR_BIT, hiz_info.mipLevels, VK_IMAGE_LAYOUT_UNDEFINED,
                      VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, 0,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    });

    // 4. The engine's patch pipeline (our four shaders, dynamic rendering).
    r.create_pipeline();

    // 5. The passes, on our device: one PassContext per VkDevice (the exact fma: shaderFloat64 is
    //    enabled). Their pipelines are made on first use; they record into our command buffers.
    pc::vk::PassContextOptions pass_options;
    pass_options.fma = pc::vk::PassContextOptions::Fma::exact_double;
    pc::vk::PassContext passes(gpu.physical, gpu.device, pass_options);
    pc::vk::CullStatusPass status(passes);
    pc::vk::FrustumPass frustum(passes);
    pc::vk::BackpatchConePass cones(passes);
    pc::vk::HiZBuildPass hiz_build(passes);
    pc::vk::OcclusionPass occlusion(passes);
    pc::vk::CompactPass compact(passes);
    // All patches; each object is a range of these buffers. No margins: nothing is displaced.
    const pc::vk::PatchBuffers all{r.patches.range(), flags.range(), {}, 0, n};
    auto range_of = [&all](const Object& o) {
        pc::vk::PatchBuffers range = all;
        range.first = o.first;
        range.count = o.count;
        return range;
    };
    const pc::vk::DrawListRanges outputs{list.range(),    0,          command_buffer.range(), draw_count.range(),
                                         scratch.range(), per_command};

    std::printf(
        "%s, %zu patches (teapot %zu two-sided, bigguy %zu one-sided), %dx%d, tessellation level %g, "
        "back-patch tcone%s, %d frames at 3 camera positions, validation %s\n",
        gpu.name.c_str(), n, scene.teapot.count, scene.bigguy.count, r.width, r.height, static_cast<double>(r.level),
        options.backpatch_open ? " (bigguy AND the open teapot: --backpatch-open)" : " (bigguy)", 3 * options.frames,
        gpu.messenger ? "on" : "off");
    std::fflush(stdout);
    const float aspect = static_cast<float>(r.width) / static_cast<float>(r.height);
    const std::uint32_t* const words = flags.data<std::uint32_t>();
    int mismatched = 0;
    std::size_t total_frustum = 0, total_backpatch = 0, total_occlusion = 0;
    const int frames = 3 * options.frames;
    for (int f = 0; f < frames; ++f) {
        const View v = camera(f, options.frames, aspect);
        // Everything a cull test needs from this view: the planes of the y-down projection in
        // zero-to-one depth, the eye (the tests' object space is our world space).
        const pc::CullView view = pc::make_cull_view(v.view, v.projection, pc::ClipDepth::zero_to_one, v.eye);
        // For the check only: which patches pass 1 draws (the statuses the previous frame left).
        const std::vector<std::uint32_t> words_before(words, words + n);

        gpu.submit([&](VkCommandBuffer cmd) {
            // Our earlier work (the previous frame, the uploads) before anything of this frame:
            // the passes ask the caller to order it (vk_passes.h).
            VkMemoryBarrier before{};
            before.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
            before.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
            before.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
            vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1,
                                 &before, 0, nullptr, 0, nullptr);
            image_barrier(cmd, r.ids, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
                          VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                          VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
            image_barrier(cmd, r.depth, VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
                          VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                          kDepthStages,
                          VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);

            // ---- the culled frame: Niessner & Loop §3's two passes ----
            // Pass 1: the patches the previous frame tagged visible, listed by CompactPass into
            // our buffers, drawn by our pipeline. Each pass records its dispatches and a barrier
            // to every later stage (PassContextOptions::after_stages), so the indirect draw sees
            // the commands: no barrier of ours between a pass and our draw.
            compact.run(cmd, all, pc::kStatusVisible, pc::kStatusVisible, outputs);
            r.begin(cmd, true, v, scene.bigguy, list.range());
            vkCmdDrawIndirectCount(cmd, command_buffer.buffer, 0, draw_count.buffer, 0,
                                   static_cast<std::uint32_t>(commands), sizeof(VkDrawIndirectCommand));
            vkCmdEndRendering(cmd);
            // Pass 1's depth to the Hi-Z build: depth writes before the compute shader's reads, in a
            // read-only layout; and our draw's reads of the list and commands done before
            // CompactPass rewrites them for pass 2 (an execution dependency, the same barrier).
            image_barrier(cmd, r.depth, VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                          depth_image.layout, kDepthStages | kDrawStages, VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                          VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
            hiz_build.run(cmd, depth_image, hiz, pc::ClipDepth::zero_to_one);
            // The flag chain. Each pass skips the patches an earlier one culled and writes its own
            // reason into those it culls.
            status.begin(cmd, all);
            frustum.run(cmd, all, view);
            // Back-patch: ONLY the closed, one-sided object (on the open teapot the inside of a
            // patch that faces away shows through the lid gap). The eye in the patches' space.
            cones.run(cmd, range_of(scene.bigguy), pc::BackpatchMethod::tcone, view.eye);
            if (options.backpatch_open) cones.run(cmd, range_of(scene.teapot), pc::BackpatchMethod::tcone, view.eye);
            // The Hi-Z test of the control-point boxes (the frustum already done).
            occlusion.run(cmd, all, view, hiz, false);
            status.end(cmd, all);
            // The depth image back to an attachment (the build's reads done first).
            image_barrier(cmd, r.depth, VK_IMAGE_ASPECT_DEPTH_BIT, 1, depth_image.layout,
                          VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0,
                          kDepthStages,
                          VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
            // Pass 2: the patches newly visible (passed now, not drawn in pass 1), into the same
            // ids and depth.
            if (!options.aggressive) {
                compact.run(cmd, all, pc::kStatusVisible | pc::kStatusNewlyVisible,
                            pc::kStatusVisible | pc::kStatusNewlyVisible, outputs);
                r.begin(cmd, false, v, scene.bigguy, list.range());
                vkCmdDrawIndirectCount(cmd, command_buffer.buffer, 0, draw_count.buffer, 0,
                                       static_cast<std::uint32_t>(commands), sizeof(VkDrawIndirectCommand));
                vkCmdEndRendering(cmd);
            }

            // Copies of both images into the read-back buffer at slot (0: culled ids, 1: culled
            // depth, 2: unculled ids, 3: unculled depth), then the images back to attachments.
            auto copy_out = [&](int slot) {
                image_barrier(cmd, r.ids, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                              VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                              VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                              VK_ACCESS_TRANSFER_READ_BIT);
                image_barrier(cmd, r.depth, VK_IMAGE_ASPECT_DEPTH_BIT, 1,
                              VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                              kDepthStages, VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                              VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
                VkBufferImageCopy copy{};
                copy.imageExtent = {static_cast<std::uint32_t>(r.width), static_cast<std::uint32_t>(r.height), 1};
                copy.bufferOffset = static_cast<VkDeviceSize>(2 * slot) * pixels * 4;
                copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                vkCmdCopyImageToBuffer(cmd, r.ids, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback.buffer, 1, &copy);
                copy.bufferOffset += pixels * 4;
                copy.imageSubresource.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
                vkCmdCopyImageToBuffer(cmd, r.depth, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback.buffer, 1, &copy);
            };
            copy_out(0);

            // ---- the reference: every patch (the list 0..n-1), the same pipeline ----
            image_barrier(cmd, r.ids, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                          VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                          VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
            image_barrier(cmd, r.depth, VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                          VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                          kDepthStages,
                          VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
            r.begin(cmd, true, v, scene.bigguy, all_list.range());
            for (std::size_t first = 0; first < n; first += per_command)
                vkCmdDraw(cmd, static_cast<std::uint32_t>(16 * std::min(per_command, n - first)), 1,
                          static_cast<std::uint32_t>(16 * first), 0);
            vkCmdEndRendering(cmd);
            copy_out(1);
        });

        // Who culled what (each culled patch keeps the reason of the pass that culled it), and
        // which patches the culled frame drew.
        std::size_t culled_frustum = 0, culled_backpatch = 0, culled_teapot_backpatch = 0, culled_occlusion = 0;
        std::size_t drawn1 = 0, drawn2 = 0;
        std::vector<bool> drawn(n, false);
        for (std::size_t p = 0; p < n; ++p) {
            const std::uint32_t reason = words[p] & pc::kCullReasonMask;
            culled_frustum += reason == pc::kCullFrustum;
            culled_backpatch += reason == pc::kCullBackPatch;
            culled_teapot_backpatch += reason == pc::kCullBackPatch && p < scene.teapot.first + scene.teapot.count;
            culled_occlusion += reason == pc::kCullOcclusion;
            const bool pass1 = (words_before[p] & pc::kStatusVisible) != 0;
            const bool pass2 = !options.aggressive && (words[p] & pc::kStatusNewlyVisible) != 0;
            drawn1 += pass1;
            drawn2 += pass2;
            drawn[p] = pass1 || pass2;
        }
        total_frustum += culled_frustum;
        total_backpatch += culled_backpatch;
        total_occlusion += culled_occlusion;
        const auto* ids = readback.data<std::uint32_t>();
        const auto* depth = readback.data<float>();
        const Comparison cmp = compare(ids, depth + pixels, ids + 2 * pixels, depth + 3 * pixels, pixels, drawn);
        const bool ok = cmp.differing == 0 && cmp.false_culls == 0;
        mismatched += ok ? 0 : 1;
        std::string verdict = ok ? "ids match"
                                 : "IDS DIFFER in " + std::to_string(cmp.differing) + " pixels, " +
                                       std::to_string(cmp.false_culls) + " false culls";
        if (cmp.ties) verdict += " (" + std::to_string(cmp.ties) + " exact depth-tie pixels, both patches drawn)";
        std::string backpatch = std::to_string(culled_backpatch);
        if (options.backpatch_open) backpatch += " (teapot " + std::to_string(culled_teapot_backpatch) + ")";
        std::printf(
            "frame %d (camera %d): culled frustum %zu, back-patch %s, occlusion %zu; drawn pass 1 %zu, pass 2 "
            "%zu%s of %zu; %s\n",
            f, f / options.frames, culled_frustum, backpatch.c_str(), culled_occlusion, drawn1, drawn2,
            options.aggressive ? " (skipped: --aggressive)" : "", n, verdict.c_str());
        std::fflush(stdout);
    }

    if (g_validation_messages) {
        std::printf("FAILED: %d Vulkan validation message(s)\n", g_validation_messages);
        return 1;
    }
    if (mismatched) {
        std::printf("FAILED: %d of %d frames differ from the unculled draw\n", mismatched, frames);
        return 1;
    }
    // Each cull pass must have culled something, or the check says nothing about it.
    const struct {
        std::size_t count;
        const char* pass;
    } culled[] = {{total_frustum, "FrustumPass"},
                  {total_backpatch, "BackpatchConePass (tcone)"},
                  {total_occlusion, "OcclusionPass"}};
    for (const auto& pass : culled)
        if (pass.count == 0) {
            std::printf("FAILED: %s culled nothing over the run, so the check proved nothing about it\n", pass.pass);
            return 1;
        }
    std::printf(
        "all %d frames match the unculled draw (patch-frames culled: %zu frustum, %zu back-patch tcone, %zu "
        "occlusion)\n",
        frames, total_frustum, total_backpatch, total_occlusion);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    int status = 2;
    try {
        const Options options = parse_options(argc, argv);
        status = run(options);
    } catch (const SetupError& e) {
        std::fprintf(stderr, "%s\n", pc::printable_line(e.message).c_str());
    } catch (const std::exception& e) {  // patchcull::Error from the import layer or a pass: one line
        std::fprintf(stderr, "%s\n", pc::printable_line(e.what()).c_str());
    }
    // Validation messages while destroying (the Gpu is gone by now) also fail the run.
    if (status == 0 && g_validation_messages) {
        std::printf("FAILED: %d Vulkan validation message(s)\n", g_validation_messages);
        status = 1;
    }
    return status;
}
