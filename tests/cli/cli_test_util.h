// Helpers shared by the CLI tests: run the patchcull binary with arguments, capture stdout,
// stderr and the exit status, and check the one-line error contract.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace patchcull::cli_test {

struct CliRun {
    int status = -1;
    std::string out, err;
};

inline std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

/// A scratch directory of this test process (under the system's temporary directory).
inline const std::string& scratch_dir() {
    static const std::string dir = [] {
        std::string d = (std::filesystem::temp_directory_path() / ("patchcull_cli_" + std::to_string(getpid()))).string();
        std::filesystem::create_directories(d);
        return d;
    }();
    return dir;
}

/// Runs `patchcull ARGS` (the build's binary) with stdin from /dev/null; env (e.g. "NAME=value")
/// is prefixed to the shell command.
inline CliRun run(const std::string& args, const std::string& env = "") {
    const std::string out = scratch_dir() + "/stdout", err = scratch_dir() + "/stderr";
    const std::string cmd =
        env + " " + std::string(PATCHCULL_CLI) + " " + args + " >" + out + " 2>" + err + " </dev/null";
    const int raw = std::system(cmd.c_str());
    CliRun r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
}

inline std::string model(const char* name) { return std::string(PATCHCULL_SOURCE_DIR) + "/data/models/" + name; }

inline std::string write_file(const std::string& name, const std::string& content) {
    const std::string path = scratch_dir() + "/" + name;
    std::ofstream(path, std::ios::binary) << content;
    return path;
}

/// The error must be exactly one line, name the culprit, and exit with status 2.
inline void expect_one_line_error(const CliRun& r, const std::string& must_contain) {
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    ASSERT_FALSE(r.err.empty());
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
    EXPECT_NE(r.err.find(must_contain), std::string::npos) << r.err;
}

}  // namespace patchcull::cli_test
