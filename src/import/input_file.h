// The one check every loader makes before reading a file (not a public header): a regular file
// of bounded size. Loaders read whole files into memory, so a device (/dev/zero), a FIFO or a
// multi-gigabyte file would otherwise hang or exhaust memory instead of failing with one line.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <system_error>

namespace patchcull::detail {

/// Empty when path names a regular file (symbolic links followed) of at most max_bytes bytes;
/// else why not, for the loader's one-line error ("cannot open file", "not a regular file ...",
/// "N bytes, larger than ...").
inline std::string input_file_problem(const std::string& path, std::uintmax_t max_bytes, const char* what) {
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status)) return "cannot open file";
    if (!std::filesystem::is_regular_file(status))
        return std::string("not a regular file (patchcull reads ") + what + " files only)";
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) return "cannot read the file size";
    if (size > max_bytes)
        return std::to_string(size) + " bytes, larger than the " + std::to_string(max_bytes >> 20) +
               " MiB patchcull reads for " + what + " files";
    return {};
}

}  // namespace patchcull::detail
