// `patchcull cull` on BigGuy translated far from the origin: no false culls and the
// untranslated model's cull rates. Before the OBJ reader re-centred in double, a translation of
// 1e6 gave hundreds of frustum false culls per 200 free views and ptp culled nothing.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_util.h"

using namespace patchcull::cli_test;

TEST(CliFarOrigin, TranslatedBigGuyCullsAsAtTheOrigin) {
    const std::string far = write_file("bigguy_far.obj", translated_bigguy(1e6));
    const std::string args =
        " --views 24 --view-mode free --methods frustum,frustum-disp,tcone,ncone,ptp,ptp-pcnt --json";
    const CliRun base = run("cull " + model("bigguy.obj") + args);
    const CliRun moved = run("cull " + far + args);
    ASSERT_EQ(base.status, 0) << base.err;
    ASSERT_EQ(moved.status, 0) << moved.err;
    const auto b = nlohmann::json::parse(base.out)["methods"], m = nlohmann::json::parse(moved.out)["methods"];
    for (const char* name : {"frustum", "frustum-disp", "tcone", "ncone", "ptp", "ptp-pcnt"}) {
        EXPECT_EQ(m[name]["false_culls"], 0) << name;
        EXPECT_NEAR(m[name]["cull_rate"].get<double>(), b[name]["cull_rate"].get<double>(), 0.01) << name;
        EXPECT_GT(b[name]["cull_rate"].get<double>(), 0.1) << name;  // not vacuous
    }
}
