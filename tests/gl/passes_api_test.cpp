// What gl_passes.h ships for an engine's own shaders: the embedded GLSL headers equal the files
// in shaders/ byte for byte, shared.h with the flag word (patchcull/core/cull_flags.h) inlined in
// place of its #include line, and only those three are handed out.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "patchcull/gl/gl_passes.h"
#include "shared.h"  // shaders/, on patchcull_gl's public include path

namespace {

std::string read_file(const std::string& path) {
    std::ifstream in(std::string(PATCHCULL_SOURCE_DIR) + "/" + path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

// shaders/NAME as shipped: its include of the flag word replaced by that file's text.
std::string read_source(const std::string& name) {
    std::string text = read_file("shaders/" + name);
    const std::string directive = "#include \"patchcull/core/cull_flags.h\"";
    const std::size_t at = text.find(directive);
    if (at != std::string::npos) text.replace(at, directive.size(), read_file("include/patchcull/core/cull_flags.h"));
    return text;
}

}  // namespace

TEST(PassesApi, ShippedGlslIsTheSourceFile) {
    for (const char* name : {"shared.h", "patchcull_tcs.h", "patchcull_draw_list.h"}) {
        const std::string_view shipped = patchcull::gl::shipped_glsl(name);
        ASSERT_FALSE(shipped.empty()) << name;
        EXPECT_EQ(std::string(shipped), read_source(name)) << name;
    }
    EXPECT_NE(patchcull::gl::shipped_glsl("patchcull_tcs.h").find("patchcull_patch_drawn"), std::string_view::npos);
    EXPECT_NE(patchcull::gl::shipped_glsl("patchcull_draw_list.h").find("patchcull_draw_list_patch"),
              std::string_view::npos);
    EXPECT_TRUE(patchcull::gl::shipped_glsl("frustum.comp.glsl").empty());  // internal, not shipped
    EXPECT_TRUE(patchcull::gl::shipped_glsl("nonexistent.h").empty());
    // The C++ side of the same constants.
    EXPECT_EQ(patchcull::gl::shared::kDrawMaskFirstPass, patchcull::gl::shared::kStatusVisible);
    EXPECT_EQ(std::string(patchcull::gl::shipped_glsl("shared.h")).find("\n#include \""), std::string::npos)
        << "the shipped shared.h needs no include of its own";
}
