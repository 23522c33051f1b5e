// The library's layering, checked by grepping includes: dependencies point one way, downwards.
//   tools -> public headers; src/eval -> import + core; src/import -> core; src/core -> nothing
//   of ours above it (and no OpenSubdiv, stb or GL).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>

namespace fs = std::filesystem;

namespace {

// Public headers by layer.
const std::set<std::string> kCoreHeaders = {"math.h", "patch.h", "mesh.h", "displacement.h", "camera.h",
                                            "frustum.h", "ground_truth.h", "parallel.h", "teapot.h", "error.h",
                                            "hiz.h", "cones.h", "backpatch.h", "displaced_bounds.h",
                                            "clip_space.h", "bounding_volumes.h", "object_bvh.h", "backface.h",
                                            "backface_clusters.h", "object_culling.h", "occlusion_horizon.h",
                                            "portal_culling.h", "tight_bounds.h", "fused_cull.h",
                                            "fused_cost_model.h"};
const std::set<std::string> kImportHeaders = {"obj.h", "subdivision.h", "image.h", "animation.h", "scene.h",
                                              "default_scene.h", "scene_file.h", "scene_object_level.h",
                                              "scene_occlusion.h"};

std::vector<std::pair<std::string, std::string>> includes_under(const std::string& dir) {
    std::vector<std::pair<std::string, std::string>> found;
    const std::regex include_re(R"(^\s*#\s*include\s*[<"]([^>"]+)[>"])");
    for (const auto& entry : fs::recursive_directory_iterator(fs::path(PATCHCULL_SOURCE_DIR) / dir)) {
        if (!entry.is_regular_file()) continue;
        std::ifstream in(entry.path());
        std::string line;
        std::smatch m;
        while (std::getline(in, line))
            if (std::regex_search(line, m, include_re)) found.emplace_back(entry.path().string(), m[1]);
    }
    return found;
}

bool is_ours(const std::string& inc, std::string& header) {
    if (inc.rfind("patchcull/", 0) != 0) return false;
    header = inc.substr(10);
    return true;
}

}  // namespace

TEST(Layering, CoreDependsOnNothingAboveIt) {
    for (const auto& [file, inc] : includes_under("src/core")) {
        std::string h;
        if (is_ours(inc, h)) {
            EXPECT_TRUE(kCoreHeaders.count(h)) << file << " includes " << inc;
        }
        EXPECT_EQ(inc.find("opensubdiv"), std::string::npos) << file;
        EXPECT_EQ(inc.find("stb"), std::string::npos) << file;
        EXPECT_EQ(inc.find("GL"), std::string::npos) << file;
    }
    for (const std::string& header : kCoreHeaders)
        for (const auto& [file, inc] : includes_under("include/patchcull")) {
            if (fs::path(file).filename() != header) continue;
            std::string h;
            if (is_ours(inc, h)) {
                EXPECT_TRUE(kCoreHeaders.count(h)) << file << " includes " << inc;
            }
        }
}

TEST(Layering, ImportDependsOnlyOnCore) {
    for (const auto& [file, inc] : includes_under("src/import")) {
        std::string h;
        if (is_ours(inc, h)) {
            EXPECT_TRUE(kCoreHeaders.count(h) || kImportHeaders.count(h)) << file << " includes " << inc;
        }
    }
}

TEST(Layering, ToolsUseOnlyPublicHeaders) {
    for (const auto& [file, inc] : includes_under("tools")) {
        EXPECT_EQ(inc.find("src/"), std::string::npos) << file << " includes " << inc;
        EXPECT_EQ(inc.find("../"), std::string::npos) << file << " includes " << inc;
        EXPECT_EQ(inc.find("opensubdiv"), std::string::npos) << file << " includes " << inc;
    }
}
