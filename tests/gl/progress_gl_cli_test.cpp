// The GPU commands' progress lines (tools/progress.h) on a pseudo-terminal: `eval temporal`
// counts frames over all speeds, `eval occlusion` views; nothing with --json. In the gl suite
// because they render (the teapot at 64x64, level 2: about a second on llvmpipe).
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "cli/terminal_run.h"

using namespace patchcull::cli_test;

TEST(ProgressGlCli, EvalTemporalCountsFramesOfEverySpeed) {
    if (!have_script()) GTEST_SKIP() << "util-linux script is not installed";
    const std::string args = "eval temporal teapot --speeds 0,20 --frames 3 --size 64x64 --tess 2";
    const TerminalRun r = run_on_terminal(args);
    ASSERT_EQ(r.status, 0) << r.terminal;
    const std::size_t final_line = r.terminal.rfind("\reval temporal: 6/6 frames  ");
    ASSERT_NE(final_line, std::string::npos) << r.terminal;
    EXPECT_EQ(r.terminal.substr(r.terminal.size() - 2), "\r\n") << r.terminal;
    const TerminalRun json = run_on_terminal(args + " --json");
    ASSERT_EQ(json.status, 0) << json.terminal;
    EXPECT_EQ(json.terminal, "");
    EXPECT_EQ(nlohmann::json::parse(json.out)["speeds"].size(), 2u);
}

TEST(ProgressGlCli, EvalOcclusionCountsViews) {
    if (!have_script()) GTEST_SKIP() << "util-linux script is not installed";
    const std::string args = "eval occlusion teapot --views 2 --size 64x64 --tess 2";
    const TerminalRun r = run_on_terminal(args);
    ASSERT_EQ(r.status, 0) << r.terminal;
    EXPECT_NE(r.terminal.rfind("\reval occlusion: 2/2 views  "), std::string::npos) << r.terminal;
    const TerminalRun json = run_on_terminal(args + " --json");
    ASSERT_EQ(json.status, 0) << json.terminal;
    EXPECT_EQ(json.terminal, "");
}
