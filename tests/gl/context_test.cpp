// GlContext: the headless context comes up on this machine (Mesa llvmpipe through EGL, or a GPU
// through an EGL device) with OpenGL 4.5 core, and the renderer's embedded shaders compile.
#include <gtest/gtest.h>

#include "gl_test_util.h"

using namespace patchcull::gl;

TEST(GlContext, HeadlessContextIsOpenGL45Core) {
    GlContext& ctx = test::context();
    EXPECT_FALSE(ctx.renderer().empty());
    EXPECT_NE(ctx.version().find("4.5"), std::string::npos) << ctx.version();  // "4.5 (Core Profile) Mesa ..."
    EXPECT_TRUE(ctx.platform() == "device" || ctx.platform() == "surfaceless" || ctx.platform() == "software-device")
        << ctx.platform();
    // A software renderer is never picked over a GPU device.
    if (ctx.platform() == "device") {
        EXPECT_FALSE(ctx.is_software()) << ctx.renderer();
    }
    RecordProperty("renderer", ctx.renderer());
    RecordProperty("platform", ctx.platform());
}

TEST(GlContext, EmbeddedShadersCompileAndLink) {
    PatchRenderer renderer(test::context());
    EXPECT_EQ(renderer.patch_count(), 0u);
    // An empty scene renders the background.
    RenderParams params;
    params.width = 16;
    params.height = 8;
    renderer.render(params);
    const auto ids = renderer.read_ids();
    ASSERT_EQ(ids.size(), 16u * 8u);
    for (auto id : ids) EXPECT_EQ(id, 0u);
    for (float d : renderer.read_depth()) EXPECT_EQ(d, 1.0f);
}

TEST(GlContext, SecondContextInSameProcess) {
    // Contexts share the EGL display; destroying one must leave the other usable.
    GlContext& first = test::context();
    {
        GlContext second = GlContext::create_headless();
        PatchRenderer r(second);
        r.render(RenderParams{});
    }
    first.make_current();
    PatchRenderer r(first);
    r.render(RenderParams{});
    EXPECT_EQ(r.read_ids().size(), 256u * 256u);
}
