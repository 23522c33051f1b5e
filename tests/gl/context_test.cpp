// GlContext: the headless context comes up on this machine (Mesa llvmpipe through EGL, or a GPU
// through an EGL device) with OpenGL 4.5 core, the renderer's embedded shaders compile, and the
// driver's threads are placed as asked.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>
#include <vector>

#include "core/driver_thread_checks.h"
#include "gl_test_util.h"
#include "patchcull/core/thread_placement.h"

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

namespace {

// True when llvmpipe's threads run in this process already (a context was made before).
bool llvmpipe_threads_running() {
    for (int id : patchcull::process_thread_ids()) {
        std::ifstream comm("/proc/self/task/" + std::to_string(id) + "/comm");
        std::string name;
        if (std::getline(comm, name) && name.rfind("llvmpipe", 0) == 0) return true;
    }
    return false;
}

}  // namespace

// DriverThreads: on llvmpipe the threads the driver starts with the process's first context (its
// screen's: a second context on the same display starts none) are pinned one CPU each (spread,
// the default), or left alone (os); the calling thread keeps its CPUs either way. Each context is
// the only one while it lives, so each starts the driver anew.
TEST(GlContext, SpreadsTheDriversThreadsOnASoftwareRasterizer) {
    if (llvmpipe_threads_running()) GTEST_SKIP() << "a context was made before in this process: run this test alone";
    const int me = static_cast<int>(gettid());
    const int cpus = patchcull::thread_cpu_count(me);
    for (DriverThreads mode : {DriverThreads::spread, DriverThreads::os}) {
        const std::vector<int> before = patchcull::process_thread_ids();
        GlContext c = GlContext::create_headless(mode);
        if (!c.is_software()) {
            EXPECT_EQ(c.pinned_driver_threads(), 0u) << "a GPU: its driver's threads are left alone";
            continue;
        }
        const std::vector<int> started = patchcull::threads_started(before, patchcull::process_thread_ids());
        const bool spread = mode == DriverThreads::spread && cpus >= 2;
        patchcull::placement_test::expect_driver_threads_placed(started, c.pinned_driver_threads(), spread, cpus);
        EXPECT_EQ(patchcull::thread_cpu_count(me), cpus);
        PatchRenderer r(c);  // a pinned context still renders
        r.render(RenderParams{});
        EXPECT_EQ(r.read_ids().size(), 256u * 256u);
    }
}
