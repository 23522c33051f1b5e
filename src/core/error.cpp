// Escaping of untrusted text in error messages (patchcull/core/error.h).
#include "patchcull/core/error.h"

#include <cstdint>

namespace patchcull {
namespace {

// Decodes the UTF-8 sequence at s[i] into cp and returns its length, or 0 when it is not valid
// UTF-8 (RFC 3629: no overlong forms, no surrogates, nothing above U+10FFFF).
std::size_t decode_utf8(std::string_view s, std::size_t i, std::uint32_t& cp) {
    const auto byte = [&](std::size_t k) { return static_cast<std::uint8_t>(s[k]); };
    const std::uint8_t b0 = byte(i);
    if (b0 < 0x80) {
        cp = b0;
        return 1;
    }
    std::size_t length = 0;
    std::uint32_t min = 0;
    if ((b0 & 0xE0) == 0xC0)
        length = 2, cp = b0 & 0x1F, min = 0x80;
    else if ((b0 & 0xF0) == 0xE0)
        length = 3, cp = b0 & 0x0F, min = 0x800;
    else if ((b0 & 0xF8) == 0xF0)
        length = 4, cp = b0 & 0x07, min = 0x10000;
    else
        return 0;
    if (i + length > s.size()) return 0;
    for (std::size_t k = 1; k < length; ++k) {
        if ((byte(i + k) & 0xC0) != 0x80) return 0;
        cp = cp << 6 | (byte(i + k) & 0x3F);
    }
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
    return length;
}

// Code points a terminal would not show as one visible character on this line: C0 and C1
// controls, DEL, the line and paragraph separators, the bidirectional marks, overrides and
// isolates (which reorder the rest of the line, so a message could be made to read differently),
// and the invisible zero-width characters and byte-order mark (a quoted 'v' that is not "v").
bool is_unprintable(std::uint32_t cp) {
    return cp < 0x20 || (cp >= 0x7F && cp < 0xA0) || (cp >= 0x200B && cp <= 0x200F) || cp == 0x2028 || cp == 0x2029 ||
           (cp >= 0x202A && cp <= 0x202E) || (cp >= 0x2066 && cp <= 0x2069) || cp == 0xFEFF;
}

const char kHex[] = "0123456789ABCDEF";

// Appends text escaped to out, stopping before out would grow past limit bytes; returns false
// when it stopped early.
bool append_escaped(std::string& out, std::string_view text, std::size_t limit, bool escape_quotes) {
    std::string piece;
    for (std::size_t i = 0; i < text.size();) {
        std::uint32_t cp = 0;
        const std::size_t length = decode_utf8(text, i, cp);
        piece.clear();
        if (length == 0) {
            const auto b = static_cast<std::uint8_t>(text[i]);
            piece = {'\\', 'x', kHex[b >> 4], kHex[b & 15]};
        } else if (cp == '\n') {
            piece = "\\n";
        } else if (cp == '\r') {
            piece = "\\r";
        } else if (cp == '\t') {
            piece = "\\t";
        } else if (cp < 0x80 && is_unprintable(cp)) {
            piece = {'\\', 'x', kHex[cp >> 4], kHex[cp & 15]};
        } else if (is_unprintable(cp)) {
            piece = {'\\', 'u', kHex[cp >> 12 & 15], kHex[cp >> 8 & 15], kHex[cp >> 4 & 15], kHex[cp & 15]};
        } else if (escape_quotes && (cp == '\\' || cp == '\'')) {
            piece = {'\\', static_cast<char>(cp)};
        } else {
            piece.assign(text.substr(i, length));
        }
        if (out.size() + piece.size() > limit) return false;
        out += piece;
        i += length == 0 ? 1 : length;
    }
    return true;
}

}  // namespace

std::string quote_input(std::string_view text, std::size_t max_bytes) {
    std::string out = "'";
    const bool whole = append_escaped(out, text, 1 + max_bytes, true);
    out += whole ? "'" : "'...";
    return out;
}

std::string printable_line(std::string_view message, std::size_t max_bytes) {
    std::string out;
    if (!append_escaped(out, message, max_bytes, false)) out += "...";
    return out;
}

bool is_printable_line(std::string_view text) {
    for (std::size_t i = 0; i < text.size();) {
        std::uint32_t cp = 0;
        const std::size_t length = decode_utf8(text, i, cp);
        if (length == 0 || is_unprintable(cp)) return false;
        i += length;
    }
    return true;
}

}  // namespace patchcull
