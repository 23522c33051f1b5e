// `render --dump-hiz DIR` and `render --draw-bounds P[,P...]` (tools/render_dumps.h; Niessner &
// Loop, "Patch-Based Occlusion Culling for Hardware Tessellation", Figs. 3 and 6): the pyramid's
// files, sizes and max reduction read back from the raw dumps; the CAF and OOBB rectangles of
// every displaced patch containing all of that patch's pixels in the id buffer of the same frame
// (the conservative promise of the bounds); one-line errors. Tiny sizes on llvmpipe.
#include <gtest/gtest.h>

#include <stb_image.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"

using namespace patchcull::cli_test;

namespace {

template <typename T>
std::vector<T> read_raw(const std::string& path) {
    const std::string bytes = slurp(path);
    std::vector<T> out(bytes.size() / sizeof(T));
    std::copy_n(bytes.data(), out.size() * sizeof(T), reinterpret_cast<char*>(out.data()));
    EXPECT_EQ(bytes.size(), out.size() * sizeof(T)) << path;
    return out;
}

// Width, height and channels of a PNG (0s when it does not decode).
struct PngInfo {
    int width = 0, height = 0, channels = 0;
    std::vector<unsigned char> pixels;  // as stored, top row first
};
PngInfo load_png(const std::string& path) {
    PngInfo info;
    unsigned char* data = stbi_load(path.c_str(), &info.width, &info.height, &info.channels, 0);
    if (data) {
        info.pixels.assign(data, data + std::size_t(info.width) * info.height * info.channels);
        stbi_image_free(data);
    }
    return info;
}

}  // namespace

TEST(RenderDump, HiZLevelsHaveThePyramidsSizesAndMaxReduction) {
    const std::string dir = scratch_dir() + "/hiz";
    std::filesystem::remove_all(dir);
    // 70x45: odd sizes, so every level rounds up (ceil) somewhere.
    const int W = 70, H = 45;
    const CliRun r =
        run("render teapot --split 2 --size 70x45 --tess 4 --frames 2 --cull all --dump-hiz " + dir + " --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(slurp(dir + "/hiz.json"));
    EXPECT_EQ(nlohmann::json::parse(r.out)["hiz_dump"], j);
    ASSERT_EQ(j["size"], nlohmann::json({W, H}));
    // The pyramid's sizes (hiz.h): level 0 = ceil(W/2) x ceil(H/2), each next ceil(previous/2), down
    // to 1x1.
    std::vector<std::pair<int, int>> sizes;
    for (int w = (W + 1) / 2, h = (H + 1) / 2;; w = (w + 1) / 2, h = (h + 1) / 2) {
        sizes.push_back({w, h});
        if (w == 1 && h == 1) break;
    }
    ASSERT_EQ(j["levels"].size(), sizes.size());
    const std::vector<float> depth = read_raw<float>(dir + "/depth.f32");
    ASSERT_EQ(depth.size(), std::size_t(W) * H);
    std::vector<std::vector<float>> level(sizes.size());
    bool some_drawn = false;
    for (std::size_t l = 0; l < sizes.size(); ++l) {
        const auto& e = j["levels"][l];
        const int w = sizes[l].first, h = sizes[l].second;
        ASSERT_EQ(e["width"], w) << l;
        ASSERT_EQ(e["height"], h) << l;
        const PngInfo png = load_png(dir + "/" + e["png"].get<std::string>());
        ASSERT_EQ(png.width, w) << l;
        ASSERT_EQ(png.height, h) << l;
        ASSERT_EQ(png.channels, 1) << l;
        level[l] = read_raw<float>(dir + "/" + e["raw"].get<std::string>());
        ASSERT_EQ(level[l].size(), std::size_t(w) * h) << l;
        // The grey mapping the help states: 255 for depth 1, else 254 (d - lo) / (hi - lo) rounded.
        const float lo = e["lo"], hi = e["hi"];
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const float d = level[l][std::size_t(y) * w + x];
                some_drawn = some_drawn || d < 1;
                const int grey = png.pixels[std::size_t(h - 1 - y) * w + x];
                const int want = d >= 1    ? 255
                                 : hi > lo ? int(std::lround(254.0 * (double(d) - lo) / (double(hi) - lo)))
                                           : 0;
                ASSERT_EQ(grey, want) << "level " << l << " texel " << x << "," << y;
            }
    }
    EXPECT_TRUE(some_drawn);
    // Level 0 against the final depth: each texel >= every depth pixel it covers (it holds pass 1's
    // depth; pass 2 only draws nearer).
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            ASSERT_GE(level[0][std::size_t(y / 2) * sizes[0].first + x / 2], depth[std::size_t(y) * W + x])
                << "pixel " << x << "," << y;
    // Level l = max of the (existing) 2x2 texels of level l-1, exactly.
    for (std::size_t l = 1; l < sizes.size(); ++l) {
        const int w = sizes[l].first, h = sizes[l].second, cw = sizes[l - 1].first, ch = sizes[l - 1].second;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                float m = -1;
                for (int dy = 0; dy < 2; ++dy)
                    for (int dx = 0; dx < 2; ++dx)
                        if (2 * x + dx < cw && 2 * y + dy < ch)
                            m = std::max(m, level[l - 1][std::size_t(2 * y + dy) * cw + 2 * x + dx]);
                ASSERT_EQ(level[l][std::size_t(y) * w + x], m) << "level " << l << " texel " << x << "," << y;
            }
    }
}

TEST(RenderDump, CafAndOobbRectanglesHoldEveryPixelOfTheirPatch) {
    // Every patch of a displaced teapot (512 patches, procedural map) at once: with occlusion, so
    // --dump-hiz gives the id buffer of the same frame.
    const std::string dir = scratch_dir() + "/bounds", png = scratch_dir() + "/bounds.png";
    std::filesystem::remove_all(dir);
    std::string all;
    for (int p = 0; p < 512; ++p) {
        if (p) all += ',';
        all += std::to_string(p);
    }
    const int W = 96, H = 64;
    const CliRun r =
        run("render teapot --split 2 --size 96x64 --tess 6 --frames 1 --cull occlusion --displace procedural "
            "--displace-scale 0.05 --cone acon --dump-hiz " +
            dir + " --draw-bounds " + all + " --out " + png + " --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j["patches"], 512);
    ASSERT_EQ(j["displaced_patches"], 512);
    const std::vector<std::uint32_t> ids = read_raw<std::uint32_t>(dir + "/ids.u32");
    ASSERT_EQ(ids.size(), std::size_t(W) * H);
    ASSERT_EQ(j["draw_bounds"].size(), 512u);
    std::size_t checked = 0, pixels_checked = 0, caf_smaller = 0;
    for (const auto& b : j["draw_bounds"]) {
        const std::uint32_t id = b["patch"].get<std::uint32_t>() + 1;
        std::size_t pixels = 0;
        for (std::uint32_t v : ids) pixels += v == id;
        ASSERT_EQ(b["pixels"], pixels);
        if (pixels == 0) continue;
        for (const char* kind : {"caf", "oobb"}) {
            // A visible patch's bound is never outside a plane; not projectable is allowed (never
            // occluded then), but not at this distance from the camera.
            ASSERT_EQ(b[kind]["status"], "projected") << b.dump();
            const auto rect = b[kind]["rect"];
            const int x0 = rect[0], y0 = rect[1], x1 = rect[2], y1 = rect[3];
            for (int y = 0; y < H; ++y)
                for (int x = 0; x < W; ++x)
                    if (ids[std::size_t(y) * W + x] == id) {
                        ASSERT_TRUE(x >= x0 && x <= x1 && y >= y0 && y <= y1)
                            << kind << " of patch " << id - 1 << " misses pixel " << x << "," << y << ": " << b.dump();
                    }
            // Not vacuous: the rectangle is a small part of the screen.
            EXPECT_LT((x1 - x0 + 1) * (y1 - y0 + 1), W * H / 4) << b.dump();
        }
        const auto c = b["caf"]["rect"], o = b["oobb"]["rect"];
        caf_smaller +=
            (int(c[2]) - int(c[0])) * (int(c[3]) - int(c[1])) < (int(o[2]) - int(o[0])) * (int(o[3]) - int(o[1]));
        ++checked;
        pixels_checked += pixels;
    }
    EXPECT_GT(checked, 50u);  // the teapot fills a good part of the 96x64 frame
    EXPECT_GT(pixels_checked, 300u);
    (void)caf_smaller;  // reported by the docs' figure, not a promise
    // The picture: the frame's size, with the CAF's green outline drawn.
    const PngInfo picture = load_png(png);
    ASSERT_EQ(picture.width, W);
    ASSERT_EQ(picture.height, H);
    std::size_t green = 0;
    for (std::size_t i = 0; i + 3 < picture.pixels.size(); i += std::size_t(picture.channels))
        green += picture.pixels[i] == 20 && picture.pixels[i + 1] == 200 && picture.pixels[i + 2] == 40;
    EXPECT_GT(green, 100u);
}

TEST(RenderDump, BadArgumentsAreOneLineNamingTheFlag) {
    const std::string file = write_file("not_a_dir", "x");
    expect_one_line_error(run("render teapot --size 32x32 --frames 1 --dump-hiz " + file + "/sub"), "--dump-hiz");
    expect_one_line_error(
        run("render teapot --size 32x32 --frames 1 --cull frustum --dump-hiz " + scratch_dir() + "/d"), "--dump-hiz");
    const std::string out = " --out " + scratch_dir() + "/b.png";
    expect_one_line_error(run("render teapot --size 32x32 --frames 1 --draw-bounds 32" + out), "--draw-bounds");
    expect_one_line_error(run("render teapot --size 32x32 --frames 1 --draw-bounds 1,,2" + out), "--draw-bounds");
    expect_one_line_error(run("render teapot --size 32x32 --frames 1 --draw-bounds -1" + out), "--draw-bounds");
    expect_one_line_error(run("render teapot --size 32x32 --frames 1 --draw-bounds 3"), "--draw-bounds");
}
