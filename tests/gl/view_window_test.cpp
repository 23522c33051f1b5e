// The window context (GlContext::create_window, GLFW) and `patchcull view`: the same pipeline as
// the headless `render`, shown in a window. Runs the CLI under a virtual X server (xvfb-run,
// installed by scripts/install-deps.sh) and compares the window's screenshot after the last frame
// with `render --out` of the same scene, frames, size and tessellation: identical pixels (both
// llvmpipe here), and an image that is not empty. Without an X display, view is a one-line error.
#include <gtest/gtest.h>
#include <stb_image.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "cli/cli_test_util.h"

using namespace patchcull::cli_test;

namespace {

struct Rgb {
    int width = 0, height = 0;
    std::vector<unsigned char> rgb;  // top row first
};

Rgb load_rgb(const std::string& path) {
    Rgb image;
    int channels = 0;
    unsigned char* data = stbi_load(path.c_str(), &image.width, &image.height, &channels, 3);
    if (!data) return image;
    image.rgb.assign(data, data + static_cast<std::size_t>(image.width) * image.height * 3);
    stbi_image_free(data);
    return image;
}

const char* const kXvfb = "xvfb-run -a -s '-screen 0 1280x1024x24'";

}  // namespace

TEST(ViewWindow, ScreenshotEqualsTheHeadlessRender) {
    ASSERT_EQ(std::system("command -v xvfb-run >/dev/null 2>&1"), 0)
        << "xvfb-run is missing: scripts/install-deps.sh installs xvfb";
    const std::string args = "teapot --split 1 --frames 2 --size 96x64 --tess 4 --cull all";
    const std::string shot = scratch_dir() + "/view.png", rendered = scratch_dir() + "/render.png";
    std::filesystem::remove(shot);
    std::filesystem::remove(rendered);
    const CliRun v = run("view " + args + " --screenshot " + shot, kXvfb);
    ASSERT_EQ(v.status, 0) << v.err;
    EXPECT_NE(v.out.find("frame 1:"), std::string::npos) << v.out;
    const CliRun r = run("render " + args + " --out " + rendered + " --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const Rgb a = load_rgb(shot), b = load_rgb(rendered);
    ASSERT_EQ(a.width, 96);
    ASSERT_EQ(a.height, 64);
    ASSERT_EQ(b.width, 96);
    ASSERT_EQ(b.height, 64);
    std::size_t differ = 0, unlike_corner = 0;
    for (std::size_t i = 0; i < a.rgb.size(); i += 3) {
        differ += a.rgb[i] != b.rgb[i] || a.rgb[i + 1] != b.rgb[i + 1] || a.rgb[i + 2] != b.rgb[i + 2];
        unlike_corner += a.rgb[i] != a.rgb[0] || a.rgb[i + 1] != a.rgb[1] || a.rgb[i + 2] != a.rgb[2];
    }
    EXPECT_EQ(differ, 0u) << "the window shows another image than the headless render";
    EXPECT_GT(unlike_corner, a.rgb.size() / 3 / 20) << "the window shows (almost) nothing";
}

TEST(ViewWindow, NoDisplayIsAOneLineError) {
    expect_one_line_error(run("view teapot --frames 1 --size 32x32", "env -u DISPLAY -u WAYLAND_DISPLAY"), "GLFW");
}

TEST(ViewWindow, ScreenshotNeedsAFrameCount) {
    expect_one_line_error(run("view teapot --screenshot x.png"), "--screenshot");
}
