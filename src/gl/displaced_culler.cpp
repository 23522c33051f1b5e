// DisplacedCuller (patchcull/gl/gl_displaced.h): GPU frustum and Hi-Z occlusion culling of displaced
// patches with the bounds of Niessner & Loop §4.2 ("Patch-Based Occlusion Culling for
// Hardware Tessellation": the camera-aligned frustum, CAF, with the Full / ACoN / CoN displacement
// extensions) and Munkberg et al.'s object-oriented box (OOBB), the GPU twin of
// src/core/displaced_bounds.cpp (include/patchcull/core/displaced_bounds.h defines every step).
// DisplacedPass (gl_passes.h) over buffers and a Hi-Z texture that the culler owns, with read-backs.
#include <epoxy/gl.h>

#include <algorithm>
#include <bit>
#include <string>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/gl/gl_backpatch.h"
#include "patchcull/gl/gl_displaced.h"
#include "patchcull/gl/gl_passes.h"
#include "renderer_internal.h"
#include "shader_sources.h"
#include "shared.h"

namespace patchcull::gl {

namespace {

using detail::check_gl;
using detail::upload;

}  // namespace

struct DisplacedCuller::Impl {
    PassContext passes;
    DisplacedPass pass{passes};
    GLuint own_points = 0, flags = 0, ranges = 0, bounds = 0;
    GLuint points = 0;  // own_points or the caller's buffer
    HiZTexture hiz;     // set_hiz's upload (texture 0 before)
    std::size_t count = 0;
    bool has_ranges = false;

    ~Impl() {
        const GLuint buffers[] = {own_points, flags, ranges, bounds};
        glDeleteBuffers(4, buffers);
        glDeleteTextures(1, &hiz.texture);
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
        if (occlusion && !hiz.texture)
            throw Error("GL: DisplacedCuller::cull_occlusion: no Hi-Z pyramid (call set_hiz)");
        glClearNamedBufferData(flags, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
        if (bound_out) upload(bounds, count * shared::kDisplacedBoundValues * sizeof(float), nullptr);
        pass.run({points, flags, 0, 0, count}, has_ranges ? ranges : 0, bound, cone, view, occlusion ? &hiz : nullptr,
                 false, bound_out ? bounds : 0);
        if (!bound_out) return;
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        std::vector<float> values(count * shared::kDisplacedBoundValues);
        if (count)
            glGetNamedBufferSubData(bounds, 0, static_cast<GLsizeiptr>(values.size() * sizeof(float)), values.data());
        check_gl("displaced bounds read-back");
        bound_out->resize(count);
        for (std::size_t p = 0; p < count; ++p) {
            const float* v = &values[p * shared::kDisplacedBoundValues];
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
};

DisplacedCuller::DisplacedCuller(const GlContext& ctx) : impl_((ctx.make_current(), std::make_unique<Impl>())) {
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
    check_gl("DisplacedCuller setup");
}

DisplacedCuller::DisplacedCuller(DisplacedCuller&&) noexcept = default;
DisplacedCuller& DisplacedCuller::operator=(DisplacedCuller&&) noexcept = default;
DisplacedCuller::~DisplacedCuller() = default;

void DisplacedCuller::set_patches(const std::vector<BezierPatch>& patches,
                                  const std::vector<DisplacementRange>& ranges) {
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
    // create_hiz_texture's layout (gl_passes.h): hiz.h's level l in the lower-left W_l x H_l
    // texels of mip level l, the rest 0 (never read: rectangles are clamped to the screen).
    glDeleteTextures(1, &m.hiz.texture);
    m.hiz = create_hiz_texture(hiz.depth_width(), hiz.depth_height());
    for (int l = 0; l < hiz.levels(); ++l) {
        const HiZLevel& lv = hiz.level(l);
        glTextureSubImage2D(m.hiz.texture, l, 0, 0, lv.width, lv.height, GL_RED, GL_FLOAT, hiz.data() + lv.offset);
    }
    check_gl("DisplacedCuller::set_hiz");
}

void DisplacedCuller::cull_frustum(DisplacedBoundKind bound, NormalConeKind cone, const DisplacedCullView& view,
                                   std::vector<std::uint8_t>* culled, std::vector<DisplacedBound>* bounds) {
    impl_->run(bound, cone, view, false, bounds);
    if (!culled) return;
    const std::vector<std::uint32_t> words = impl_->read_words();
    culled->resize(words.size());
    for (std::size_t p = 0; p < words.size(); ++p) (*culled)[p] = words[p] == kCullFrustum ? 1 : 0;
}

void DisplacedCuller::cull_occlusion(DisplacedBoundKind bound, NormalConeKind cone, const DisplacedCullView& view,
                                     std::vector<std::uint8_t>* decisions, std::vector<DisplacedBound>* bounds) {
    impl_->run(bound, cone, view, true, bounds);
    if (!decisions) return;
    const std::vector<std::uint32_t> words = impl_->read_words();
    decisions->resize(words.size());
    for (std::size_t p = 0; p < words.size(); ++p)
        (*decisions)[p] = words[p] == kCullFrustum     ? kHiZFrustumCulled
                          : words[p] == kCullOcclusion ? kHiZOccluded
                                                       : kHiZVisible;
}

std::uint32_t DisplacedCuller::flag_buffer() const { return impl_->flags; }

std::vector<std::uint32_t> DisplacedCuller::read_flag_words() const { return impl_->read_words(); }

bool DisplacedCuller::fma_via_double() const { return impl_->passes.fma_via_double(); }

}  // namespace patchcull::gl
