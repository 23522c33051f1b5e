// CullRenderer (patchcull/vk/vk_renderer.h): the headless Vulkan renderer and its two-pass frame,
// the Vulkan twin of src/gl's CullPipeline (cull_pipeline.cpp, frame_chain.cpp) for one object.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "draw_pipelines.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/error.h"
#include "patchcull/vk/vk_renderer.h"
#include "renderer_resources.h"
#include "shared.h"

namespace patchcull::vk {

namespace sh = gl::shared;
using detail::DrawKind;
using detail::DrawPushConstants;
using detail::full_barrier;
using detail::HostBuffer;
using detail::Image;

namespace {

// The projection as Vulkan draws it: y row negated (image row 0 = the top of OpenGL's picture).
Mat4 y_down(const Mat4& projection) {
    Mat4 p = projection;
    for (int c = 0; c < 4; ++c) p.at(1, c) = -p.at(1, c);
    return p;
}

// Timestamps of a frame: at most this many marks.
constexpr std::uint32_t kMaxMarks = 8;

}  // namespace

struct CullRenderer::Impl {
    explicit Impl(HeadlessDevice& d)
        : dev(d),
          passes(d.physical_device(), d.device(), exact_fma()),
          status(passes),
          frustum(passes),
          frustum_disp(passes),
          cones(passes),
          ptp(passes),
          hiz_build(passes),
          occlusion(passes),
          fused(passes),
          displaced(passes),
          compact(passes),
          draws(d),
          control_points(d),
          flags(d),
          margins(d),
          texcoords(d),
          tangents(d),
          tess_scale(d),
          ranges(d),
          marks(d),
          occluder_vertices(d),
          counters(d),
          readback(d),
          lists{HostBuffer(d), HostBuffer(d)},
          commands{HostBuffer(d), HostBuffer(d)},
          counts{HostBuffer(d), HostBuffer(d)},
          scratch{HostBuffer(d), HostBuffer(d)},
          color(d),
          ids(d),
          depth(d),
          hiz_image(d),
          displacement(d) {
        try {
            create_objects();
        } catch (...) {
            destroy_objects();
            throw;
        }
    }
    ~Impl() {
        vkDeviceWaitIdle(dev.device());
        destroy_objects();
    }
    // The sampler, the timestamp pool and the first (empty) inputs; destroy_objects undoes them.
    void create_objects() {
        VkSamplerCreateInfo sampler{};
        sampler.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
        sampler.magFilter = VK_FILTER_LINEAR;
        sampler.minFilter = VK_FILTER_LINEAR;
        sampler.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
        sampler.addressModeU = sampler.addressModeV = sampler.addressModeW = VK_SAMPLER_ADDRESS_MODE_REPEAT;
        sampler.maxLod = 0.0f;
        detail::check_renderer(vkCreateSampler(dev.device(), &sampler, nullptr, &linear), "vkCreateSampler");
        VkQueryPoolCreateInfo query{};
        query.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
        query.queryType = VK_QUERY_TYPE_TIMESTAMP;
        query.queryCount = kMaxMarks;
        detail::check_renderer(vkCreateQueryPool(dev.device(), &query, nullptr, &timestamps), "vkCreateQueryPool");
        counters.assign(nullptr, sh::kCounterCount * 4);
        for (HostBuffer& list : lists) list.reserve(4);  // bound by every patch draw (flags too)
        set_displacement_map({});
        flags.assign(nullptr, 4);
        upload_patches(nullptr, 0, {}, false);
    }
    void destroy_objects() {
        if (linear) vkDestroySampler(dev.device(), linear, nullptr);
        if (timestamps) vkDestroyQueryPool(dev.device(), timestamps, nullptr);
        linear = VK_NULL_HANDLE;
        timestamps = VK_NULL_HANDLE;
    }
    Impl(const Impl&) = delete;
    Impl& operator=(const Impl&) = delete;

    static PassContextOptions exact_fma() {
        PassContextOptions o;
        o.fma = PassContextOptions::Fma::exact_double;
        return o;
    }

    HeadlessDevice& dev;
    PassContext passes;
    CullStatusPass status;
    FrustumPass frustum;
    FrustumDispPass frustum_disp;
    BackpatchConePass cones;
    BackpatchPtpPass ptp;
    HiZBuildPass hiz_build;
    OcclusionPass occlusion;
    FusedCullPass fused;
    DisplacedPass displaced;
    CompactPass compact;
    detail::DrawPipelines draws;
    HostBuffer control_points, flags, margins, texcoords, tangents, tess_scale, ranges, marks, occluder_vertices,
        counters, readback;
    HostBuffer lists[2], commands[2], counts[2], scratch[2];  // per draw pass (indirect)
    std::size_t used_commands[2] = {0, 0};                    // commands compacted this frame
    Image color, ids, depth, hiz_image, displacement;
    HiZImage hiz;
    VkSampler linear = VK_NULL_HANDLE;
    VkQueryPool timestamps = VK_NULL_HANDLE;
    std::uint32_t marks_written = 0;

    std::size_t count = 0;
    bool has_margins = false, has_ranges = false, has_tangents = false;
    float max_tess_scale = 1.0f;
    bool primed = false;  // the statuses of the first frame are set
    bool has_map = false;
    float map_scale = 0.0f, map_midlevel = 0.5f;
    std::size_t occluder_triangles = 0;
    std::vector<TriangleRange> occluder_sides[2];  // two-sided, one-sided
    int width = 0, height = 0;
    ClipDepth frame_depth = ClipDepth::zero_to_one;

    void upload_patches(const std::vector<BezierPatch>* patches, std::size_t n, const PatchAttributes& a,
                        bool keep_flags);
    void set_displacement_map(const DisplacementMap& map);
    void ensure_targets(int w, int h);
    DrawPushConstants push_constants(const RenderParams& rp, bool mark_drawn) const;
    int level(const RenderParams& rp) const { return std::clamp(rp.tess_level, 1, 64); }
    std::size_t patches_per_draw(int lvl) const {  // core/render_params.h's llvmpipe split
        return max_patches_per_draw(std::min(64, static_cast<int>(static_cast<float>(lvl) * max_tess_scale)));
    }
    PatchBuffers chain_buffers(bool displacing) const {
        PatchBuffers b;
        b.control_points = control_points.range(std::max<std::size_t>(count, 1) * sizeof(BezierPatch));
        b.flags = flags.range(std::max<std::size_t>(count, 1) * 4);
        if (displacing && has_margins) b.margins = margins.range(std::max<std::size_t>(count, 1) * 4);
        b.first = 0;
        b.count = count;
        return b;
    }

    void mark(VkCommandBuffer cmd) {
        if (dev.timestamp_period_ns() > 0 && marks_written < kMaxMarks)
            vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, timestamps, marks_written);
        ++marks_written;
    }
    std::vector<double> intervals() {
        const std::uint32_t n = std::min(marks_written, kMaxMarks);
        std::vector<double> ms(n > 0 ? n - 1 : 0, 0.0);
        if (dev.timestamp_period_ns() <= 0 || n < 2) return ms;
        std::uint64_t t[kMaxMarks] = {};
        detail::check_renderer(
            vkGetQueryPoolResults(dev.device(), timestamps, 0, n, sizeof(t), t, sizeof(std::uint64_t),
                                  VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
            "vkGetQueryPoolResults");
        for (std::uint32_t i = 0; i + 1 < n; ++i)
            ms[i] = static_cast<double>(t[i + 1] - t[i]) * dev.timestamp_period_ns() * 1e-6;
        return ms;
    }

    // ---- drawing ---------------------------------------------------------------------------
    void begin_rendering(VkCommandBuffer cmd, bool clear) const {
        VkRenderingAttachmentInfo attachments[2]{};
        for (int i = 0; i < 2; ++i) {
            attachments[i].sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
            attachments[i].imageView = i == 0 ? color.view() : ids.view();
            attachments[i].imageLayout = VK_IMAGE_LAYOUT_GENERAL;
            attachments[i].loadOp = clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
            attachments[i].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        }
        attachments[0].clearValue.color = {{0.12f, 0.12f, 0.14f, 1.0f}};
        attachments[1].clearValue.color.uint32[0] = sh::kIdBackground;
        VkRenderingAttachmentInfo depth_attachment{};
        depth_attachment.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
        depth_attachment.imageView = depth.view();
        depth_attachment.imageLayout = VK_IMAGE_LAYOUT_GENERAL;
        depth_attachment.loadOp = clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
        depth_attachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        depth_attachment.clearValue.depthStencil.depth = is_reversed(frame_depth) ? 0.0f : 1.0f;
        VkRenderingInfo info{};
        info.sType = VK_STRUCTURE_TYPE_RENDERING_INFO;
        info.renderArea = {{0, 0}, {static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height)}};
        info.layerCount = 1;
        info.colorAttachmentCount = 2;
        info.pColorAttachments = attachments;
        info.pDepthAttachment = &depth_attachment;
        vkCmdBeginRendering(cmd, &info);
        const VkViewport viewport{0, 0, static_cast<float>(width), static_cast<float>(height), 0.0f, 1.0f};
        vkCmdSetViewport(cmd, 0, 1, &viewport);
        vkCmdSetScissor(cmd, 0, 1, &info.renderArea);
    }

    void draw_occluders(VkCommandBuffer cmd, const DrawPushConstants& pc) {
        if (occluder_triangles == 0) return;
        VkDescriptorBufferInfo buffer{occluder_vertices.buffer(), 0, VK_WHOLE_SIZE};
        VkWriteDescriptorSet write{};
        write.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        write.dstBinding = sh::kBindingOccluderVertices;
        write.descriptorCount = 1;
        write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        write.pBufferInfo = &buffer;
        for (int side = 0; side < 2; ++side) {
            if (occluder_sides[side].empty()) continue;
            vkCmdBindPipeline(
                cmd, VK_PIPELINE_BIND_POINT_GRAPHICS,
                draws.get(side ? DrawKind::occluders_one_sided : DrawKind::occluders, is_reversed(frame_depth)));
            draws.push_descriptors()(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, draws.occluder_layout(), 0, 1, &write);
            vkCmdPushConstants(cmd, draws.occluder_layout(), VK_SHADER_STAGE_ALL_GRAPHICS, 0, sizeof(pc), &pc);
            for (const TriangleRange& r : occluder_sides[side])
                vkCmdDraw(cmd, static_cast<std::uint32_t>(3 * r.count), 1, static_cast<std::uint32_t>(3 * r.first), 0);
        }
    }

    // Binds kind's pipeline with the patch buffers, marks, draw list and displacement map.
    void bind_patch_draw(VkCommandBuffer cmd, DrawKind kind, const DrawPushConstants& pc, const HostBuffer& list) {
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, draws.get(kind, is_reversed(frame_depth)));
        const std::pair<std::uint32_t, const HostBuffer*> buffers[] = {
            {sh::kBindingControlPoints, &control_points}, {sh::kBindingCullFlags, &flags},
            {sh::kBindingMaxDisplacement, &margins},      {sh::kBindingPatchTexcoords, &texcoords},
            {sh::kBindingPatchTangents, &tangents},       {sh::kBindingPatchMarks, &marks},
            {sh::kBindingPatchTessScale, &tess_scale},    {sh::kBindingDrawList, &list}};
        VkDescriptorBufferInfo infos[9]{};
        VkWriteDescriptorSet writes[9]{};
        for (std::size_t i = 0; i < 8; ++i) {
            infos[i] = {buffers[i].second->buffer(), 0, VK_WHOLE_SIZE};
            writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
            writes[i].dstBinding = buffers[i].first;
            writes[i].descriptorCount = 1;
            writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            writes[i].pBufferInfo = &infos[i];
        }
        VkDescriptorImageInfo image{linear, displacement.view(), VK_IMAGE_LAYOUT_GENERAL};
        writes[8].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        writes[8].dstBinding = 31;  // shaders/draw_params.h's kTextureUnitDisplacement under Vulkan
        writes[8].descriptorCount = 1;
        writes[8].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
        writes[8].pImageInfo = &image;
        draws.push_descriptors()(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, draws.patch_layout(), 0, 9, writes);
        vkCmdPushConstants(cmd, draws.patch_layout(), VK_SHADER_STAGE_ALL_GRAPHICS, 0, sizeof(pc), &pc);
    }

    // Every patch issued in sub-draws of at most patches_per_draw; the TCS keeps (w & mask) == value.
    void draw_selected(VkCommandBuffer cmd, DrawKind kind, DrawPushConstants pc, std::uint32_t mask,
                       std::uint32_t value, int lvl) {
        if (count == 0) return;
        pc.draw_mask = mask;
        pc.draw_value = value;
        bind_patch_draw(cmd, kind, pc, lists[0]);
        const std::size_t per_draw = patches_per_draw(lvl);
        for (std::size_t first = 0; first < count; first += per_draw)
            vkCmdDraw(cmd, static_cast<std::uint32_t>(16 * std::min(per_draw, count - first)), 1,
                      static_cast<std::uint32_t>(16 * first), 0);
    }

    // Lists the patches of pass `pass` that (w & mask) == value keeps (before the rendering).
    void compact_pass(VkCommandBuffer cmd, int pass, std::uint32_t mask, std::uint32_t value, int lvl,
                      CompactMethod method) {
        const std::size_t k = patches_per_indirect_command(patches_per_draw(lvl), dev.is_software());
        const std::size_t command_count = compact_command_count(count, k);
        lists[pass].reserve(std::max<std::size_t>(count, 1) * 4);
        commands[pass].reserve(command_count * 16);
        counts[pass].reserve(4);
        scratch[pass].reserve(compact_scratch_bytes(count, method));
        DrawListRanges out;
        out.list = lists[pass].range(std::max<std::size_t>(count, 1) * 4);
        out.command = commands[pass].range(command_count * 16);
        out.draw_count = counts[pass].range(4);
        out.scratch = scratch[pass].range(std::max<std::size_t>(compact_scratch_bytes(count, method), 4));
        out.patches_per_command = k;
        compact.run(cmd, chain_buffers(false), mask, value, out, method);
        used_commands[pass] = command_count;
    }

    void draw_list(VkCommandBuffer cmd, int pass, DrawPushConstants pc) {
        if (count == 0 || used_commands[pass] == 0) return;
        pc.draw_mask = 0;
        pc.draw_value = 0;
        bind_patch_draw(cmd, DrawKind::patch_list, pc, lists[pass]);
        vkCmdDrawIndirectCount(cmd, commands[pass].buffer(), 0, counts[pass].buffer(), 0,
                               static_cast<std::uint32_t>(used_commands[pass]), 16);
    }

    // One draw pass: its compaction (indirect), then clear (first) or load, occluders (first),
    // the patches of the selection.
    void draw_pass(VkCommandBuffer cmd, int pass, bool first, std::uint32_t mask, std::uint32_t value,
                   const CullFrameParams& params, const DrawPushConstants& pc) {
        const int lvl = level(params.render);
        if (params.indirect && count > 0) compact_pass(cmd, pass, mask, value, lvl, params.compact);
        begin_rendering(cmd, first);
        if (first) draw_occluders(cmd, pc);
        if (params.indirect)
            draw_list(cmd, pass, pc);
        else
            draw_selected(cmd, DrawKind::patches, pc, mask, value, lvl);
        vkCmdEndRendering(cmd);
        full_barrier(cmd);
    }

    void run_chain(VkCommandBuffer cmd, const CullFrameParams& params, const CullView& view, std::uint32_t tests,
                   bool displacing, bool fused_pass, bool occluding);
    void copy_images(VkCommandBuffer cmd);
    FrameImages read_images(std::size_t mark_count);
};

// ---- patches and inputs ------------------------------------------------------------------------

void CullRenderer::Impl::upload_patches(const std::vector<BezierPatch>* patches, std::size_t n,
                                        const PatchAttributes& a, bool keep_flags) {
    auto check_size = [n](std::size_t size, const char* what) {
        if (size != 0 && size != n)
            throw Error(std::string("Vulkan: CullRenderer: ") + what + " has " + std::to_string(size) +
                        " entries for " + std::to_string(n) + " patches");
    };
    check_size(a.max_displacement.size(), "max_displacement");
    check_size(a.texcoords.size(), "texcoords");
    check_size(a.tangent_index.size(), "tangent_index");
    check_size(a.displacement_ranges.size(), "displacement_ranges");
    check_size(a.depth.size(), "depth");
    for (std::int32_t t : a.tangent_index)
        if (t >= 0 && static_cast<std::size_t>(t) >= a.tangents.size())
            throw Error("Vulkan: CullRenderer: tangent_index " + std::to_string(t) + " is past the " +
                        std::to_string(a.tangents.size()) + " tangent patches");
    if (patches)
        for (std::size_t p = 0; p < n; ++p) check_patch_weights((*patches)[p], p);
    if (n > 0x7FFFFFFFu / 16) throw Error("Vulkan: CullRenderer: too many patches (" + std::to_string(n) + ")");
    if (keep_flags && n != count)
        throw Error("Vulkan: CullRenderer: update_patches: " + std::to_string(n) + " patches for a set of " +
                    std::to_string(count));
    vkDeviceWaitIdle(dev.device());  // the buffers may be replaced
    count = n;
    control_points.assign(patches ? patches->data() : nullptr, std::max<std::size_t>(n, 1) * sizeof(BezierPatch));
    if (!keep_flags) {
        flags.assign(nullptr, std::max<std::size_t>(n, 1) * 4);
        primed = false;
    }
    std::vector<float> m = a.max_displacement;
    if (m.empty() && !a.displacement_ranges.empty())
        for (const DisplacementRange& r : a.displacement_ranges) m.push_back(r.max_abs());
    has_margins = !m.empty();
    margins.assign(has_margins ? m.data() : nullptr, std::max<std::size_t>(n, 1) * 4);
    has_ranges = !a.displacement_ranges.empty();
    ranges.assign(has_ranges ? a.displacement_ranges.data() : nullptr,
                  std::max<std::size_t>(n, 1) * sizeof(DisplacementRange));
    std::vector<Vec2> uv(4 * std::max<std::size_t>(n, 1));
    for (std::size_t p = 0; p < n; ++p)
        for (int c = 0; c < 4; ++c)
            uv[4 * p + c] = a.texcoords.empty() ? Vec2{float(c & 1), float(c >> 1)} : a.texcoords[p][c];
    texcoords.assign(uv.data(), uv.size() * sizeof(Vec2));
    std::vector<Vec4> t(std::max<std::size_t>(1, a.tangent_index.empty() ? 1 : n * sh::kTangentVec4s));
    for (std::size_t p = 0; p < a.tangent_index.size(); ++p) {
        if (a.tangent_index[p] < 0) continue;
        const TangentPatches& tp = a.tangents[static_cast<std::size_t>(a.tangent_index[p])];
        Vec4* out = &t[p * sh::kTangentVec4s];
        for (int k = 0; k < 12; ++k) out[k] = {tp.du[k].x, tp.du[k].y, tp.du[k].z, 0.0f};
        for (int k = 0; k < 12; ++k) out[12 + k] = {tp.dv[k].x, tp.dv[k].y, tp.dv[k].z, 0.0f};
        out[0].w = 1.0f;
    }
    tangents.assign(t.data(), t.size() * sizeof(Vec4));
    has_tangents = !a.tangent_index.empty();
    const int deepest = a.depth.empty() ? 0 : *std::max_element(a.depth.begin(), a.depth.end());
    std::vector<float> scales(std::max<std::size_t>(n, 1), 1.0f);
    for (std::size_t p = 0; p < a.depth.size(); ++p)
        scales[p] = std::ldexp(1.0f, std::min(deepest - int(a.depth[p]), 6));
    max_tess_scale = *std::max_element(scales.begin(), scales.end());
    tess_scale.assign(scales.data(), scales.size() * sizeof(float));
    marks.assign(nullptr, std::max<std::size_t>(n, 1) * 4);
}

void CullRenderer::Impl::set_displacement_map(const DisplacementMap& map) {
    if (!map.empty() && map.texels.size() != static_cast<std::size_t>(map.width) * map.height)
        throw Error("Vulkan: CullRenderer: displacement map texels are not width x height");
    vkDeviceWaitIdle(dev.device());
    has_map = !map.empty();
    map_scale = map.scale;
    map_midlevel = map.midlevel;
    const int w = has_map ? map.width : 1, h = has_map ? map.height : 1;
    VkImageCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = VK_FORMAT_R32_SFLOAT;
    info.extent = {static_cast<std::uint32_t>(w), static_cast<std::uint32_t>(h), 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    displacement.create(info, VK_IMAGE_ASPECT_COLOR_BIT);
    const float zero = 0.0f;
    readback.assign(has_map ? map.texels.data() : &zero, static_cast<std::size_t>(w) * h * sizeof(float));
    dev.submit([&](VkCommandBuffer cmd) {
        detail::to_general(cmd, displacement.image(), VK_IMAGE_ASPECT_COLOR_BIT);
        VkBufferImageCopy region{};
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageExtent = info.extent;
        vkCmdCopyBufferToImage(cmd, readback.buffer(), displacement.image(), VK_IMAGE_LAYOUT_GENERAL, 1, &region);
        full_barrier(cmd);
    });
}

void CullRenderer::Impl::ensure_targets(int w, int h) {
    if (w < 1 || h < 1 || w > 8192 || h > 8192)
        throw Error("Vulkan: CullRenderer: size " + std::to_string(w) + "x" + std::to_string(h) + " outside [1, 8192]");
    if (w == width && h == height) return;
    vkDeviceWaitIdle(dev.device());
    VkImageCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    info.imageType = VK_IMAGE_TYPE_2D;
    info.extent = {static_cast<std::uint32_t>(w), static_cast<std::uint32_t>(h), 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.format = VK_FORMAT_R8G8B8A8_UNORM;
    info.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    color.create(info, VK_IMAGE_ASPECT_COLOR_BIT);
    info.format = VK_FORMAT_R32_UINT;
    ids.create(info, VK_IMAGE_ASPECT_COLOR_BIT);
    info.format = VK_FORMAT_D32_SFLOAT;
    info.usage =
        VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    depth.create(info, VK_IMAGE_ASPECT_DEPTH_BIT);
    const VkImageCreateInfo hiz_info = hiz_image_create_info(w, h);
    hiz_image.create(hiz_info, VK_IMAGE_ASPECT_COLOR_BIT);
    hiz = HiZImage{};
    hiz.image = hiz_image.image();
    hiz.all_levels = hiz_image.view();
    for (std::uint32_t l = 0; l < hiz_info.mipLevels; ++l) hiz.level_views[l] = hiz_image.level_view(l);
    hiz.width = w;
    hiz.height = h;
    dev.submit([&](VkCommandBuffer cmd) {
        detail::to_general(cmd, color.image(), VK_IMAGE_ASPECT_COLOR_BIT);
        detail::to_general(cmd, ids.image(), VK_IMAGE_ASPECT_COLOR_BIT);
        detail::to_general(cmd, depth.image(), VK_IMAGE_ASPECT_DEPTH_BIT);
        detail::to_general(cmd, hiz_image.image(), VK_IMAGE_ASPECT_COLOR_BIT);
    });
    width = w;
    height = h;
}

DrawPushConstants CullRenderer::Impl::push_constants(const RenderParams& rp, bool mark_drawn) const {
    DrawPushConstants pc{};
    const Mat4 object_to_clip = y_down(rp.projection) * rp.view;
    std::copy(std::begin(object_to_clip.m), std::end(object_to_clip.m), pc.object_to_clip);
    Mat4 inverse;
    if (invert(rp.view, inverse)) {
        pc.eye[0] = inverse.at(0, 3);
        pc.eye[1] = inverse.at(1, 3);
        pc.eye[2] = inverse.at(2, 3);
    }
    pc.tess_level = static_cast<float>(level(rp));
    pc.adaptive = rp.adaptive_tess ? 1u : 0u;
    pc.tess_reference = rp.tess_reference_distance > 0 ? rp.tess_reference_distance : 1.0f;
    pc.mark_drawn = mark_drawn ? 1u : 0u;
    pc.has_tangents = has_tangents ? 1u : 0u;
    pc.displacement_scale = map_scale;
    pc.displacement_midlevel = map_midlevel;
    pc.color_mode = sh::kColorPatch;
    pc.discard_back_facing = rp.discard_back_facing ? 1u : 0u;
    pc.displace = rp.displace && has_map ? 1u : 0u;
    pc.has_margins = has_margins ? 1u : 0u;
    return pc;
}

// ---- the frame ---------------------------------------------------------------------------------

void CullRenderer::Impl::run_chain(VkCommandBuffer cmd, const CullFrameParams& params, const CullView& view,
                                   std::uint32_t tests, bool displacing, bool fused_pass, bool occluding) {
    const PatchBuffers b = chain_buffers(displacing);
    const ClipDepth d = params.render.depth;
    status.begin(cmd, b);
    if (fused_pass) {
        const std::uint32_t fused_tests =
            (tests & (kCullFrustum | kCullBackPatch)) | (occluding ? (tests & kCullOcclusion) : 0u);
        const BackpatchMethod method =
            (tests & kCullBackPatch) ? params.backpatch : BackpatchMethod::tcone;  // unused without the test
        fused.run(cmd, b, fused_tests, view.object_to_clip, d, method, view.eye, hiz);
    } else if (tests & kCullFrustum) {
        if (params.frustum_aabb)
            frustum_disp.run(cmd, b, view);
        else
            frustum.run(cmd, b, view);
    }
    mark(cmd);
    if (!fused_pass && (tests & kCullBackPatch)) {
        if (params.backpatch == BackpatchMethod::ptp)
            ptp.run(cmd, b, view.object_to_clip, view.alpha, params.ptp_rule);
        else
            cones.run(cmd, b, params.backpatch, view.eye);
    }
    mark(cmd);
    const bool occlusion_test = occluding && (tests & kCullOcclusion);
    const bool bounds = displacing && has_ranges &&
                        (params.frustum_aabb ? occlusion_test : (tests & (kCullFrustum | kCullOcclusion)) != 0);
    if (occlusion_test && !fused_pass) occlusion.run(cmd, b, view, hiz, false);
    if (bounds)
        displaced.run(cmd, b, ranges.range(std::max<std::size_t>(count, 1) * sizeof(DisplacementRange)), params.bound,
                      params.cone, make_displaced_cull_view(view), hiz, occlusion_test, true);
    status.end(cmd, b, counters.range(sh::kCounterCount * 4));
    mark(cmd);
}

void CullRenderer::Impl::copy_images(VkCommandBuffer cmd) {
    const std::size_t pixels = static_cast<std::size_t>(width) * height;
    readback.reserve(pixels * 12);
    VkBufferImageCopy region{};
    region.imageExtent = {static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height), 1};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.bufferOffset = 0;
    vkCmdCopyImageToBuffer(cmd, ids.image(), VK_IMAGE_LAYOUT_GENERAL, readback.buffer(), 1, &region);
    region.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
    region.bufferOffset = pixels * 4;
    vkCmdCopyImageToBuffer(cmd, depth.image(), VK_IMAGE_LAYOUT_GENERAL, readback.buffer(), 1, &region);
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.bufferOffset = pixels * 8;
    vkCmdCopyImageToBuffer(cmd, color.image(), VK_IMAGE_LAYOUT_GENERAL, readback.buffer(), 1, &region);
}

FrameImages CullRenderer::Impl::read_images(std::size_t mark_count) {
    const std::size_t pixels = static_cast<std::size_t>(width) * height;
    FrameImages out;
    out.ids.resize(pixels);
    out.depth.resize(pixels);
    const auto* bytes = static_cast<const char*>(readback.data());
    std::memcpy(out.ids.data(), bytes, pixels * 4);
    std::memcpy(out.depth.data(), bytes + pixels * 4, pixels * 4);
    const std::vector<std::uint32_t> m = marks.read<std::uint32_t>(mark_count);
    out.patches.assign(m.begin(), m.end());
    for (std::uint8_t& v : out.patches) v = v ? 1 : 0;
    return out;
}

CullRenderer::CullRenderer(HeadlessDevice& device) : impl_(std::make_unique<Impl>(device)) {}
CullRenderer::~CullRenderer() = default;

void CullRenderer::set_patches(const std::vector<BezierPatch>& patches, const PatchAttributes& attributes) {
    impl_->upload_patches(&patches, patches.size(), attributes, false);
}
void CullRenderer::update_patches(const std::vector<BezierPatch>& patches, const PatchAttributes& attributes) {
    impl_->upload_patches(&patches, patches.size(), attributes, true);
}
std::size_t CullRenderer::patch_count() const { return impl_->count; }
void CullRenderer::set_displacement_map(const DisplacementMap& map) { impl_->set_displacement_map(map); }

void CullRenderer::set_occluders(const std::vector<Vec3>& vertices, const std::vector<std::uint32_t>& indices,
                                 const std::vector<TriangleRange>& one_sided) {
    Impl& m = *impl_;
    if (indices.size() % 3 != 0) throw Error("Vulkan: CullRenderer: occluder indices are not a multiple of 3");
    const std::size_t triangles = indices.size() / 3;
    if (triangles >= 0x80000000u) throw Error("Vulkan: CullRenderer: 2^31 occluder triangles or more");
    std::vector<Vec4> expanded(std::max<std::size_t>(indices.size(), 1));
    for (std::size_t i = 0; i < indices.size(); ++i) {
        if (indices[i] >= vertices.size())
            throw Error("Vulkan: CullRenderer: occluder index " + std::to_string(indices[i]) + " out of range");
        const Vec3 v = vertices[indices[i]];
        expanded[i] = {v.x, v.y, v.z, 1.0f};
    }
    std::vector<std::uint8_t> side(triangles, 0);
    for (const TriangleRange& r : one_sided) {
        if (r.first > triangles || r.count > triangles - r.first)
            throw Error("Vulkan: CullRenderer: one-sided range [" + std::to_string(r.first) + ", +" +
                        std::to_string(r.count) + ") leaves the " + std::to_string(triangles) + " triangles");
        std::fill(side.begin() + static_cast<std::ptrdiff_t>(r.first),
                  side.begin() + static_cast<std::ptrdiff_t>(r.first + r.count), std::uint8_t{1});
    }
    vkDeviceWaitIdle(m.dev.device());
    m.occluder_vertices.assign(expanded.data(), expanded.size() * sizeof(Vec4));
    m.occluder_triangles = triangles;
    m.occluder_sides[0].clear();
    m.occluder_sides[1].clear();
    for (std::size_t t = 0; t < triangles;) {
        std::size_t end = t + 1;
        while (end < triangles && side[end] == side[t]) ++end;
        m.occluder_sides[side[t]].push_back({t, end - t});
        t = end;
    }
}

CullFrameStats CullRenderer::render_frame(const CullFrameParams& params) {
    Impl& m = *impl_;
    const RenderParams& rp = params.render;
    if (rp.depth == ClipDepth::minus_one_to_one)
        throw Error(
            "Vulkan: CullRenderer: depth minus-one-to-one: Vulkan's clip space has depth 0..1 (zero-to-one, "
            "reversed or reversed-infinite)");
    if (params.backpatch != BackpatchMethod::tcone && params.backpatch != BackpatchMethod::ncone &&
        params.backpatch != BackpatchMethod::ptp && (params.tests & kCullBackPatch))
        throw Error(std::string("Vulkan: CullRenderer: the back-patch method ") +
                    backpatch_method_name(params.backpatch) + " has no Vulkan pass");
    m.ensure_targets(rp.width, rp.height);
    m.frame_depth = rp.depth;
    const CullView view = make_cull_view(rp.view, y_down(rp.projection), rp.depth);
    if (!view.has_eye) throw Error("render: the view matrix is singular (no eye position)");
    std::uint32_t tests = params.tests & (kCullFrustum | kCullBackPatch | kCullOcclusion);
    const bool two_pass = (tests & kCullOcclusion) != 0;
    const bool displacing = rp.displace && m.has_map;
    if (displacing && !m.has_margins) tests = 0;  // displaced by an unknown amount: nothing may be culled
    const bool fused_pass = params.fused_pass && !params.frustum_aabb &&
                            !((tests & kCullBackPatch) && !backpatch_method_info(params.backpatch).fusable);
    if (!m.primed) {  // Niessner & Loop §3's first frame: the even-indexed patches tagged visible
        auto* words = static_cast<std::uint32_t*>(m.flags.data());
        for (std::size_t p = 0; p < m.count; ++p) words[p] = (p % 2 == 0) ? sh::kStatusVisible : 0u;
        m.primed = true;
    }
    const DrawPushConstants pc = m.push_constants(rp, true);
    m.marks_written = 0;
    m.used_commands[0] = m.used_commands[1] = 0;
    m.dev.submit([&](VkCommandBuffer cmd) {
        full_barrier(cmd);  // the previous frame's reads and writes (and host writes) before this one
        vkCmdResetQueryPool(cmd, m.timestamps, 0, kMaxMarks);
        vkCmdFillBuffer(cmd, m.counters.buffer(), 0, VK_WHOLE_SIZE, 0);
        vkCmdFillBuffer(cmd, m.marks.buffer(), 0, VK_WHOLE_SIZE, 0);
        full_barrier(cmd);
        m.mark(cmd);
        if (two_pass) {
            m.draw_pass(cmd, 0, true, sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass, params, pc);
            m.mark(cmd);
            m.hiz_build.run(cmd, {m.depth.view(), VK_IMAGE_LAYOUT_GENERAL, VK_FORMAT_D32_SFLOAT}, m.hiz, rp.depth);
            m.mark(cmd);
            m.run_chain(cmd, params, view, tests, displacing, fused_pass, true);
            if (!params.aggressive)
                m.draw_pass(cmd, 1, false, sh::kDrawMaskSecondPass, sh::kDrawValueSecondPass, params, pc);
            m.mark(cmd);
        } else {
            m.run_chain(cmd, params, view, tests, displacing, fused_pass, false);
            m.draw_pass(cmd, 0, true, sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass, params, pc);
            m.mark(cmd);
        }
    });

    CullFrameStats stats;
    stats.patches = m.count;
    stats.two_pass = two_pass;
    stats.fused_pass = fused_pass;
    const std::vector<std::uint32_t> c = m.counters.read<std::uint32_t>(sh::kCounterCount);
    stats.frustum_culled = c[sh::kCounterFrustum];
    stats.backpatch_culled = c[sh::kCounterBackPatch];
    stats.occlusion_culled = c[sh::kCounterOcclusion];
    stats.displaced_occlusion_culled = c[sh::kCounterDisplacedOcclusion];
    stats.visible = c[sh::kCounterVisible];
    stats.newly_visible = c[sh::kCounterNewlyVisible];
    if (two_pass) {
        stats.pass1_drawn = c[sh::kCounterWasVisible];
        stats.pass2_drawn = params.aggressive ? 0 : stats.newly_visible;
    } else {
        stats.pass1_drawn = stats.visible;
    }
    for (int pass = 0; pass < 2; ++pass) {
        std::size_t submitted = 0;
        if (params.indirect) {
            const std::vector<std::uint32_t> words = m.commands[pass].read<std::uint32_t>(4 * m.used_commands[pass]);
            for (std::size_t i = 0; i < m.used_commands[pass]; ++i) submitted += words[4 * i] / 16;
        } else if (pass == 0 || (two_pass && !params.aggressive)) {
            submitted = m.count;
        }
        (pass == 0 ? stats.pass1_submitted : stats.pass2_submitted) = submitted;
    }
    // Marks: two-pass: start | pass1 | hiz | chain A | back-patch | chain B | pass2; one pass:
    // start | chain A | back-patch | chain B | pass1.
    const std::vector<double> ms = m.intervals();
    if (two_pass && ms.size() == 6) {
        stats.pass1_ms = ms[0];
        stats.hiz_ms = ms[1];
        stats.cull_ms = ms[2] + ms[3] + ms[4];
        stats.pass2_ms = ms[5];
    } else if (!two_pass && ms.size() == 4) {
        stats.cull_ms = ms[0] + ms[1] + ms[2];
        stats.pass1_ms = ms[3];
    }
    for (double t : ms) stats.total_ms += t;
    return stats;
}

FrameImages CullRenderer::capture() {
    Impl& m = *impl_;
    if (m.width == 0) throw Error("Vulkan: CullRenderer: capture: nothing drawn yet");
    m.dev.submit([&](VkCommandBuffer cmd) {
        full_barrier(cmd);
        m.copy_images(cmd);
    });
    return m.read_images(m.count);
}

FrameImages CullRenderer::render_reference(const RenderParams& params) {
    Impl& m = *impl_;
    if (params.depth == ClipDepth::minus_one_to_one)
        throw Error("Vulkan: CullRenderer: depth minus-one-to-one: Vulkan's clip space has depth 0..1");
    m.ensure_targets(params.width, params.height);
    m.frame_depth = params.depth;
    const DrawPushConstants pc = m.push_constants(params, false);
    const int lvl = m.level(params);
    m.dev.submit([&](VkCommandBuffer cmd) {
        full_barrier(cmd);
        vkCmdFillBuffer(cmd, m.marks.buffer(), 0, VK_WHOLE_SIZE, 0);
        full_barrier(cmd);
        m.begin_rendering(cmd, true);
        m.draw_occluders(cmd, pc);
        m.draw_selected(cmd, DrawKind::patches, pc, 0u, 0u, lvl);
        vkCmdEndRendering(cmd);
        full_barrier(cmd);
        // The front set: every patch fragment exactly at its pixel's front depth marks its patch.
        m.begin_rendering(cmd, false);
        m.draw_selected(cmd, DrawKind::mark_front, pc, 0u, 0u, lvl);
        vkCmdEndRendering(cmd);
        full_barrier(cmd);
        m.copy_images(cmd);
    });
    FrameImages out = m.read_images(m.count);
    // Every patch the reference's id image shows is front too (whatever the EQUAL pass found).
    for (std::uint32_t id : out.ids)
        if (id != sh::kIdBackground && !(id & sh::kIdOccluderBit) && id - 1 < out.patches.size())
            out.patches[id - 1] = 1;
    return out;
}

std::vector<std::uint8_t> CullRenderer::read_color() {
    Impl& m = *impl_;
    if (m.width == 0) throw Error("Vulkan: CullRenderer: read_color: nothing drawn yet");
    m.dev.submit([&](VkCommandBuffer cmd) {
        full_barrier(cmd);
        m.copy_images(cmd);
    });
    const std::size_t pixels = static_cast<std::size_t>(m.width) * m.height;
    std::vector<std::uint8_t> rgba(pixels * 4);
    std::memcpy(rgba.data(), static_cast<const char*>(m.readback.data()) + pixels * 8, pixels * 4);
    return rgba;
}

}  // namespace patchcull::vk
