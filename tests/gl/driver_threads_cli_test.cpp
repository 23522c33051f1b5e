// `render --driver-threads spread|os` ("driver_threads" and "pinned_driver_threads" in the JSON):
// on llvmpipe the driver's threads are pinned one CPU each by default and left alone with os, and
// the frames verify either way; the OpenSubdiv patch-table path takes the flag too; bad values are
// one-line errors.
#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"
#include "patchcull/core/thread_placement.h"

using namespace patchcull::cli_test;

namespace {

// `render ARGS --json`: exit 0; returns the JSON.
nlohmann::json driver_threads_run(const std::string& args) {
    const CliRun r = run("render " + args + " --json");
    EXPECT_EQ(r.status, 0) << args << "\n" << r.err;
    return r.out.empty() ? nlohmann::json::object() : nlohmann::json::parse(r.out);
}

bool several_cpus() { return patchcull::thread_cpu_count(static_cast<int>(gettid())) >= 2; }

}  // namespace

TEST(DriverThreadsCli, SpreadByDefaultOsLeavesThemAloneBothVerify) {
    const nlohmann::json spread = driver_threads_run("default --frames 2 --tess 2 --size 80x48 --verify");
    const nlohmann::json os =
        driver_threads_run("default --frames 2 --tess 2 --size 80x48 --verify --driver-threads os");
    ASSERT_TRUE(spread.contains("driver_threads") && os.contains("driver_threads"));
    EXPECT_EQ(spread["driver_threads"], "spread");
    EXPECT_EQ(os["driver_threads"], "os");
    EXPECT_EQ(os["pinned_driver_threads"], 0);
    const bool software = spread["renderer"].get<std::string>().find("llvmpipe") != std::string::npos;
    if (software && several_cpus()) {
        EXPECT_GT(spread["pinned_driver_threads"].get<int>(), 0);
    } else {
        EXPECT_EQ(spread["pinned_driver_threads"], 0);
    }
    EXPECT_EQ(spread["false_culls"], 0);
    EXPECT_EQ(os["false_culls"], 0);
}

TEST(DriverThreadsCli, OsdTablePathTakesTheFlag) {
    const nlohmann::json j = driver_threads_run(
        "bigguy --scheme osd --patch-source osd-table --frames 1 --tess 2 --size 64x48 --driver-threads os");
    EXPECT_EQ(j.value("driver_threads", ""), "os");
    EXPECT_EQ(j.value("pinned_driver_threads", -1), 0);
}

TEST(DriverThreadsCli, BadValuesAreOneLineErrors) {
    expect_one_line_error(run("render default --frames 1 --driver-threads pinned"), "--driver-threads");
    expect_one_line_error(run("render default --frames 1 --driver-threads"), "--driver-threads");
}
