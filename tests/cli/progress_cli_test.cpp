// `cull`'s progress line (tools/progress.h): drawn on stderr when stderr is a terminal (a
// pseudo-terminal from util-linux `script`), ending at the total with a newline; nothing extra
// with --json, and nothing when stderr is not a terminal. The teapot (32 patches), a few hundred
// views: well under a second.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "terminal_run.h"

using namespace patchcull::cli_test;

namespace {

// Each line cut before its ", N ns/patch" (a timing differs from run to run).
std::string without_timings(const std::string& text) {
    std::string out;
    std::size_t begin = 0;
    while (begin < text.size()) {
        std::size_t end = text.find('\n', begin);
        if (end == std::string::npos) end = text.size();
        std::string line = text.substr(begin, end - begin);
        const std::size_t timing = line.find(" ns/patch");
        if (timing != std::string::npos) line = line.substr(0, line.rfind(", ", timing));
        out += line + "\n";
        begin = end + 1;
    }
    return out;
}

const char* const kArgs = "cull teapot --views 300";  // frustum, frustum-disp: no warning on the open teapot

}  // namespace

TEST(ProgressCli, CullDrawsViewsRateAndTheFinalLineOnATerminal) {
    if (!have_script()) GTEST_SKIP() << "util-linux script is not installed";
    const TerminalRun r = run_on_terminal(kArgs);
    ASSERT_EQ(r.status, 0) << r.terminal;
    // The final line: all views, a rate, the elapsed time, then the newline (the terminal's "\r\n").
    const std::size_t final_line = r.terminal.rfind("\rcull: 300/300 views  ");
    ASSERT_NE(final_line, std::string::npos) << r.terminal;
    const std::string last = r.terminal.substr(final_line);
    EXPECT_NE(last.find(" views/s  "), std::string::npos) << last;
    EXPECT_EQ(last.find("ETA"), std::string::npos) << last;
    EXPECT_EQ(last.substr(last.size() - 2), "\r\n") << last;
    EXPECT_EQ(last.find('\n'), last.size() - 1) << last;  // one line
    // The result on stdout is what it is without a terminal (but for the timings, ns/patch).
    const CliRun plain = run(kArgs);
    ASSERT_EQ(plain.status, 0) << plain.err;
    EXPECT_EQ(without_timings(r.out), without_timings(plain.out)) << r.out;
    EXPECT_NE(without_timings(r.out).find("frustum-disp: cull rate"), std::string::npos) << r.out;
}

TEST(ProgressCli, NothingExtraWithJsonOrWithoutATerminal) {
    if (!have_script()) GTEST_SKIP() << "util-linux script is not installed";
    const TerminalRun json = run_on_terminal(std::string(kArgs) + " --json");
    ASSERT_EQ(json.status, 0) << json.terminal;
    EXPECT_EQ(json.terminal, "");  // --json on a terminal: no progress
    EXPECT_EQ(nlohmann::json::parse(json.out)["views"], 300);
    // stderr a file: no progress either (the frustum methods on the teapot print nothing there).
    const CliRun plain = run(kArgs);
    ASSERT_EQ(plain.status, 0) << plain.err;
    EXPECT_EQ(plain.err.find("views/s"), std::string::npos) << plain.err;
    EXPECT_EQ(plain.err.find('\r'), std::string::npos) << plain.err;
}

TEST(ProgressCli, AnErrorOnATerminalStaysOneLine) {
    if (!have_script()) GTEST_SKIP() << "util-linux script is not installed";
    // Fails before the loop (a bad flag): no progress line drawn, the error is the only line.
    const TerminalRun r = run_on_terminal("cull teapot --views 0");
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.terminal.find("views/s"), std::string::npos) << r.terminal;
    EXPECT_EQ(r.terminal.find("patchcull: error: --views"), 0u) << r.terminal;
    EXPECT_EQ(r.terminal.find('\n'), r.terminal.size() - 1) << r.terminal;
}
