// The viewer's --script parser (viewer_script.h).
#include "viewer_script.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "patchcull/core/error.h"

namespace patchcull::cli {
namespace {

constexpr int kMaxFrame = 10000000;

// Printable for a one-line message: control characters and bytes outside ASCII as \xNN.
std::string printable(const std::string& text) {
    static const char* hex = "0123456789abcdef";
    std::string out;
    for (unsigned char c : text.substr(0, 80)) {
        if (c >= 0x20 && c < 0x7f)
            out += static_cast<char>(c);
        else
            out += std::string("\\x") + hex[c >> 4] + hex[c & 15];
    }
    return text.size() > 80 ? out + "..." : out;
}

bool parse_int(const std::string& text, int& out) {
    const char* end = text.data() + text.size();
    const auto [ptr, ec] = std::from_chars(text.data(), end, out);
    return !text.empty() && ec == std::errc() && ptr == end;
}

bool parse_float(const std::string& text, float& out) {
    const char* end = text.data() + text.size();
    const auto [ptr, ec] = std::from_chars(text.data(), end, out);
    return !text.empty() && ec == std::errc() && ptr == end && std::isfinite(out) && std::fabs(out) <= 1e6f;
}

}  // namespace

ViewerScript parse_viewer_script(const std::string& text, const std::string& path) {
    ViewerScript script;
    script.path = path;
    std::istringstream in(text);
    std::string raw;
    int line_number = 0, last_frame = 0;
    while (std::getline(in, raw)) {
        ++line_number;
        auto fail = [&](const std::string& why) {
            std::string message = path;
            message.append(":").append(std::to_string(line_number)).append(": ").append(why);
            throw Error(message);
        };
        const std::string line = raw.substr(0, raw.find('#'));
        std::istringstream fields(line);
        std::vector<std::string> f;
        for (std::string w; fields >> w;) f.push_back(w);
        if (f.empty()) continue;
        ScriptEvent e;
        e.line = line_number;
        if (!parse_int(f[0], e.frame) || e.frame < 0 || e.frame > kMaxFrame)
            fail("expected a frame number in 0.." + std::to_string(kMaxFrame) + ", got '" + printable(f[0]) + "'");
        if (e.frame < last_frame)
            fail("frame " + std::to_string(e.frame) + " comes after frame " + std::to_string(last_frame) +
                 " (events must be in frame order)");
        last_frame = e.frame;
        if (f.size() < 2)
            fail("expected an event after the frame number (orbit, look, zoom, key, set, screenshot, quit)");
        const std::string& kind = f[1];
        auto expect_fields = [&](std::size_t n, const char* usage) {
            if (f.size() != n) fail(kind + ": expected '" + usage + "'");
        };
        auto number = [&](const std::string& t, const char* what) {
            float v = 0;
            if (!parse_float(t, v))
                fail(kind + ": " + what + " must be a number in -1e6..1e6, got '" + printable(t) + "'");
            return v;
        };
        if (kind == "orbit" || kind == "look") {
            expect_fields(4, kind == "orbit" ? "FRAME orbit DX DY" : "FRAME look DX DY");
            e.kind = kind == "orbit" ? ScriptEvent::Kind::orbit : ScriptEvent::Kind::look;
            e.x = number(f[2], "DX");
            e.y = number(f[3], "DY");
        } else if (kind == "zoom") {
            expect_fields(3, "FRAME zoom STEPS");
            e.kind = ScriptEvent::Kind::zoom;
            e.x = number(f[2], "STEPS");
        } else if (kind == "key") {
            expect_fields(3, "FRAME key NAME");
            e.kind = ScriptEvent::Kind::key;
            if (!parse_viewer_key(f[2], e.key))
                fail("unknown key '" + printable(f[2]) + "' (" + viewer_key_names() + ")");
        } else if (kind == "set") {
            expect_fields(4, "FRAME set NAME VALUE");
            e.kind = ScriptEvent::Kind::set;
            e.name = f[2];
            e.value = f[3];
            ViewerSettings scratch;  // the value's validity does not depend on the state
            const std::string why = apply_setting(scratch, e.name, e.value);
            if (!why.empty()) fail(printable(why));
        } else if (kind == "screenshot") {
            expect_fields(3, "FRAME screenshot PATH");
            e.kind = ScriptEvent::Kind::screenshot;
            e.value = f[2];
        } else if (kind == "quit") {
            expect_fields(2, "FRAME quit");
            e.kind = ScriptEvent::Kind::quit;
        } else {
            fail("unknown event '" + printable(kind) + "' (orbit, look, zoom, key, set, screenshot, quit)");
        }
        script.events.push_back(std::move(e));
    }
    return script;
}

ViewerScript load_viewer_script(const std::string& path) {
    std::error_code ec;
    std::ifstream file;
    if (std::filesystem::is_regular_file(path, ec)) file.open(path, std::ios::binary);
    if (!file.is_open() || !file) throw Error("--script: cannot read '" + printable(path) + "'");
    std::ostringstream text;
    text << file.rdbuf();
    return parse_viewer_script(text.str(), path);
}

}  // namespace patchcull::cli
