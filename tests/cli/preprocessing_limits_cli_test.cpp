// The CLI on faces and vertices beyond the preprocessing limits (patchcull/import/subdivision.h): one
// line naming the file and the face or vertex (1-based, as in the OBJ), exit status 2, at once.
// Before the limits `info` on a 10000-sided face exited 3 (std::bad_alloc) with acc and ran for
// minutes with osd.
#include <chrono>
#include <string>

#include "cli/cli_test_util.h"

using namespace patchcull::cli_test;

namespace {

std::string ngon_obj(int n) {
    std::string s;
    // Appended piecewise: GCC 12's -Wrestrict misreads "literal" + std::string.
    for (int k = 0; k < n; ++k) {
        s += "v ";
        s += std::to_string(k % 7);
        s += ' ';
        s += std::to_string(k);
        s += " 0\n";
    }
    s += "f";
    for (int k = 1; k <= n; ++k) {
        s += ' ';
        s += std::to_string(k);
    }
    return s + "\n";
}

std::string fan_obj(int n) {
    std::string s = "v 0 0 1\n";
    for (int k = 0; k < n; ++k) s += "v " + std::to_string(k) + " " + std::to_string(k % 5) + " 0\n";
    for (int k = 0; k < n; ++k) s += "f 1 " + std::to_string(2 + k) + " " + std::to_string(2 + (k + 1) % n) + "\n";
    return s;
}

}  // namespace

TEST(CliPreprocessingLimits, HugeFaceAndValenceExitTwoWithOneLine) {
    const std::string ngon = write_file("ngon10000.obj", ngon_obj(10000));
    const std::string fan = write_file("fan10000.obj", fan_obj(10000));
    for (const char* scheme : {"acc", "osd"}) {
        const auto t0 = std::chrono::steady_clock::now();
        expect_one_line_error(run("info " + ngon + " --scheme " + scheme), "ngon10000.obj: face 1 has 10000 corners");
        expect_one_line_error(run("info " + fan + " --scheme " + scheme), "fan10000.obj: vertex 1 has valence 10000");
        EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0) << scheme;
    }
}
