// Meshes whose size float arithmetic cannot hold (patchcull/import/model_loader.h, kMaxMeshExtent): a box with
// corners at +-3e38 is finite in the OBJ, but every squared length of it overflows float, so the
// views and kernels saw infinities and culled nothing without a word; at +-1e13 ptp's rounding
// margin already blocks every cull. Both are refused with one line, exit 2; a box at the limit
// loads and culls as a unit box does.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"

using namespace patchcull::cli_test;

namespace {

std::string box_obj(const std::string& half) {
    std::string obj;
    for (int i = 0; i < 8; ++i) {
        obj += 'v';
        for (int bit : {1, 2, 4}) {
            obj += i & bit ? " " : " -";
            obj += half;
        }
        obj += '\n';
    }
    obj += "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
    return obj;
}

}  // namespace

TEST(CliHugeMesh, MeshWiderThanFloatArithmeticIsRefused) {
    for (const char* half : {"3e38", "1e13"}) {
        const std::string path = write_file("huge_box.obj", box_obj(half));
        for (const char* command : {"info", "cull"}) {
            const CliRun r = run(std::string(command) + " " + path);
            expect_one_line_error(r, "units across");
        }
    }
}

TEST(CliHugeMesh, MeshTooSmallForFloatIsRefused) {
    // 1e-40 is subnormal in float; 1e-10 used to make every free view cull everything.
    for (const char* half : {"1e-40", "1e-10"}) {
        const CliRun r = run("cull " + write_file("tiny_box.obj", box_obj(half)) + " --views 3");
        expect_one_line_error(r, "units across");
    }
    const CliRun ok = run("info " + write_file("small_box.obj", box_obj("1e-6")));
    EXPECT_EQ(ok.status, 0) << ok.err;
}

TEST(CliHugeMesh, MeshAtTheLimitCullsAsAUnitBox) {
    const std::string args = " --views 100 --view-mode free --methods frustum,frustum-disp,ptp --json";
    const CliRun unit = run("cull " + write_file("unit_box.obj", box_obj("1")) + args);
    const CliRun wide = run("cull " + write_file("wide_box.obj", box_obj("1e11")) + args);
    ASSERT_EQ(unit.status, 0) << unit.err;
    ASSERT_EQ(wide.status, 0) << wide.err;
    const auto u = nlohmann::json::parse(unit.out)["methods"], w = nlohmann::json::parse(wide.out)["methods"];
    for (const char* method : {"frustum", "frustum-disp", "ptp"}) {
        EXPECT_EQ(w[method]["false_culls"], 0) << method;
        EXPECT_NEAR(w[method]["cull_rate"].get<double>(), u[method]["cull_rate"].get<double>(), 0.01) << method;
        EXPECT_GT(w[method]["cull_rate"].get<double>(), 0.3) << method;
    }
}
