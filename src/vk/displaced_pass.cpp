// DisplacedPass (patchcull/vk/vk_passes.h): the bounds of displaced patches (Niessner & Loop §4.2)
// and their frustum and Hi-Z decisions on Vulkan, shaders/displaced.comp.glsl (one module per
// cone kind, PC_DISPLACED_CONE); its 336-byte parameter block is the context's uniform buffer.
#include <algorithm>
#include <string>

#include "vk_common.h"

namespace patchcull::vk {

static_assert(sizeof(pp::DisplacedParams) == 336);
static_assert(sizeof(pp::DisplacedParams) <= PassContext::Impl::kParamBufferBytes);
static_assert(static_cast<unsigned>(DisplacedBoundKind::oobb) == shared::kDisplacedBoundOobb &&
              static_cast<unsigned>(DisplacedBoundKind::caf) == shared::kDisplacedBoundCaf);
static_assert(static_cast<unsigned>(NormalConeKind::full) == shared::kDisplacedConeFull &&
              static_cast<unsigned>(NormalConeKind::acon) == shared::kDisplacedConeAcon &&
              static_cast<unsigned>(NormalConeKind::con) == shared::kDisplacedConeCon);

DisplacedPass::DisplacedPass(PassContext& context) : context_(&context.impl()) {}

void DisplacedPass::run(VkCommandBuffer cmd, const PatchBuffers& patches, const BufferRange& ranges,
                        DisplacedBoundKind bound, NormalConeKind cone, const DisplacedCullView& view,
                        const HiZImage& hiz, bool occlusion, bool only_displaced, const BufferRange& bounds) {
    const char* who = "DisplacedPass";
    PassContext::Impl& context = *context_;
    const VkDeviceSize end = patches.first + patches.count;
    context.check_range(who, "control-point", patches.control_points, end * 256, false);
    context.check_range(who, "flag", patches.flags, end * 4, false);
    context.check_range(who, "margin", patches.margins, end * 4, true);
    context.check_range(who, "range", ranges, end * 8, true);
    context.check_range(who, "bound", bounds, end * shared::kDisplacedBoundValues * sizeof(float), true);
    if (!hiz.all_levels || hiz.width < 1 || hiz.height < 1)
        throw Error("Vulkan: DisplacedPass: no Hi-Z pyramid (bound in every run, read with occlusion)");
    if (occlusion && hiz.reversed != is_reversed(view.depth))
        throw Error(std::string("Vulkan: DisplacedPass: the view is ") + clip_depth_name(view.depth) +
                    " but the Hi-Z pyramid was built from a " + (hiz.reversed ? "reversed" : "forward") +
                    " depth buffer (HiZBuildPass::run's convention)");
    if (patches.count == 0) return;
    const char* variants[3] = {"PC_DISPLACED_CONE=0", "PC_DISPLACED_CONE=1", "PC_DISPLACED_CONE=2"};
    const detail::Pipeline& p = context.pipeline("displaced.comp.glsl", variants[static_cast<int>(cone)],
                                                 {shared::kBindingControlPoints,
                                                  shared::kBindingCullFlags,
                                                  shared::kBindingMaxDisplacement,
                                                  {api::kTextureHiZBinding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER},
                                                  {api::kParamsBinding, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER},
                                                  shared::kBindingDisplacementRanges,
                                                  shared::kBindingDisplacedBounds},
                                                 0);
    pp::DisplacedParams params;
    std::copy_n(view.object_to_view.m, 16, params.object_to_view);
    for (int q = 0; q < 6; ++q) {
        const Vec4& r = view.view_planes.rows[q];
        params.view_planes[q] = {r.x, r.y, r.z, r.w};
    }
    for (int i = 0; i < 3; ++i)
        params.axis_unit[i] = {view.axis_unit[i].x, view.axis_unit[i].y, view.axis_unit[i].z, 0};
    params.axis_length = {view.axis_length[0], view.axis_length[1], view.axis_length[2], 0};
    params.abs_row_z = {view.abs_row_z[0], view.abs_row_z[1], view.abs_row_z[2], view.abs_row_z[3]};
    const Mat4& pr = view.projection;
    params.proj = {pr.at(0, 0), pr.at(0, 2), pr.at(1, 1), pr.at(1, 2)};
    params.proj_z = {pr.at(2, 2), pr.at(2, 3), view.key_near, view.key_far};
    params.constants = {kDisplacedDeltaSlack, kDisplacedExtScale, kDisplacedFramePad, kDisplacedDepthSafety};
    params.has_ranges = ranges.buffer ? 1u : 0u;
    params.only_displaced = only_displaced ? 1u : 0u;
    params.write_bounds = bounds.buffer ? 1u : 0u;
    params.bound_kind = static_cast<pp::uint>(bound);
    params.occlusion = occlusion ? 1u : 0u;
    params.view_valid = view.valid ? 1u : 0u;
    params.screen_width = occlusion ? hiz.width : 1;
    params.screen_height = occlusion ? hiz.height : 1;
    params.hiz_levels = occlusion ? HiZPyramid::level_count(hiz.width, hiz.height) : 1;
    params.zero = 0.0f;

    const detail::Binding bindings[] = {{shared::kBindingControlPoints, patches.control_points},
                                        {shared::kBindingCullFlags, patches.flags},
                                        {shared::kBindingMaxDisplacement, patches.margins},
                                        {shared::kBindingDisplacementRanges, ranges},
                                        {shared::kBindingDisplacedBounds, bounds}};
    context.record_uniform(cmd, p, bindings, 5, hiz.all_levels, params, patches.first, patches.count,
                           shared::kDisplacedGroupSize);
}

}  // namespace patchcull::vk
