// The CLI11 types the CLI's headers name, declared without <CLI/CLI.hpp> (CLI11 2.x, namespace
// CLI): only the files that register or parse options include CLI11 itself, which costs several
// seconds of compile time in every file that includes it.
#pragma once

namespace CLI {
class App;
class Option;
class ParseError;
}  // namespace CLI
