// Strict option values and output-path checks shared by the CLI's commands (cli_options.h).
#include <CLI/CLI.hpp>

#include "cli_options.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "commands.h"
#include "patchcull/core/error.h"

namespace patchcull::cli {
namespace {

// Plain decimal text only: from_chars alone would accept a leading '-' for signed types, so the
// sign rule is checked here, and the whole text must be consumed.
template <class T>
bool from_decimal(const std::string& text, T& value) {
    if (text.empty()) return false;
    const char* begin = text.data();
    const char* end = begin + text.size();
    const auto [ptr, ec] = std::from_chars(begin, end, value);
    return ec == std::errc() && ptr == end;
}

[[noreturn]] void throw_integer_error(const std::string& flag, const std::string& text, const std::string& range) {
    throw Error(flag + ": expected an integer in " + range + ", got " + quote_input(text));
}

std::string errno_text(int error) { return std::strerror(error); }

}  // namespace

std::int64_t parse_integer(const std::string& flag, const std::string& text, std::int64_t min, std::int64_t max) {
    std::int64_t value = 0;
    const std::string range = std::to_string(min) + ".." + std::to_string(max);
    if (!from_decimal(text, value) || value < min || value > max) throw_integer_error(flag, text, range);
    return value;
}

std::uint64_t parse_unsigned(const std::string& flag, const std::string& text, std::uint64_t max) {
    std::uint64_t value = 0;
    if (!from_decimal(text, value) || value > max) throw_integer_error(flag, text, "0.." + std::to_string(max));
    return value;
}

double parse_real(const std::string& flag, const std::string& text, double min, double max) {
    double value = 0;
    // chars_format::general: no hex floats; "nan"/"inf" parse but are not finite; ERANGE (overflow
    // or underflow) is an error rather than a clamp.
    if (!from_decimal(text, value) || !std::isfinite(value) || value < min || value > max) {
        char range[64];
        std::snprintf(range, sizeof range, "%g..%g", min, max);
        throw Error(flag + ": expected a finite number in " + range + ", got " + quote_input(text));
    }
    return value;
}

CLI::Option* add_int_option(CLI::App& command, const std::string& flag, int& target, int min, int max,
                            const std::string& description) {
    CLI::Option* option = command.add_option_function<std::string>(
        flag,
        [&target, flag, min, max](const std::string& text) {
            target = static_cast<int>(parse_integer(flag, text, min, max));
        },
        description);
    option->type_name("INT " + std::to_string(min) + ".." + std::to_string(max));
    option->default_str(std::to_string(target));
    return option;
}

CLI::Option* add_uint64_option(CLI::App& command, const std::string& flag, std::uint64_t& target, std::uint64_t max,
                               const std::string& description) {
    CLI::Option* option = command.add_option_function<std::string>(
        flag, [&target, flag, max](const std::string& text) { target = parse_unsigned(flag, text, max); }, description);
    option->type_name("UINT 0.." + std::to_string(max));
    option->default_str(std::to_string(target));
    return option;
}

CLI::Option* add_float_option(CLI::App& command, const std::string& flag, float& target, double min, double max,
                              const std::string& description) {
    CLI::Option* option = command.add_option_function<std::string>(
        flag,
        [&target, flag, min, max](const std::string& text) {
            target = static_cast<float>(parse_real(flag, text, min, max));
        },
        description);
    char range[64];
    std::snprintf(range, sizeof range, "REAL %g..%g", min, max);
    option->type_name(range);
    return option;
}

CLI::Option* add_text_option(CLI::App& command, const std::string& flag, std::string& target,
                             const std::string& description) {
    CLI::Option* option = command.add_option_function<std::string>(
        flag,
        [&target, flag](const std::string& text) {
            if (text.empty()) throw Error(flag + ": must not be empty");
            target = text;
        },
        description);
    if (!target.empty()) option->default_str(target);
    return option;
}

CLI::Option* add_choice_option(CLI::App& command, const std::string& flag, std::string& target,
                               const std::vector<std::string>& choices, const std::string& description) {
    std::string names;
    for (const std::string& c : choices) names += (names.empty() ? "" : "|") + c;
    CLI::Option* option = command.add_option_function<std::string>(
        flag,
        [&target, flag, choices, names](const std::string& text) {
            for (const std::string& c : choices)
                if (text == c) {
                    target = text;
                    return;
                }
            throw Error(flag + ": expected one of " + names + ", got " + quote_input(text));
        },
        description);
    option->type_name(names);
    option->default_str(target);
    return option;
}

CLI::Option* add_clip_depth_option(CLI::App& command, std::string& target) {
    return add_choice_option(command, "--clip-depth", target,
                             {"zero-to-one", "minus-one-to-one", "reversed", "reversed-infinite"},
                             "depth convention to draw, cull and verify in: zero-to-one (near 0, far 1), "
                             "minus-one-to-one (OpenGL's default), reversed (near 1, far 0, GL_GREATER) or "
                             "reversed-infinite (near 1, no far plane)");
}

ClipDepth parse_clip_depth_option(const std::string& text) {
    ClipDepth depth = ClipDepth::zero_to_one;
    if (!parse_clip_depth(text, depth)) throw Error("--clip-depth: unknown convention " + quote_input(text));
    return depth;
}

CLI::Option* add_size_option(CLI::App& command, const std::string& flag, std::string& target,
                             const std::string& description) {
    CLI::Option* option = command.add_option_function<std::string>(
        flag,
        [&target, flag](const std::string& text) {
            // parse_size quotes the text as it is: only digits and 'x' reach it.
            if (text.find_first_not_of("0123456789x") != std::string::npos)
                throw Error(flag + ": expected WIDTHxHEIGHT with each in 1..8192, got " + quote_input(text));
            int width = 0, height = 0;
            parse_size(flag, text, width, height);
            target = text;
        },
        description);
    option->type_name("WxH");
    option->default_str(target);
    return option;
}

void check_output_file(const std::string& flag, const std::string& path) {
    if (path.empty()) throw Error(flag + ": empty path");
    const auto fail = [&](const std::string& reason) {
        throw Error(flag + ": cannot write " + quote_input(path, 200) + ": " + reason);
    };
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(path, ec);
    if (std::filesystem::is_directory(status)) fail("is a directory");
    if (std::filesystem::exists(status)) {
        // Opened without O_TRUNC (the old file stays until the work is done) and O_NONBLOCK (a
        // FIFO without a reader fails with ENXIO instead of blocking).
        const int fd = ::open(path.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
        if (fd < 0) fail(errno_text(errno));
        ::close(fd);
        return;
    }
    // A new file: the probe is the file itself, created exclusively so that nothing is clobbered,
    // then removed. This covers a missing directory, a parent that is a file, permissions and
    // read-only file systems in one call.
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) fail(errno_text(errno));
    ::close(fd);
    ::unlink(path.c_str());
}

CLI::Option* add_output_file_option(CLI::App& command, const std::string& flag, std::string& target,
                                    const std::string& description) {
    return command.add_option_function<std::string>(
        flag,
        [&target, flag](const std::string& text) {
            check_output_file(flag, text);
            target = text;
        },
        description);
}

void prepare_output_dir(const std::string& flag, const std::string& dir, const std::vector<std::string>& files) {
    if (dir.empty()) throw Error(flag + ": empty path");
    std::error_code ec;
    const std::filesystem::path path(dir);
    if (!std::filesystem::is_directory(path, ec)) {
        std::filesystem::create_directories(path, ec);
        if (ec || !std::filesystem::is_directory(path))
            throw Error(flag + ": cannot create directory " + quote_input(dir, 200) + ": " +
                        (ec ? ec.message() : "not a directory"));
    }
    for (const std::string& file : files) check_output_file(flag, (path / file).string());
}

}  // namespace patchcull::cli

namespace patchcull::cli {

std::string parse_error_message(const CLI::ParseError& error) {
    std::string what = error.what();
    // CLI11 (ArgumentMismatch::AtMost): "NAME: At Most N required but received M", thrown for every
    // option whose values, over all its occurrences, outnumber what it takes.
    static const std::string kAtMost = ": At Most ", kReceived = " required but received ";
    const std::size_t at = what.find(kAtMost);
    const std::size_t received = what.find(kReceived);
    if (dynamic_cast<const CLI::ArgumentMismatch*>(&error) == nullptr || at == std::string::npos ||
        received == std::string::npos || received < at)
        return what;
    const std::string name = what.substr(0, at);
    const std::string most = what.substr(at + kAtMost.size(), received - at - kAtMost.size());
    const std::string given = what.substr(received + kReceived.size());
    if (most == "1") return name + " may be given once (given " + given + " times)";
    return name + " takes at most " + most + " values (given " + given + ")";
}

}  // namespace patchcull::cli
