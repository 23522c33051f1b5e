// The names of cull modes and back-patch methods as the CLI's --cull and --backpatch take them:
// the choices, their listing in messages, and parsing with errors that name the flag
// (tools/cull_mode_names.cpp).
#pragma once

#include <string>
#include <vector>

#include "patchcull/gl/gl_cull_flags.h"
#include "patchcull/gl/gl_passes.h"

namespace patchcull::cli {

/// --cull's choices: the name of every gl::kCullModes mode, then "auto".
std::vector<std::string> cull_mode_choices();
/// --backpatch's choices: the name of every gl::kBackpatchMethods method.
std::vector<std::string> backpatch_method_choices();
/// "a, b or c": names as a message lists them.
std::string names_text(const std::vector<std::string>& names);
/// backpatch_method_choices()'s names -> method; throws patchcull::Error naming flag otherwise.
gl::BackpatchMethod parse_backpatch_method(const std::string& flag, const std::string& text);
/// cull_mode_name's names -> mode; throws patchcull::Error naming flag otherwise.
gl::CullMode parse_cull_mode_option(const std::string& flag, const std::string& text);

}  // namespace patchcull::cli
