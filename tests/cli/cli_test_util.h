// Helpers shared by the CLI tests: run the patchcull binary with arguments, capture stdout,
// stderr and the exit status, and check the one-line error contract.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

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
        std::string d =
            (std::filesystem::temp_directory_path() / ("patchcull_cli_" + std::to_string(getpid()))).string();
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

/// The OBJ file at path with every vertex (x, y, z) -> move(index, x, y, z) (written with 17
/// significant digits, so a file's own decimals survive translations up to 1e7) and, when
/// reverse is set, every face's corner order reversed; other lines as they are. For tests of
/// edits of the shipped models: translated, mirrored, inside out, folded, flat.
inline std::string edited_obj(const std::string& path, const std::function<void(int, double&, double&, double&)>& move,
                              bool reverse = false) {
    std::istringstream in(slurp(path));
    std::ostringstream out;
    std::string line;
    int vertex = 0;
    char buf[128];
    while (std::getline(in, line)) {
        std::istringstream fields(line);
        std::string tag;
        fields >> tag;
        double x = 0, y = 0, z = 0;
        if (tag == "v" && (fields >> x >> y >> z)) {
            move(vertex++, x, y, z);
            std::snprintf(buf, sizeof buf, "v %.17g %.17g %.17g", x, y, z);
            out << buf << '\n';
        } else if (tag == "f" && reverse) {
            std::vector<std::string> corners;
            for (std::string c; fields >> c;) corners.push_back(c);
            out << 'f';
            for (auto it = corners.rbegin(); it != corners.rend(); ++it) out << ' ' << *it;
            out << '\n';
        } else {
            out << line << '\n';
        }
    }
    return out.str();
}

/// edited_obj of the shipped BigGuy translated by (t, t, t).
inline std::string translated_bigguy(double t) {
    return edited_obj(model("bigguy.obj"), [t](int, double& x, double& y, double& z) { x += t, y += t, z += t; });
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
