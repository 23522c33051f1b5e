// HiZBuildPass (patchcull/gl/gl_passes.h): Niessner & Loop §4.1's pyramid, shaders/hiz_build.comp.glsl,
// one dispatch per level, level 0 gathering from the depth texture.
#include "pass_common.h"

#include <cstdio>
#include <string>

namespace patchcull::gl {

struct HiZBuildPass::Impl : detail::PassState {
    using PassState::PassState;
    Impl(const Impl&) = delete;
    Impl& operator=(const Impl&) = delete;
    ~Impl() {
        if (clamp_sampler) glDeleteSamplers(1, &clamp_sampler);
    }
    // Level 0's sampler of the depth texture: nearest, clamp to edge (its textureGather).
    GLuint clamp_sampler = 0;
};

HiZBuildPass::HiZBuildPass(PassContext& context) : impl_(std::make_unique<Impl>(context.impl())) {}
HiZBuildPass::HiZBuildPass(HiZBuildPass&&) noexcept = default;
HiZBuildPass& HiZBuildPass::operator=(HiZBuildPass&&) noexcept = default;
HiZBuildPass::~HiZBuildPass() = default;

void HiZBuildPass::run(std::uint32_t depth_texture, const HiZTexture& hiz) {
    if (hiz.reversed) throw Error("GL: HiZBuildPass: the pyramid was built reversed; pass its convention to run()");
    HiZTexture forward = hiz;
    run(depth_texture, forward, ClipDepth::zero_to_one);
}

void HiZBuildPass::run(std::uint32_t depth_texture, HiZTexture& hiz, ClipDepth convention) {
    detail::begin_pass("HiZBuildPass");
    if (!glIsTexture(depth_texture))
        throw Error("GL: HiZBuildPass: " + std::to_string(depth_texture) + " is not a texture");
    if (!glIsTexture(hiz.texture) || hiz.width < 1 || hiz.height < 1)
        throw Error("GL: HiZBuildPass: no Hi-Z texture (create_hiz_texture)");
    GLint format = 0;
    glGetTextureLevelParameteriv(depth_texture, 0, GL_TEXTURE_INTERNAL_FORMAT, &format);
    bool unorm24 = false;
    switch (format) {
        case GL_DEPTH_COMPONENT32F:
        case GL_DEPTH32F_STENCIL8:
            break;
        case GL_DEPTH_COMPONENT24:
        case GL_DEPTH24_STENCIL8:
            unorm24 = true;
            break;
        default: {
            char hex[16];
            std::snprintf(hex, sizeof hex, "0x%04X", static_cast<unsigned>(format));
            throw Error(
                std::string("GL: HiZBuildPass: depth texture format ") + hex +
                " is not GL_DEPTH_COMPONENT32F, GL_DEPTH32F_STENCIL8, GL_DEPTH_COMPONENT24 or GL_DEPTH24_STENCIL8");
        }
    }
    hiz.reversed = is_reversed(convention);
    glBindTextureUnit(shared::kTextureUnitDepth, depth_texture);
    if (!impl_->clamp_sampler) {
        glCreateSamplers(1, &impl_->clamp_sampler);
        glSamplerParameteri(impl_->clamp_sampler, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glSamplerParameteri(impl_->clamp_sampler, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glSamplerParameteri(impl_->clamp_sampler, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glSamplerParameteri(impl_->clamp_sampler, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    glBindSampler(shared::kTextureUnitDepth, impl_->clamp_sampler);
    glBindTextureUnit(shared::kTextureUnitHiZ, hiz.texture);
    const int levels = HiZPyramid::level_count(hiz.width, hiz.height);
    pp::HiZBuildParams params;
    int source_w = hiz.width, source_h = hiz.height;
    for (int l = 0; l < levels; ++l) {
        const int out_w = (source_w + 1) / 2, out_h = (source_h + 1) / 2;
        params.from_depth = l == 0 ? 1u : 0u;
        params.source_level = l == 0 ? 0 : l - 1;
        params.source_width = source_w;
        params.source_height = source_h;
        params.out_width = out_w;
        params.out_height = out_h;
        params.reversed = hiz.reversed ? 1u : 0u;
        params.unorm24 = unorm24 ? 1u : 0u;
        // Level 0 gathers from the depth texture (a program per depth format and convention), the
        // others read the pyramid: llvmpipe computes every side of a branch, even on a uniform.
        if (l == 0)
            glUseProgram(impl_->context.program("hiz_build.comp.glsl",
                                                std::string("#define PC_HIZ_FROM_DEPTH 1\n#define PC_HIZ_UNORM24 ") +
                                                    (unorm24 ? "1" : "0") + "\n#define PC_HIZ_REVERSED " +
                                                    (hiz.reversed ? "1" : "0") + "\n"));
        if (l == 1) glUseProgram(impl_->context.program("hiz_build.comp.glsl", "#define PC_HIZ_FROM_DEPTH 0\n"));
        impl_->block.upload(params);
        glBindImageTexture(shared::kImageUnitHiZOut, hiz.texture, l, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
        glDispatchCompute((static_cast<GLuint>(out_w) + shared::kHiZGroupSize - 1) / shared::kHiZGroupSize,
                          (static_cast<GLuint>(out_h) + shared::kHiZGroupSize - 1) / shared::kHiZGroupSize, 1);
        // The next level reads this one.
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        source_w = out_w;
        source_h = out_h;
    }
    glBindSampler(shared::kTextureUnitDepth, 0);  // the caller's unit samples with its texture's state again
    detail::finish_pass("HiZBuildPass");
}

}  // namespace patchcull::gl
