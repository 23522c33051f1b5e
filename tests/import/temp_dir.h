// A fresh directory per test under the system's temp directory, named by a prefix, the test and
// the process (test runs of other build directories may run at the same time), removed at the
// end; and a file written into it.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include <unistd.h>

namespace patchcull::test_files {

struct TempDir {
    std::filesystem::path path;
    TempDir(const std::string& prefix, const std::string& name)
        : path(std::filesystem::temp_directory_path() / (prefix + "_" + name + "_" + std::to_string(::getpid()))) {
        std::filesystem::remove_all(path);
        std::filesystem::create_directories(path);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    std::filesystem::path operator/(const std::string& p) const { return path / p; }
    std::string string() const { return path.string(); }
};

/// Writes text to path (binary), creating its directories.
inline void write_file(const std::filesystem::path& path, const std::string& text) {
    std::filesystem::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << text;
}

}  // namespace patchcull::test_files
