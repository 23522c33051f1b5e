// Helpers shared by the OpenGL tests: one headless context per test process, the teapot split into
// small patches, and id-buffer summaries.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <set>
#include <utility>
#include <vector>

#include "patchcull/gl_passes.h"
#include "patchcull/gl_pipeline.h"
#include "patchcull/gl_renderer.h"
#include "patchcull/mesh.h"
#include "patchcull/patch.h"
#include "patchcull/teapot.h"

namespace patchcull::gl::test {

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

/// The teapot's 32 patches after `levels` 1-to-4 splits (32 * 4^levels patches).
inline std::vector<BezierPatch> split_teapot(int levels) {
    std::vector<BezierPatch> patches = teapot_patches();
    for (int l = 0; l < levels; ++l) {
        std::vector<BezierPatch> next(patches.size() * 4);
        for (std::size_t i = 0; i < patches.size(); ++i) split_patch(patches[i], &next[4 * i]);
        patches.swap(next);
    }
    return patches;
}

inline Bounds control_point_bounds(const std::vector<BezierPatch>& patches) {
    std::vector<Vec3> points;
    for (const BezierPatch& p : patches)
        for (const Vec4& c : p.cp) points.push_back(cartesian(c));
    return compute_bounds(points);
}

/// Distinct non-background ids in an id buffer.
inline std::set<std::uint32_t> ids_present(const std::vector<std::uint32_t>& ids) {
    std::set<std::uint32_t> s;
    for (std::uint32_t id : ids)
        if (id != 0) s.insert(id);
    return s;
}

}  // namespace patchcull::gl::test
