// ACC tangent-patch shading normals in the renderer (gl_renderer.h, PatchAttributes::tangents):
// extraordinary patches shade with du x dv of their tangent patches, regular ones and the
// geometry (ids, depth, hence every cull decision) do not change.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "gl_test_util.h"
#include "patchcull/core/camera.h"
#include "patchcull/import/model_loader.h"

using namespace patchcull;
using namespace patchcull::gl;

namespace {

struct Frame {
    std::vector<std::uint8_t> color;
    std::vector<std::uint32_t> ids;
    std::vector<float> depth;
};

Frame render_with(PatchRenderer& r, const std::vector<BezierPatch>& patches, const PatchAttributes& attributes,
                  const RenderParams& params) {
    r.set_patches(patches, attributes);
    r.render(params);
    return {r.read_color(), r.read_ids(), r.read_depth()};
}

}  // namespace

TEST(TangentShading, ExtraordinaryPatchesShadeWithTheirTangentPatchesGeometryUnchanged) {
    const LoadedModel m = load_model(shipped_model_path("bigguy.obj"), Scheme::acc, 0);
    ASSERT_FALSE(m.rest.tangents.empty());
    PatchAttributes with_tangents;
    for (const PatchInfo& info : m.rest.info) with_tangents.tangent_index.push_back(info.tangent_index);
    with_tangents.tangents = m.rest.tangents;

    PatchRenderer r(test::context());
    ViewGenerator views(patch_bounds(m.rest), ViewMode::contain, 3);
    const Camera camera = views.next();
    RenderParams params;
    params.view = camera.view();
    params.projection = camera.projection();
    params.width = params.height = 96;
    params.tess_level = 4;
    params.use_cull_flags = false;
    const Frame plain = render_with(r, m.rest.patches, {}, params);
    const Frame shaded = render_with(r, m.rest.patches, with_tangents, params);
    EXPECT_EQ(plain.ids, shaded.ids);
    EXPECT_EQ(plain.depth, shaded.depth);
    std::size_t regular_differ = 0, extraordinary_differ = 0, extraordinary_pixels = 0;
    for (std::size_t i = 0; i < plain.ids.size(); ++i) {
        const std::uint32_t id = plain.ids[i];
        if (id == 0) continue;
        bool differ = false;
        for (int c = 0; c < 3; ++c) differ = differ || plain.color[4 * i + c] != shaded.color[4 * i + c];
        if (m.rest.info[id - 1].tangent_index >= 0) {
            ++extraordinary_pixels;
            extraordinary_differ += differ;
        } else {
            regular_differ += differ;
        }
    }
    EXPECT_EQ(regular_differ, 0u);
    ASSERT_GT(extraordinary_pixels, 0u) << "the view shows no extraordinary patch: the test would check nothing";
    EXPECT_GT(extraordinary_differ, 0u) << "tangent patches did not change the shading";
}

TEST(TangentShading, BadTangentIndexThrows) {
    PatchRenderer r(test::context());
    std::vector<BezierPatch> patches(2);
    PatchAttributes a;
    a.tangent_index = {0, 1};
    a.tangents.resize(1);
    EXPECT_THROW(r.set_patches(patches, a), patchcull::Error);
    a.tangent_index = {0};
    EXPECT_THROW(r.set_patches(patches, a), patchcull::Error);
}
