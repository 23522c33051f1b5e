// --dump-hiz and --draw-bounds of `patchcull render` (render_dumps.h).
#include "render_dumps.h"

#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "patchcull/core/clip_space.h"
#include "patchcull/core/error.h"

namespace patchcull::cli {
namespace {

template <typename T>
void write_raw(const std::string& path, const std::vector<T>& values) {
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (!file) throw Error(path + ": cannot write: cannot open the file");
    const bool written = std::fwrite(values.data(), sizeof(T), values.size(), file) == values.size();
    const bool closed = std::fclose(file) == 0;
    if (!written || !closed) throw Error(path + ": cannot write: write failed (disk full?)");
}

template <typename T>
std::vector<T> bottom_first(const std::vector<T>& top_first, int width, int height) {
    std::vector<T> out(top_first.size());
    for (int y = 0; y < height; ++y)
        std::copy_n(&top_first[static_cast<std::size_t>(height - 1 - y) * width], width,
                    &out[static_cast<std::size_t>(y) * width]);
    return out;
}

std::string level_name(int level, const char* extension) {
    char name[32];
    std::snprintf(name, sizeof name, "hiz_level_%02d.%s", level, extension);
    return name;
}

const char* status_name(std::uint8_t status) {
    switch (status) {
        case kDisplacedBoundProjected:
            return "projected";
        case kDisplacedBoundOutsidePlane:
            return "outside-plane";
        case kDisplacedBoundUnprojectable:
            return "unprojectable";
        default:
            return "invalid";
    }
}

nlohmann::json screen_bound_json(const ScreenBound& s) {
    nlohmann::json j = {{"status", status_name(s.bound.status)}};
    if (s.projected) {
        j["ndc"] = {s.bound.ndc_xmin, s.bound.ndc_xmax, s.bound.ndc_ymin, s.bound.ndc_ymax};
        j["rect"] = {s.rect.x0, s.rect.y0, s.rect.x1, s.rect.y1};
        j["depth_near"] = s.bound.depth_near;
        j["depth_far"] = s.bound.depth_far;
    }
    return j;
}

}  // namespace

void write_png_checked(const std::string& path, int width, int height, int channels,
                       const std::vector<std::uint8_t>& top_first) {
    // Encoded in memory, then written with every step checked: stbi_write_png alone ignores a
    // failed write (a truncated file and success).
    std::vector<unsigned char> bytes;
    auto append = [](void* context, void* data, int size) {
        auto* out = static_cast<std::vector<unsigned char>*>(context);
        out->insert(out->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
    };
    if (!stbi_write_png_to_func(append, &bytes, width, height, channels, top_first.data(), width * channels))
        throw Error(path + ": cannot write PNG: encoding failed");
    write_raw(path, bytes);
}

nlohmann::json dump_hiz(const gl::CullPipeline& pipeline, const std::string& dir) {
    if (pipeline.hiz_levels() == 0)
        throw Error("--dump-hiz: the last frame built no Hi-Z pyramid (it needs --cull occlusion, all or auto)");
    const gl::PatchRenderer& renderer = pipeline.renderer();
    const int width = renderer.width(), height = renderer.height();
    const std::vector<float> texels = pipeline.read_hiz();
    const HiZPyramid layout(width, height);  // level sizes and offsets of read_hiz's layout
    const std::filesystem::path base(dir);
    nlohmann::json levels = nlohmann::json::array();
    for (int l = 0; l < layout.levels(); ++l) {
        const HiZLevel& level = layout.level(l);
        const std::size_t n = static_cast<std::size_t>(level.width) * level.height;
        std::vector<float> values(texels.begin() + level.offset, texels.begin() + level.offset + n);
        float lo = 1, hi = 0;
        for (float d : values) {
            lo = std::min(lo, d);
            if (d < 1) hi = std::max(hi, d);
        }
        if (hi < lo) hi = lo;  // nothing below 1
        std::vector<std::uint8_t> grey(n);
        for (int y = 0; y < level.height; ++y)
            for (int x = 0; x < level.width; ++x) {
                const float d = values[static_cast<std::size_t>(y) * level.width + x];
                const double t = hi > lo ? (double(d) - lo) / (double(hi) - lo) : 0.0;
                const std::uint8_t g =
                    d >= 1 ? 255 : static_cast<std::uint8_t>(std::lround(254 * std::clamp(t, 0.0, 1.0)));
                grey[static_cast<std::size_t>(level.height - 1 - y) * level.width + x] = g;  // PNG: top row first
            }
        const std::string png = level_name(l, "png"), raw = level_name(l, "f32");
        write_png_checked((base / png).string(), level.width, level.height, 1, grey);
        write_raw((base / raw).string(), values);
        levels.push_back({{"level", l},
                          {"width", level.width},
                          {"height", level.height},
                          {"png", png},
                          {"raw", raw},
                          {"lo", lo},
                          {"hi", hi}});
    }
    // The renderer's read-backs are top row first; the dumps are row 0 = bottom, as the pyramid.
    write_raw((base / "depth.f32").string(), bottom_first(renderer.read_depth(), width, height));
    write_raw((base / "ids.u32").string(), bottom_first(renderer.read_ids(), width, height));
    nlohmann::json out = {{"size", {width, height}},
                          {"levels", levels},
                          {"depth", "depth.f32"},
                          {"ids", "ids.u32"},
                          {"mapping",
                           "grey = 255 where depth is 1 (far), else round(254 (d - lo) / (hi - lo)), lo/hi the level's "
                           "smallest depth and largest depth below 1"}};
    const std::string json_path = (base / "hiz.json").string();
    const std::string text = out.dump(1) + "\n";
    write_raw(json_path, std::vector<char>(text.begin(), text.end()));
    return out;
}

std::vector<std::size_t> parse_patch_list(const std::string& text, std::size_t patch_count) {
    std::vector<std::size_t> out;
    std::size_t start = 0;
    while (true) {
        const std::size_t comma = text.find(',', start);
        const std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        std::size_t used = 0;
        unsigned long long value = 0;
        bool ok = !item.empty() && item.find_first_not_of("0123456789") == std::string::npos && item.size() <= 18;
        if (ok) value = std::stoull(item, &used);
        if (!ok || used != item.size())
            throw Error("--draw-bounds: '" + item.substr(0, 40) + "' is not a patch index (expected P[,P...])");
        if (value >= patch_count)
            throw Error("--draw-bounds: patch " + item + " is not in the scene (" + std::to_string(patch_count) +
                        " patches: 0.." + std::to_string(patch_count ? patch_count - 1 : 0) + ")");
        out.push_back(static_cast<std::size_t>(value));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return out;
}

ScreenBound screen_bound(const BezierPatch& patch, DisplacementRange range, DisplacedBoundKind kind,
                         NormalConeKind cone, const gl::RenderParams& frame) {
    // The view the pipeline's DisplacedPass gets (cull_pipeline.cpp): world-space patches, the
    // frame's view and projection in its depth convention.
    const DisplacedCullView view = make_displaced_cull_view(frame.view, frame.projection, frame.depth);
    ScreenBound s;
    s.bound = compute_displaced_bound(patch, range, kind, cone, view);
    s.projected = s.bound.status == kDisplacedBoundProjected;
    if (s.projected) {
        // displaced_bounds.h's occlusion test: window box, then hiz.h step 6.
        const float hw = 0.5f * float(frame.width), hh = 0.5f * float(frame.height);
        s.rect = hiz_rect_from_window_box(std::fma(s.bound.ndc_xmin, hw, hw), std::fma(s.bound.ndc_xmax, hw, hw),
                                          std::fma(s.bound.ndc_ymin, hh, hh), std::fma(s.bound.ndc_ymax, hh, hh),
                                          frame.width, frame.height);
    }
    return s;
}

nlohmann::json patch_bounds_json(const PatchBounds& b, const std::vector<std::uint32_t>& ids) {
    const std::size_t pixels =
        static_cast<std::size_t>(std::count(ids.begin(), ids.end(), static_cast<std::uint32_t>(b.patch + 1)));
    return {{"patch", b.patch},
            {"range", {b.range.d_min, b.range.d_max}},
            {"pixels", pixels},
            {"caf", screen_bound_json(b.caf)},
            {"oobb", screen_bound_json(b.oobb)}};
}

void write_bounds_png(const std::string& path, std::vector<std::uint8_t> rgba, const std::vector<std::uint32_t>& ids,
                      int width, int height, const std::vector<PatchBounds>& bounds) {
    // rgba and ids are top row first (the renderer's read-backs), rectangles row 0 = bottom.
    auto pixel = [&](int x, int y) { return &rgba[(static_cast<std::size_t>(height - 1 - y) * width + x) * 4]; };
    for (const PatchBounds& b : bounds)
        for (std::size_t i = 0; i < ids.size(); ++i)
            if (ids[i] == b.patch + 1) {
                std::uint8_t* p = &rgba[i * 4];  // half-way to yellow
                p[0] = static_cast<std::uint8_t>((p[0] + 255) / 2);
                p[1] = static_cast<std::uint8_t>((p[1] + 230) / 2);
                p[2] = static_cast<std::uint8_t>(p[2] / 2);
            }
    auto outline = [&](const ScreenBound& s, std::uint8_t r, std::uint8_t g, std::uint8_t bl) {
        if (!s.projected) return;
        const PixelRect& q = s.rect;
        auto set = [&](int x, int y) {
            std::uint8_t* p = pixel(x, y);
            p[0] = r, p[1] = g, p[2] = bl, p[3] = 255;
        };
        for (int x = q.x0; x <= q.x1; ++x) set(x, q.y0), set(x, q.y1);
        for (int y = q.y0; y <= q.y1; ++y) set(q.x0, y), set(q.x1, y);
    };
    for (const PatchBounds& b : bounds) outline(b.oobb, 230, 30, 30);
    for (const PatchBounds& b : bounds) outline(b.caf, 20, 200, 40);
    write_png_checked(path, width, height, 4, rgba);
}

}  // namespace patchcull::cli
