// OpenSubdiv's own regression shapes (tests/data/opensubdiv, tags read by patchcull/import/obj.h) through
// the CLI: they load with both schemes and the CPU cull check finds no false cull on them.
#include <nlohmann/json.hpp>

#include "cli_test_util.h"

using namespace patchcull::cli_test;

namespace {

std::string shape(const char* name) {
    return std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/opensubdiv/" + name + ".obj";
}

}  // namespace

TEST(CliOpenSubdivShapes, TheHelmetAndAHoledCubeCullWithoutFalseCullsWithBothSchemes) {
    // The helmet (creases, interpolateboundary) was refused before its tags were read; the cube
    // has a face tagged as a hole, so it is drawn two-sided (the back-patch truth then counts
    // front-facing samples only: cull warns, and its false culls must still be 0).
    for (const char* name : {"catmark_helmet", "catmark_hole_test1"})
        for (const char* scheme : {"acc", "osd"}) {
            SCOPED_TRACE(std::string(name) + " " + scheme);
            const CliRun r =
                run("cull " + shape(name) + " --scheme " + scheme +
                    " --views 12 --seed 7 --view-mode free --methods frustum,frustum-disp,tcone,ptp --json");
            ASSERT_EQ(r.status, 0) << r.err;
            const auto j = nlohmann::json::parse(r.out);
            EXPECT_GT(j["patches"].get<int>(), 0);
            for (const char* m : {"frustum", "frustum-disp", "tcone", "ptp"}) {
                ASSERT_TRUE(j["methods"][m].is_object()) << m;
                EXPECT_EQ(j["methods"][m]["false_culls"], 0) << m;
            }
        }
}

TEST(CliOpenSubdivShapes, AnEdgesOnlyShapeWithCornersIsRefusedByAccNamingTheLineAndOsd) {
    const CliRun acc = run("info " + shape("catmark_edgeonly") + " --scheme acc");
    expect_one_line_error(acc, "catmark_edgeonly.obj:");
    EXPECT_NE(acc.err.find("use the osd scheme"), std::string::npos) << acc.err;
    const CliRun osd = run("info " + shape("catmark_edgeonly") + " --scheme osd --json");
    EXPECT_EQ(osd.status, 0) << osd.err;
}
