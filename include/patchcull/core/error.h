// patchcull/core/error.h: the one exception type thrown by patchcull's loaders and builders, and the
// escaping every message that quotes input goes through.
//
// Kernels never throw. Loaders and factories throw patchcull::Error whose what() is a complete
// one-line message naming the file and line (or the flag) at fault, e.g.
// "model.obj:12: non-finite coordinate 'nan'". The CLI prints it and exits with status 2.
//
// Messages are one printable line and short: a loader that quotes the offending input quotes it
// through quote_input (a few dozen bytes at most, escaped), never raw. Input is untrusted: a
// fuzzed OBJ line can hold control bytes, invalid UTF-8 or megabytes without a newline, and a
// terminal shows those as garbage, or worse, obeys them.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace patchcull {

class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

/// Quotes untrusted input for an error message: the text in single quotes, escaped, and cut
/// after at most max_bytes bytes of escaped text ("..." then marks the cut).
/// Escaped: control bytes and DEL (\n \r \t, else \xNN), bytes that are not valid UTF-8 (\xNN
/// each), C1 controls, line/paragraph separators, bidirectional marks and overrides, zero-width
/// characters and U+FEFF (\uXXXX), backslash and the quote (\\ and \'). Other valid UTF-8 is
/// kept. Never throws except bad_alloc.
/// Example: quote_input("a\x01b") == "'a\\x01b'".
std::string quote_input(std::string_view text, std::size_t max_bytes = 40);

/// Makes a whole message safe to print as one line: the same escaping as quote_input (except
/// that backslashes and quotes stay as they are, so already quoted pieces read the same), cut
/// after max_bytes bytes with "...". The CLI's last line of defence before it prints an error.
std::string printable_line(std::string_view message, std::size_t max_bytes = 500);

/// True when text is what printable_line produces: valid UTF-8 without any of the characters it
/// escapes (so one line on a terminal). For tests and fuzz targets.
bool is_printable_line(std::string_view text);

}  // namespace patchcull
