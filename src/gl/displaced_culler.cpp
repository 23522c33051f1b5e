// DisplacedCuller (patchcull/gl_displaced.h): GPU frustum and Hi-Z occlusion culling of displaced
// patches with the bounds of seed 000 §4.2 (Niessner & Loop, "Patch-Based Occlusion Culling for
// Hardware Tessellation": the camera-aligned frustum, CAF, with the Full / ACoN / CoN displacement
// extensions) and Munkberg et al.'s object-oriented box (OOBB), the GPU twin of
// src/core/displaced_bounds.cpp (include/patchcull/displaced_bounds.h defines every step).
// Self-contained like BackpatchCuller: its own programs, buffers and Hi-Z texture; shares only the
// layouts and bindings of shaders/shared.h and shaders/displaced_shared.h with the renderer.
#include <epoxy/gl.h>

#include <algorithm>
#include <bit>
#include <string>
#include <vector>

#include "displaced_shared.h"
#include "patchcull/error.h"
#include "patchcull/gl_backpatch.h"
#include "patchcull/gl_displaced.h"
#include "renderer_internal.h"
#include "shader_sources.h"
#include "shared.h"

namespace patchcull::gl {

namespace {

namespace ds = displaced_shared;

static_assert(kFlagFrustum == sh::kCullFrustum && kFlagOcclusion == sh::kCullOcclusion);
static_assert(static_cast<unsigned>(DisplacedBoundKind::oobb) == ds::kDisplacedBoundOobb &&
              static_cast<unsigned>(DisplacedBoundKind::caf) == ds::kDisplacedBoundCaf);
static_assert(static_cast<unsigned>(NormalConeKind::full) == ds::kDisplacedConeFull &&
              static_cast<unsigned>(NormalConeKind::acon) == ds::kDisplacedConeAcon &&
              static_cast<unsigned>(NormalConeKind::con) == ds::kDisplacedConeCon);
static_assert(sizeof(DisplacementRange) == 2 * sizeof(float), "DisplacementRange must be two packed floats (vec2)");

using detail::check_gl;
using detail::upload;

// Patches per dispatch: at most 65535 work groups (the GL minimum of the x count).
constexpr std::size_t kMaxGroups = 65535;
constexpr int kConeKinds = 3;

}  // namespace

struct DisplacedCuller::Impl {
    GLuint programs[kConeKinds] = {0, 0, 0};
    GLuint own_points = 0, flags = 0, ranges = 0, bounds = 0, hiz = 0;
    // Bound instead of hiz while there is none (frustum passes before set_hiz): llvmpipe compiles a
    // shader variant per bound texture kind (format, power-of-two sizes, mip levels), seconds for
    // `con`, so the placeholder is of the Hi-Z's kind: R32F, power of two, several levels.
    GLuint placeholder_hiz = 0;
    GLuint points = 0;  // own_points or the caller's buffer
    std::size_t count = 0;
    bool has_ranges = false;
    bool fma_via_double = false;
    int hiz_width = 0, hiz_height = 0, hiz_levels = 0;

    ~Impl() {
        for (GLuint p : programs) glDeleteProgram(p);
        const GLuint buffers[] = {own_points, flags, ranges, bounds};
        glDeleteBuffers(4, buffers);
        glDeleteTextures(1, &hiz);
        glDeleteTextures(1, &placeholder_hiz);
    }

    GLuint program(NormalConeKind cone) {
        const int k = static_cast<int>(cone);
        if (!programs[k]) {
            std::string defines = "#define PC_DISPLACED_CONE " + std::to_string(k) + "\n";
            if (fma_via_double) defines += "#define PATCHCULL_FMA_VIA_DOUBLE 1\n";
            programs[k] = detail::link_program({{"cull_displaced.comp.glsl", GL_COMPUTE_SHADER}},
                                               "cull_displaced.comp.glsl", defines);
        }
        return programs[k];
    }

    void resize_flags(std::size_t n) {
        count = n;
        upload(flags, n * sizeof(std::uint32_t), nullptr);
        glClearNamedBufferData(flags, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
    }

    void upload_ranges(const DisplacementRange* r, std::size_t n) {
        has_ranges = r != nullptr;
        upload(ranges, has_ranges ? n * sizeof(DisplacementRange) : 0, r);
    }

    std::vector<std::uint32_t> read_words() const {
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        std::vector<std::uint32_t> words(count);
        if (count)
            glGetNamedBufferSubData(flags, 0, static_cast<GLsizeiptr>(count * sizeof(std::uint32_t)), words.data());
        check_gl("displaced flag read-back");
        return words;
    }

    void run(DisplacedBoundKind bound, NormalConeKind cone, const DisplacedCullView& view, bool occlusion,
             std::vector<DisplacedBound>* bound_out) {
        if (occlusion && !hiz) throw Error("GL: DisplacedCuller::cull_occlusion: no Hi-Z pyramid (call set_hiz)");
        const GLuint prog = program(cone);
        if (bound_out) upload(bounds, count * ds::kDisplacedBoundValues * sizeof(float), nullptr);
        glUseProgram(prog);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingControlPoints, points);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingCullFlags, flags);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ds::kBindingDisplacementRanges, ranges);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ds::kBindingDisplacedBounds, bounds);
        // Bound for the frustum pass too (unread there): llvmpipe compiles a shader variant per
        // bound texture kind, so the same kind for both passes avoids compiling a program twice.
        glBindTextureUnit(sh::kTextureUnitHiZ, hiz ? hiz : placeholder_hiz);
        auto loc = [prog](const char* name) { return glGetUniformLocation(prog, name); };
        glUniform1ui(loc("u_patch_count"), static_cast<GLuint>(count));
        glUniform1i(loc("u_has_ranges"), has_ranges ? 1 : 0);
        glUniform1i(loc("u_write_bounds"), bound_out ? 1 : 0);
        glUniform1ui(loc("u_bound_kind"), static_cast<GLuint>(bound));
        glUniform1i(loc("u_occlusion"), occlusion ? 1 : 0);
        glUniform1i(loc("u_view_valid"), view.valid ? 1 : 0);
        glUniformMatrix4fv(loc("u_object_to_view"), 1, GL_FALSE, view.object_to_view.m);
        glUniform4fv(loc("u_abs_row_z"), 1, view.abs_row_z);
        glUniform3fv(loc("u_axis_unit"), 3, &view.axis_unit[0].x);
        glUniform1fv(loc("u_axis_length"), 3, view.axis_length);
        const Mat4& pr = view.projection;
        glUniform4f(loc("u_proj"), pr.at(0, 0), pr.at(0, 2), pr.at(1, 1), pr.at(1, 2));
        glUniform2f(loc("u_proj_z"), pr.at(2, 2), pr.at(2, 3));
        glUniform4fv(loc("u_view_planes"), 6, &view.view_planes.rows[0].x);
        glUniform1f(loc("u_delta_slack"), kDisplacedDeltaSlack);
        glUniform1f(loc("u_ext_scale"), kDisplacedExtScale);
        glUniform1f(loc("u_frame_pad"), kDisplacedFramePad);
        glUniform1f(loc("u_depth_safety"), kDisplacedDepthSafety);
        glUniform1f(loc("u_zero"), 0.0f);  // backpatch_cones.h's run-time zero
        glUniform2i(loc("u_screen"), hiz_width, hiz_height);
        glUniform1i(loc("u_hiz_levels"), hiz_levels);
        const GLint first_loc = loc("u_first_patch");
        const std::size_t per_dispatch = kMaxGroups * ds::kDisplacedGroupSize;
        for (std::size_t first = 0; first < count; first += per_dispatch) {
            const std::size_t n = std::min(per_dispatch, count - first);
            glUniform1ui(first_loc, static_cast<GLuint>(first));
            glDispatchCompute(static_cast<GLuint>((n + ds::kDisplacedGroupSize - 1) / ds::kDisplacedGroupSize), 1, 1);
        }
        glUseProgram(0);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        check_gl(occlusion ? "displaced occlusion pass" : "displaced frustum pass");
        if (bound_out) {
            glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
            std::vector<float> values(count * ds::kDisplacedBoundValues);
            if (count)
                glGetNamedBufferSubData(bounds, 0, static_cast<GLsizeiptr>(values.size() * sizeof(float)), values.data());
            check_gl("displaced bounds read-back");
            bound_out->resize(count);
            for (std::size_t p = 0; p < count; ++p) {
                const float* v = &values[p * ds::kDisplacedBoundValues];
                DisplacedBound& b = (*bound_out)[p];
                b.ndc_xmin = v[0];
                b.ndc_xmax = v[1];
                b.ndc_ymin = v[2];
                b.ndc_ymax = v[3];
                b.depth_near = v[4];
                b.depth_far = v[5];
                b.status = static_cast<std::uint8_t>(v[6]);
            }
        }
    }
};

DisplacedCuller::DisplacedCuller(const GlContext& ctx) : impl_(std::make_unique<Impl>()) {
    ctx.make_current();
    if (epoxy_gl_version() < 45)
        throw Error("GL: DisplacedCuller needs OpenGL 4.5 (context has " + ctx.version() + ")");
    // The fma mode is BackpatchCuller's decision (its start-up probe on GPUs; always double on
    // software rasterizers), so both cullers round the same way.
    impl_->fma_via_double = BackpatchCuller(ctx).fma_via_double();
    Impl& m = *impl_;
    GLuint buffers[4];
    glCreateBuffers(4, buffers);
    m.own_points = buffers[0];
    m.flags = buffers[1];
    m.ranges = buffers[2];
    m.bounds = buffers[3];
    upload(m.own_points, 0, nullptr);
    upload(m.ranges, 0, nullptr);
    upload(m.bounds, 0, nullptr);
    m.points = m.own_points;
    m.resize_flags(0);
    glCreateTextures(GL_TEXTURE_2D, 1, &m.placeholder_hiz);
    glTextureStorage2D(m.placeholder_hiz, 2, GL_R32F, 2, 2);
    glTextureParameteri(m.placeholder_hiz, GL_TEXTURE_MIN_FILTER, GL_NEAREST_MIPMAP_NEAREST);
    glTextureParameteri(m.placeholder_hiz, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    check_gl("DisplacedCuller setup");
}

DisplacedCuller::DisplacedCuller(DisplacedCuller&&) noexcept = default;
DisplacedCuller& DisplacedCuller::operator=(DisplacedCuller&&) noexcept = default;
DisplacedCuller::~DisplacedCuller() = default;

void DisplacedCuller::set_patches(const std::vector<BezierPatch>& patches, const std::vector<DisplacementRange>& ranges) {
    static_assert(sizeof(BezierPatch) == kPatchPoints * 4 * sizeof(float), "BezierPatch must be 16 packed float4");
    if (!ranges.empty() && ranges.size() != patches.size())
        throw Error("GL: DisplacedCuller::set_patches: " + std::to_string(ranges.size()) + " ranges for " +
                    std::to_string(patches.size()) + " patches");
    Impl& m = *impl_;
    upload(m.own_points, patches.size() * sizeof(BezierPatch), patches.empty() ? nullptr : &patches[0].cp[0].x);
    m.points = m.own_points;
    m.resize_flags(patches.size());
    m.upload_ranges(ranges.empty() ? nullptr : ranges.data(), ranges.size());
    check_gl("DisplacedCuller::set_patches");
}

void DisplacedCuller::set_patches(const PatchBatchView& patches, const DisplacementRange* ranges) {
    Impl& m = *impl_;
    detail::upload_patch_batch(m.own_points, patches);
    m.points = m.own_points;
    m.resize_flags(patches.count);
    m.upload_ranges(ranges, patches.count);
    check_gl("DisplacedCuller::set_patches");
}

void DisplacedCuller::use_patch_buffer(std::uint32_t buffer, std::size_t count) {
    Impl& m = *impl_;
    detail::check_patch_buffer("DisplacedCuller::use_patch_buffer", buffer, count);
    m.points = buffer;
    m.resize_flags(count);
    m.upload_ranges(nullptr, 0);
    check_gl("DisplacedCuller::use_patch_buffer");
}

void DisplacedCuller::set_ranges(const std::vector<DisplacementRange>& ranges) {
    Impl& m = *impl_;
    if (!ranges.empty() && ranges.size() != m.count)
        throw Error("GL: DisplacedCuller::set_ranges: " + std::to_string(ranges.size()) + " ranges for " +
                    std::to_string(m.count) + " patches");
    m.upload_ranges(ranges.empty() ? nullptr : ranges.data(), ranges.size());
    check_gl("DisplacedCuller::set_ranges");
}

std::size_t DisplacedCuller::patch_count() const { return impl_->count; }

void DisplacedCuller::set_hiz(const HiZPyramid& hiz) {
    Impl& m = *impl_;
    if (hiz.levels() < 1 || hiz.size() == 0) throw Error("GL: DisplacedCuller::set_hiz: the pyramid is not built");
    // The renderer's layout (occlusion_pipeline.cpp ensure_hiz): a power-of-two texture with
    // level_count mip levels, hiz.h's level l in the lower-left W_l x H_l texels of mip level l, the
    // rest 0 (never read: rectangles are clamped to the screen).
    glDeleteTextures(1, &m.hiz);
    m.hiz = 0;
    const int pot_w = static_cast<int>(std::bit_ceil(static_cast<unsigned>(hiz.level(0).width)));
    const int pot_h = static_cast<int>(std::bit_ceil(static_cast<unsigned>(hiz.level(0).height)));
    glCreateTextures(GL_TEXTURE_2D, 1, &m.hiz);
    glTextureStorage2D(m.hiz, hiz.levels(), GL_R32F, pot_w, pot_h);
    glTextureParameteri(m.hiz, GL_TEXTURE_MIN_FILTER, GL_NEAREST_MIPMAP_NEAREST);
    glTextureParameteri(m.hiz, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    const float zero = 0.0f;
    for (int l = 0; l < hiz.levels(); ++l) {
        const HiZLevel& lv = hiz.level(l);
        glClearTexImage(m.hiz, l, GL_RED, GL_FLOAT, &zero);
        glTextureSubImage2D(m.hiz, l, 0, 0, lv.width, lv.height, GL_RED, GL_FLOAT, hiz.data() + lv.offset);
    }
    m.hiz_width = hiz.depth_width();
    m.hiz_height = hiz.depth_height();
    m.hiz_levels = hiz.levels();
    check_gl("DisplacedCuller::set_hiz");
}

void DisplacedCuller::cull_frustum(DisplacedBoundKind bound, NormalConeKind cone, const DisplacedCullView& view,
                                   std::vector<std::uint8_t>* culled, std::vector<DisplacedBound>* bounds) {
    impl_->run(bound, cone, view, false, bounds);
    if (!culled) return;
    const std::vector<std::uint32_t> words = impl_->read_words();
    culled->resize(words.size());
    for (std::size_t p = 0; p < words.size(); ++p) (*culled)[p] = words[p] == kFlagFrustum ? 1 : 0;
}

void DisplacedCuller::cull_occlusion(DisplacedBoundKind bound, NormalConeKind cone, const DisplacedCullView& view,
                                     std::vector<std::uint8_t>* decisions, std::vector<DisplacedBound>* bounds) {
    impl_->run(bound, cone, view, true, bounds);
    if (!decisions) return;
    const std::vector<std::uint32_t> words = impl_->read_words();
    decisions->resize(words.size());
    for (std::size_t p = 0; p < words.size(); ++p)
        (*decisions)[p] = words[p] == kFlagFrustum     ? kHiZFrustumCulled
                          : words[p] == kFlagOcclusion ? kHiZOccluded
                                                       : kHiZVisible;
}

std::uint32_t DisplacedCuller::flag_buffer() const { return impl_->flags; }

std::vector<std::uint32_t> DisplacedCuller::read_flag_words() const { return impl_->read_words(); }

bool DisplacedCuller::fma_via_double() const { return impl_->fma_via_double; }

}  // namespace patchcull::gl
