// Shipped models by name in every command (`cull bigguy`, `info monsterfrog`; render, view and
// eval load through the same load_model), with the answers of their paths, and PATCHCULL_DATA_DIR:
// an empty value counts as unset, a wrong one gives one line naming the path.
#include <gtest/gtest.h>

#include <algorithm>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"

namespace patchcull::cli_test {
namespace {

TEST(ModelNamesCli, ShippedModelsResolveByName) {
    for (const char* name : {"bigguy", "monsterfrog"}) {
        const CliRun by_name = run(std::string("info ") + name + " --json");
        ASSERT_EQ(by_name.status, 0) << by_name.err;
        const CliRun by_path = run("info " + model((std::string(name) + ".obj").c_str()) + " --json");
        ASSERT_EQ(by_path.status, 0) << by_path.err;
        const auto a = nlohmann::json::parse(by_name.out), b = nlohmann::json::parse(by_path.out);
        EXPECT_EQ(a["model"], name);
        EXPECT_EQ(a["patches"], b["patches"]) << name;
    }
    const CliRun cull = run("cull bigguy --views 2 --methods frustum --json");
    ASSERT_EQ(cull.status, 0) << cull.err;
    EXPECT_EQ(nlohmann::json::parse(cull.out)["model"], "bigguy");
}

TEST(ModelNamesCli, EmptyDataDirIsUnsetAndAWrongOneIsNamed) {
    const CliRun empty = run("info bigguy --json", "PATCHCULL_DATA_DIR=");
    EXPECT_EQ(empty.status, 0) << empty.err;
    const CliRun wrong = run("info bigguy --json", "PATCHCULL_DATA_DIR=/nonexistent/patchcull");
    EXPECT_EQ(wrong.status, 2);
    EXPECT_NE(wrong.err.find("/nonexistent/patchcull/models/bigguy.obj"), std::string::npos) << wrong.err;
    EXPECT_EQ(std::count(wrong.err.begin(), wrong.err.end(), '\n'), 1) << wrong.err;
}

TEST(ModelNamesCli, UnknownNamesAreStillPaths) {
    const CliRun r = run("info no_such_model --json");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("no_such_model"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace patchcull::cli_test
