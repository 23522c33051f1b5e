// Strict option values for every CLI command, in one place so that each command rejects
// bad values the same way: one printable line naming the flag, exit status 2 (tools/main.cpp).
//
// CLI11's own conversions are too lenient for that promise: integers go through strtoll/strtoull
// with base 0 ("-1" wraps to 2^64-1 for an unsigned seed, "010" is octal, " 5" and "0x5" pass,
// overflow saturates), and reals through strtold ("nan", "inf", "1e999" pass). The helpers here
// parse plain decimal text with std::from_chars, which reports every one of those cases, and check
// the range the option documents. Output paths are checked before any work starts, so that a bad
// path costs no render and never surfaces as a filesystem exception afterwards.
#pragma once

#include "cli_fwd.h"

#include "patchcull/core/clip_space.h"

#include <cstdint>
#include <string>
#include <vector>

namespace patchcull::cli {

/// Decimal integer in [min, max]: ASCII digits, a leading '-' only for negative values; no '+',
/// spaces, base prefixes, exponents or fractions; no overflow. Throws patchcull::Error
/// "FLAG: expected an integer in MIN..MAX, got 'TEXT'" (TEXT quoted through quote_input).
std::int64_t parse_integer(const std::string& flag, const std::string& text, std::int64_t min, std::int64_t max);

/// Decimal unsigned integer in [0, max], the same rules (so "-1" is an error, not 2^64-1).
std::uint64_t parse_unsigned(const std::string& flag, const std::string& text, std::uint64_t max);

/// Finite decimal number in [min, max] ("1.5", "2e-3"; not "nan", "inf", hex floats, nor a value
/// that overflows or underflows a double). Throws patchcull::Error naming flag otherwise.
double parse_real(const std::string& flag, const std::string& text, double min, double max);

/// Registers `flag` (an option or a positional name) with an int target parsed by parse_integer
/// when the option is given; the target keeps its default otherwise. The range goes into the
/// help text's type name.
CLI::Option* add_int_option(CLI::App& command, const std::string& flag, int& target, int min, int max,
                            const std::string& description);

/// The same for an unsigned 64-bit target in [0, max] (view generator seeds).
CLI::Option* add_uint64_option(CLI::App& command, const std::string& flag, std::uint64_t& target, std::uint64_t max,
                               const std::string& description);

/// The same for a float target in [min, max], parsed by parse_real (the value then rounded to float;
/// min and max must be floats' range, so the rounded value stays in it).
CLI::Option* add_float_option(CLI::App& command, const std::string& flag, float& target, double min, double max,
                              const std::string& description);

/// A string option or positional whose value must not be empty (a path, a list).
CLI::Option* add_text_option(CLI::App& command, const std::string& flag, std::string& target,
                             const std::string& description);

/// A string option whose value must be one of choices; the error lists them.
CLI::Option* add_choice_option(CLI::App& command, const std::string& flag, std::string& target,
                               const std::vector<std::string>& choices, const std::string& description);

/// --clip-depth zero-to-one|minus-one-to-one|reversed|reversed-infinite (clip_space.h): the depth
/// convention a GPU command draws, culls and verifies in.
CLI::Option* add_clip_depth_option(CLI::App& command, std::string& target);
/// The ClipDepth of --clip-depth's text (checked by add_clip_depth_option).
ClipDepth parse_clip_depth_option(const std::string& text);

/// A "WIDTHxHEIGHT" option checked as it is parsed by parse_size (commands.h: each in 1..8192);
/// the target keeps the text, which the command converts with parse_size again.
CLI::Option* add_size_option(CLI::App& command, const std::string& flag, std::string& target,
                             const std::string& description);

/// Checks, before any work, that a file can be written at path (flag names the option in the
/// error): not empty, not a directory, and either an existing file that opens for writing (it is
/// not truncated here) or a new file that can be created in an existing directory (a probe is
/// created and removed). Throws patchcull::Error "FLAG: cannot write 'PATH': REASON" otherwise.
void check_output_file(const std::string& flag, const std::string& path);

/// A file path option checked by check_output_file as it is parsed (before the command's work).
CLI::Option* add_output_file_option(CLI::App& command, const std::string& flag, std::string& target,
                                    const std::string& description);

/// Checks, before any work, a directory that files will be written into: creates it (and its
/// parents) when missing, then checks each of files (names inside it) with check_output_file.
/// Throws patchcull::Error "FLAG: cannot create directory 'DIR': REASON" (or check_output_file's
/// error, naming flag) otherwise.
void prepare_output_dir(const std::string& flag, const std::string& dir, const std::vector<std::string>& files);

}  // namespace patchcull::cli

namespace patchcull::cli {

/// The one-line message for a CLI11 parse error. CLI11's own wording is kept except where it
/// does not say what is wrong: an option given more often than it may be ("FLAG: At Most 1
/// required but received 2") becomes "FLAG may be given once (given 2 times)".
std::string parse_error_message(const CLI::ParseError& error);

}  // namespace patchcull::cli
