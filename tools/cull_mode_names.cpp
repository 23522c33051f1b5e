// The CLI's names of cull modes and back-patch methods (cull_mode_names.h).
#include "cull_mode_names.h"

#include <string>

#include "patchcull/core/error.h"
#include "patchcull/gl/gl_backpatch_passes.h"

namespace patchcull::cli {

std::vector<std::string> cull_mode_choices() {
    std::vector<std::string> names;
    for (gl::CullMode m : gl::kCullModes) names.emplace_back(gl::cull_mode_name(m));
    names.emplace_back("auto");
    return names;
}

std::vector<std::string> backpatch_method_choices() {
    std::vector<std::string> names;
    for (gl::BackpatchMethod m : gl::gpu_backpatch_methods()) names.emplace_back(gl::backpatch_method_name(m));
    return names;
}

std::string names_text(const std::vector<std::string>& names) {
    std::string text;
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (i > 0) text += i + 1 == names.size() ? " or " : ", ";
        text += names[i];
    }
    return text;
}

gl::BackpatchMethod parse_backpatch_method(const std::string& flag, const std::string& text) {
    gl::BackpatchMethod method = gl::BackpatchMethod::tcone;
    if (!gl::parse_backpatch_method(text.c_str(), method))
        throw Error(flag + ": unknown back-patch method '" + text + "' (" + names_text(backpatch_method_choices()) +
                    ")");
    return method;
}

gl::CullMode parse_cull_mode_option(const std::string& flag, const std::string& text) {
    gl::CullMode mode = gl::CullMode::none;
    if (!gl::parse_cull_mode(text.c_str(), mode)) {
        std::vector<std::string> names = cull_mode_choices();
        names.pop_back();  // "auto" is the tools' own, decided before a mode is parsed
        throw Error(flag + ": unknown cull mode '" + text + "' (" + names_text(names) + ")");
    }
    return mode;
}

}  // namespace patchcull::cli
