// The library's layering for the renderer (the folders themselves: tests/core/layering_test.cpp):
// src/gl uses public headers (and its own files, the shared shader header), never src/import or
// src/eval internals; shaders are real files, not C++ strings.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

namespace fs = std::filesystem;

TEST(GlLayering, RendererUsesOnlyPublicHeadersAndItsOwnFiles) {
    const std::regex include_re(R"(^\s*#\s*include\s*[<"]([^>"]+)[>"])");
    std::size_t files = 0;
    for (const auto& entry : fs::directory_iterator(fs::path(PATCHCULL_SOURCE_DIR) / "src/gl")) {
        if (!entry.is_regular_file() || entry.path().extension() == ".txt") continue;
        ++files;
        std::ifstream in(entry.path());
        std::string line;
        std::smatch m;
        while (std::getline(in, line)) {
            if (!std::regex_search(line, m, include_re)) continue;
            const std::string inc = m[1];
            EXPECT_EQ(inc.find("import"), std::string::npos) << entry.path() << " includes " << inc;
            EXPECT_EQ(inc.find("eval"), std::string::npos) << entry.path() << " includes " << inc;
            EXPECT_EQ(inc.find("topology"), std::string::npos) << entry.path() << " includes " << inc;
            EXPECT_EQ(inc.find("opensubdiv"), std::string::npos) << entry.path() << " includes " << inc;
            EXPECT_EQ(inc.find("../"), std::string::npos) << entry.path() << " includes " << inc;
            // The import layer (model loading, animation) stays out of the renderer: the caller hands
            // it patches.
            EXPECT_EQ(inc.find("patchcull/import/"), std::string::npos) << entry.path() << " includes " << inc;
        }
        // No GLSL embedded as string literals in the sources: shaders live in shaders/*.glsl.
        std::ifstream again(entry.path());
        const std::string text((std::istreambuf_iterator<char>(again)), std::istreambuf_iterator<char>());
        EXPECT_EQ(text.find("#version 4"), std::string::npos) << entry.path();
    }
    EXPECT_GE(files, 3u);
}

TEST(GlLayering, PublicRendererHeaderUsesOnlyCoreHeaders) {
    const std::regex include_re(R"(^\s*#\s*include\s*[<"]([^>"]+)[>"])");
    // No import header (scenes, models, animation, subdivision): the renderer takes patches.
    // gl_posing.h: tables as plain arrays.
    for (const char* header :
         {"gl_context.h", "gl_cull_flags.h", "gl_renderer.h", "gl_verification.h", "gl_posing.h"}) {
        std::ifstream in(fs::path(PATCHCULL_SOURCE_DIR) / "include/patchcull/gl" / header);
        ASSERT_TRUE(in.good()) << header;
        std::string line;
        std::smatch m;
        while (std::getline(in, line)) {
            if (!std::regex_search(line, m, include_re)) continue;
            const std::string inc = m[1];
            for (const char* banned : {"patchcull/import/", "epoxy", "GL/", "EGL/"})
                EXPECT_EQ(inc.find(banned), std::string::npos) << header << " includes " << inc;
        }
    }
}
