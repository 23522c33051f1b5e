// Uses patchcull::gl from an installed package: the GLSL headers installed for an engine's shaders
// are the ones the library embeds (shipped_glsl), shared.h compiles as C++ from patchcull::gl's
// include path, and a headless GL 4.5 context comes up (Mesa llvmpipe without a GPU). Exit
// status 1 on any failure.
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "check.h"
#include "patchcull/core/error.h"
#include "patchcull/gl/gl_passes.h"
#include "patchcull/gl/gl_renderer.h"
#include "shared.h"  // include/patchcull/glsl/shared.h, on patchcull::gl's include path

namespace {

std::string read_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

}  // namespace

int main() {
    for (const char* name : {"shared.h", "patchcull_tcs.h", "patchcull_draw_list.h"}) {
        const std::string path = std::string(CONSUMER_GLSL_DIR) + "/" + name;
        const std::string installed = read_file(path);
        const std::string_view embedded = patchcull::gl::shipped_glsl(name);
        check(!installed.empty() && installed == embedded, path + " (" + std::to_string(installed.size()) +
                                                               " bytes) is shipped_glsl(\"" + name + "\") (" +
                                                               std::to_string(embedded.size()) + " bytes)");
    }
    check(patchcull::gl::shared::kBindingControlPoints == 0u, "shared.h: kBindingControlPoints is binding 0");
    try {
        patchcull::gl::GlContext context = patchcull::gl::GlContext::create_headless();
        check(true, "headless context: " + context.renderer() + ", " + context.version());
    } catch (const patchcull::Error& e) {
        check(false, std::string("headless context: ") + e.what());
    }
    return failures == 0 ? 0 : 1;
}
