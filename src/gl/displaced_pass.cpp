// DisplacedPass (patchcull/gl/gl_passes.h): the bounds of displaced patches (Niessner & Loop §4.2: caf,
// Munkberg et al.'s oobb; cones full, acon, con) and their frustum and Hi-Z decisions on the GPU,
// shaders/displaced.comp.glsl (one program per cone kind).
#include "pass_common.h"

namespace patchcull::gl {

static_assert(static_cast<unsigned>(DisplacedBoundKind::oobb) == shared::kDisplacedBoundOobb &&
              static_cast<unsigned>(DisplacedBoundKind::caf) == shared::kDisplacedBoundCaf);
static_assert(static_cast<unsigned>(NormalConeKind::full) == shared::kDisplacedConeFull &&
              static_cast<unsigned>(NormalConeKind::acon) == shared::kDisplacedConeAcon &&
              static_cast<unsigned>(NormalConeKind::con) == shared::kDisplacedConeCon);
static_assert(sizeof(DisplacementRange) == 2 * sizeof(float), "DisplacementRange must be two packed floats (vec2)");

struct DisplacedPass::Impl {
    explicit Impl(PassContext::Impl& c) : context(c) {}
    ~Impl() { glDeleteTextures(1, &placeholder_hiz); }
    PassContext::Impl& context;
    detail::ParamBlock block;
    // Bound instead of a pyramid for frustum-only runs: llvmpipe compiles a shader variant per
    // bound texture kind (format, power-of-two sizes, mip levels), seconds for `con`, so the
    // placeholder is of the Hi-Z's kind: R32F, power of two, several levels.
    GLuint placeholder_hiz = 0;
};

DisplacedPass::DisplacedPass(PassContext& context) : impl_(std::make_unique<Impl>(context.impl())) {}
DisplacedPass::DisplacedPass(DisplacedPass&&) noexcept = default;
DisplacedPass& DisplacedPass::operator=(DisplacedPass&&) noexcept = default;
DisplacedPass::~DisplacedPass() = default;

void DisplacedPass::run(const PatchBuffers& patches, std::uint32_t ranges, DisplacedBoundKind bound,
                        NormalConeKind cone, const DisplacedCullView& view, const HiZTexture* hiz, bool only_displaced,
                        std::uint32_t bounds) {
    Impl& m = *impl_;
    detail::begin_pass("DisplacedPass");
    detail::check_patch_buffers("DisplacedPass", patches);
    const std::size_t end = patches.first + patches.count;
    if (ranges) detail::check_buffer_size("DisplacedPass", "range", ranges, end * sizeof(DisplacementRange));
    if (bounds)
        detail::check_buffer_size("DisplacedPass", "bound", bounds,
                                  end * shared::kDisplacedBoundValues * sizeof(float));
    if (hiz && (!glIsTexture(hiz->texture) || hiz->width < 1 || hiz->height < 1))
        throw Error("GL: DisplacedPass: no Hi-Z pyramid (create_hiz_texture, HiZBuildPass)");
    if (hiz && hiz->reversed != is_reversed(view.depth))
        throw Error(std::string("GL: DisplacedPass: the view is ") + clip_depth_name(view.depth) +
                    " but the Hi-Z pyramid was built from a " + (hiz->reversed ? "reversed" : "forward") +
                    " depth buffer (HiZBuildPass::run's convention)");
    if (patches.count == 0) return;
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
    params.has_ranges = ranges ? 1u : 0u;
    params.only_displaced = only_displaced ? 1u : 0u;
    params.write_bounds = bounds ? 1u : 0u;
    params.bound_kind = static_cast<pp::uint>(bound);
    params.occlusion = hiz ? 1u : 0u;
    params.view_valid = view.valid ? 1u : 0u;
    params.screen_width = hiz ? hiz->width : 1;
    params.screen_height = hiz ? hiz->height : 1;
    params.hiz_levels = hiz ? HiZPyramid::level_count(hiz->width, hiz->height) : 1;
    params.zero = 0.0f;
    if (!hiz && !m.placeholder_hiz) {
        glCreateTextures(GL_TEXTURE_2D, 1, &m.placeholder_hiz);
        glTextureStorage2D(m.placeholder_hiz, 2, GL_R32F, 2, 2);
        glTextureParameteri(m.placeholder_hiz, GL_TEXTURE_MIN_FILTER, GL_NEAREST_MIPMAP_NEAREST);
        glTextureParameteri(m.placeholder_hiz, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    // One program per cone, bound and test (llvmpipe would run every side of a uniform branch).
    const std::string defines = "#define PC_DISPLACED_CONE " + std::to_string(static_cast<int>(cone)) +
                                "\n#define PC_DISPLACED_BOUND " + std::to_string(params.bound_kind) +
                                "u\n#define PC_DISPLACED_OCCLUSION " + (hiz ? "1" : "0") + "\n";
    glUseProgram(m.context.program("displaced.comp.glsl", defines));
    detail::bind_patch_buffers(patches);
    if (ranges) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingDisplacementRanges, ranges);
    if (bounds) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingDisplacedBounds, bounds);
    glBindTextureUnit(shared::kTextureUnitHiZ, hiz ? hiz->texture : m.placeholder_hiz);
    detail::dispatch_patches(m.block, params, patches.first, patches.count, shared::kDisplacedGroupSize);
    detail::finish_pass("DisplacedPass");
}

}  // namespace patchcull::gl
