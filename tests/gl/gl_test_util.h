// Helpers shared by the OpenGL tests: one headless context per test process, the teapot split into
// small patches, and id-buffer summaries.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "patchcull/core/displacement.h"
#include "patchcull/core/mesh.h"
#include "patchcull/core/patch.h"
#include "patchcull/core/teapot.h"
#include "patchcull/gl/gl_passes.h"
#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/gl/gl_renderer.h"

#include "core/test_patches.h"

namespace patchcull::gl::test {

using test_patches::control_point_bounds;
using test_patches::split_teapot;

/// The process's context (created on first use, on the calling thread). Creation failing is a
/// test failure, not a skip: the supported platform (Debian 12) always has Mesa's llvmpipe.
inline GlContext& context() {
    static GlContext ctx = GlContext::create_headless();
    return ctx;
}

/// The process's pass context (on context()) and passes, for tests that run one pass on a
/// renderer's buffers.
inline PassContext& passes() {
    context().make_current();
    static PassContext p;
    return p;
}

/// A GL buffer of `bytes` bytes (zeroed), deleted at scope end.
class ScratchBuffer {
public:
    explicit ScratchBuffer(std::size_t bytes);
    ~ScratchBuffer();
    ScratchBuffer(const ScratchBuffer&) = delete;
    ScratchBuffer& operator=(const ScratchBuffer&) = delete;
    std::uint32_t name() const { return name_; }
    std::vector<float> read_floats(std::size_t count) const;

private:
    std::uint32_t name_ = 0;
};

/// The frustum pass on the renderer's whole set as a chain of its own: reasons cleared
/// (CullStatusPass::begin), then FrustumPass; plane_values (optional) receives the 6 maxima per
/// patch.
void cull_frustum(PatchRenderer& r, const FrustumPlanes& planes, std::vector<float>* plane_values = nullptr);

/// Attributes with only the cull margins set.
inline PatchAttributes margins_only(std::vector<float> max_displacement) {
    PatchAttributes a;
    a.max_displacement = std::move(max_displacement);
    return a;
}

/// Attributes for `count` displaced patches, each sampling its own random square window of MAP
/// (origin in [-0.5, 1.5)^2, side 0.05..0.35, drawn from SEED), with max_displacement = the
/// window's DisplacementRange bound: the margins a displaced frustum test must honour.
inline PatchAttributes random_texture_windows(std::size_t count, const DisplacementMap& map, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    PatchAttributes attributes;
    for (std::size_t p = 0; p < count; ++p) {
        const Vec2 o{2.0f * u01(rng) - 0.5f, 2.0f * u01(rng) - 0.5f};
        const float s = 0.05f + 0.3f * u01(rng);
        const std::array<Vec2, 4> uv = {o, o + Vec2{s, 0}, o + Vec2{0, s}, o + Vec2{s, s}};
        attributes.texcoords.push_back(uv);
        attributes.max_displacement.push_back(map.patch_range(uv.data()).max_abs());
    }
    return attributes;
}

/// Distinct non-background ids in an id buffer.
// A batch written through component(), as an engine's own memory would be: no weight check, for
// tests that feed the kernels patches which make_batch refuses (weights <= 0).
inline PatchBatch unchecked_batch(const std::vector<BezierPatch>& patches) {
    PatchBatch batch(patches.size());
    for (std::size_t p = 0; p < patches.size(); ++p)
        for (int k = 0; k < kPatchPoints; ++k) {
            batch.component(k, 0)[p] = patches[p].cp[k].x;
            batch.component(k, 1)[p] = patches[p].cp[k].y;
            batch.component(k, 2)[p] = patches[p].cp[k].z;
            batch.component(k, 3)[p] = patches[p].cp[k].w;
        }
    return batch;
}

inline std::set<std::uint32_t> ids_present(const std::vector<std::uint32_t>& ids) {
    std::set<std::uint32_t> s;
    for (std::uint32_t id : ids)
        if (id != 0) s.insert(id);
    return s;
}

}  // namespace patchcull::gl::test
