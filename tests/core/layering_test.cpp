// The library's layering, checked by the folders: each layer is a folder of sources (src/<layer>)
// and of public headers (include/patchcull/<layer>), and its files include the public headers of
// the layers below it only:
//   core <- objects <- import <- eval;  core, objects <- gl;  eval, gl <- eval_gl (the
//   evaluations of the GPU pipeline);  import, gl <- gl_osd (OpenSubdiv's GL patch tables culled
//   by the gl passes);  core <- vk (the Vulkan passes, no GL);  tools -> public headers.
// The kernels and the object level include no OpenSubdiv, stb or GL; the Vulkan layer no GL.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

// The layers each layer may include (itself included).
const std::map<std::string, std::set<std::string>> kAllowed = {
    {"core", {"core"}},
    {"objects", {"core", "objects"}},
    {"import", {"core", "objects", "import"}},
    {"eval", {"core", "objects", "import", "eval"}},
    {"gl", {"core", "objects", "gl"}},
    {"eval_gl", {"core", "objects", "import", "eval", "gl", "eval_gl"}},
    {"gl_osd", {"core", "objects", "import", "gl", "gl_osd"}},
    {"vk", {"core", "vk"}},
};

struct Include {
    std::string file, target;
};

std::vector<Include> includes_under(const fs::path& dir) {
    std::vector<Include> found;
    if (!fs::exists(dir)) return found;
    const std::regex include_re(R"(^\s*#\s*include\s*[<"]([^>"]+)[>"])");
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
        if (!entry.is_regular_file()) continue;
        std::ifstream in(entry.path());
        std::string line;
        std::smatch m;
        while (std::getline(in, line))
            if (std::regex_search(line, m, include_re)) found.push_back({entry.path().string(), m[1]});
    }
    return found;
}

// The layer of a public header include ("patchcull/core/frustum.h" -> "core"); "" for
// patchcull/version.h (generated, every layer's), "?" for any other patchcull/ path.
std::string layer_of(const std::string& inc) {
    if (inc.rfind("patchcull/", 0) != 0) return "-";
    const std::string rest = inc.substr(10);
    if (rest == "version.h") return "";
    const std::size_t slash = rest.find('/');
    return slash == std::string::npos ? "?" : rest.substr(0, slash);
}

const fs::path kRoot = fs::path(PATCHCULL_SOURCE_DIR);

}  // namespace

TEST(Layering, EveryPublicHeaderLivesInALayerFolder) {
    std::size_t headers = 0;
    for (const auto& entry : fs::directory_iterator(kRoot / "include/patchcull")) {
        if (entry.is_directory()) {
            EXPECT_TRUE(kAllowed.count(entry.path().filename().string())) << entry.path() << " is not a layer";
            for (const auto& h : fs::directory_iterator(entry.path())) headers += h.path().extension() == ".h";
            continue;
        }
        const std::string name = entry.path().filename().string();
        EXPECT_TRUE(name == "version.h.in") << entry.path() << " is outside every layer folder";
    }
    EXPECT_GE(headers, 40u);
    for (const auto& [layer, allowed] : kAllowed) {
        (void)allowed;
        EXPECT_TRUE(fs::is_directory(kRoot / "include/patchcull" / layer)) << layer;
        EXPECT_TRUE(fs::is_directory(kRoot / "src" / layer)) << layer;
    }
}

TEST(Layering, EachLayerIncludesOnlyTheLayersBelowIt) {
    for (const auto& [layer, allowed] : kAllowed) {
        std::vector<Include> all = includes_under(kRoot / "include/patchcull" / layer);
        const std::vector<Include> sources = includes_under(kRoot / "src" / layer);
        all.insert(all.end(), sources.begin(), sources.end());
        EXPECT_FALSE(all.empty()) << layer;
        for (const Include& i : all) {
            const std::string to = layer_of(i.target);
            if (to == "-" || to.empty()) continue;
            EXPECT_TRUE(allowed.count(to)) << i.file << " (layer " << layer << ") includes " << i.target;
        }
    }
}

TEST(Layering, KernelsAndObjectLevelNeedNoOpenSubdivStbOrGl) {
    for (const char* layer : {"core", "objects"})
        for (const char* dir : {"src", "include/patchcull"})
            for (const Include& i : includes_under(kRoot / dir / layer)) {
                EXPECT_EQ(i.target.find("opensubdiv"), std::string::npos) << i.file;
                EXPECT_EQ(i.target.find("stb"), std::string::npos) << i.file;
                EXPECT_EQ(i.target.find("GL"), std::string::npos) << i.file;
                EXPECT_EQ(i.target.find("epoxy"), std::string::npos) << i.file;
            }
}

TEST(Layering, VulkanLayerNeedsNoGl) {
    for (const char* dir : {"src/vk", "include/patchcull/vk"})
        for (const Include& i : includes_under(kRoot / dir)) {
            EXPECT_EQ(i.target.find("epoxy"), std::string::npos) << i.file << " includes " << i.target;
            EXPECT_EQ(i.target.find("GL/"), std::string::npos) << i.file << " includes " << i.target;
            EXPECT_EQ(i.target.find("EGL"), std::string::npos) << i.file << " includes " << i.target;
            EXPECT_EQ(i.target.find("gl_"), std::string::npos) << i.file << " includes " << i.target;
        }
}

TEST(Layering, ToolsUseOnlyPublicHeaders) {
    for (const Include& i : includes_under(kRoot / "tools")) {
        EXPECT_EQ(i.target.find("src/"), std::string::npos) << i.file << " includes " << i.target;
        EXPECT_EQ(i.target.find("../"), std::string::npos) << i.file << " includes " << i.target;
        EXPECT_EQ(i.target.find("opensubdiv"), std::string::npos) << i.file << " includes " << i.target;
        EXPECT_NE(layer_of(i.target), "?") << i.file << " includes " << i.target;
    }
}
