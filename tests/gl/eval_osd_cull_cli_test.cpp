// `patchcull eval osd-cull MODEL` (tools/eval/eval_osd_cull.cpp), a smoke run of a few frames at
// 16x16 (about half a second): three views, four modes each, every culled frame's ids equal to the
// unculled frame's (exit status 0, "diff px" 0), the unculled frame tessellates every patch and
// the culling modes no more; bad flags are one-line errors. Times are not asserted (the figures
// are in docs/PERFORMANCE.md, "OpenSubdiv's own patch culling against patchcull's passes").
#include <gtest/gtest.h>

#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "cli/cli_test_util.h"

using namespace patchcull::cli_test;

namespace {

struct ModeRow {
    std::string mode;
    unsigned long long tessellated = 0, differing = 0;
};

// The rows of each view's table: "  (x) label   tessellated ratio invocs ratio ms ratio diff".
std::vector<std::vector<ModeRow>> parse_views(const std::string& out) {
    std::vector<std::vector<ModeRow>> views;
    std::istringstream in(out);
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("view ", 0) == 0) views.emplace_back();
        if (line.rfind("  (", 0) != 0 || views.empty() || line.size() < 40) continue;
        ModeRow row;
        row.mode = line.substr(2, 3);
        std::istringstream numbers(line.substr(39));
        std::string ratio, invocations, invocation_ratio, ms, ms_ratio;
        numbers >> row.tessellated >> ratio >> invocations >> invocation_ratio >> ms >> ms_ratio >> row.differing;
        EXPECT_TRUE(numbers) << line;
        views.back().push_back(row);
    }
    return views;
}

}  // namespace

TEST(EvalOsdCullCli, SmokeRunDrawsTheUnculledPixels) {
    const CliRun r = run("eval osd-cull bigguy --level 1 --tess 2 --size 16x16 --rounds 1 --warmup 1");
    ASSERT_EQ(r.status, 0) << r.err << r.out;
    unsigned long long patches = 0;
    ASSERT_EQ(std::sscanf(r.out.c_str(), "eval osd-cull: %*[^,], adaptive level 1, %llu patches", &patches), 1)
        << r.out;
    const std::vector<std::vector<ModeRow>> views = parse_views(r.out);
    ASSERT_EQ(views.size(), 3u) << r.out;
    for (const std::vector<ModeRow>& rows : views) {
        ASSERT_EQ(rows.size(), 4u) << r.out;
        EXPECT_EQ(rows[0].mode, "(a)");
        EXPECT_EQ(rows[0].tessellated, patches);
        for (const ModeRow& row : rows) {
            EXPECT_LE(row.tessellated, patches) << row.mode;
            EXPECT_EQ(row.differing, 0u) << row.mode;
        }
    }
    // The aside view leaves part of the model outside: both frustum tests cull.
    EXPECT_LT(views[2][1].tessellated, patches);
    EXPECT_LT(views[2][2].tessellated, patches);
}

TEST(EvalOsdCullCli, BadFlagsAreOneLineErrors) {
    expect_one_line_error(run("eval osd-cull bigguy --tess 17"), "--tess");
    expect_one_line_error(run("eval osd-cull bigguy --level 0"), "--level");
    expect_one_line_error(run("eval osd-cull teapot"), "teapot");
}
