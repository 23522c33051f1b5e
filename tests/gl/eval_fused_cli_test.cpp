// `patchcull eval fused SCENE --json` (tools/eval/eval_fused.cpp): the JSON contract of its head
// comment on data/scenes/city_small.json and on the default scene with both schemes, every culled
// patch checked against the unculled frame's id buffer (0 false culls), the fixed plans' ratios
// relative to the best, the model's choices adding up to its object-frames; bad flags are one-line
// errors with exit status 2. Under tests/gl (GL-heavy CLI runs stay out of the ASan build's run).
// Speed itself is not asserted: the numbers are in docs/PERFORMANCE.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_json_util.h"

using namespace patchcull::cli_test;
using nlohmann::json;

namespace {

void check_contract(const json& j, int frames) {
    EXPECT_EQ(json_keys(j),
              (std::set<std::string>{
                  "scene",         "clip_depth", "scheme",    "target", "objects", "fused_objects",    "patches",
                  "fused_patches", "frames",     "size",      "tess",   "repeats", "profile_interval", "cone",
                  "culled",        "plans",      "best_plan", "model",  "oracle",  "separate",         "false_culls"}));
    EXPECT_EQ(j["false_culls"], 0);
    EXPECT_EQ(j["frames"], frames);
    EXPECT_GT(j["fused_objects"].get<int>(), 0);
    EXPECT_LE(j["fused_patches"].get<int>(), j["patches"].get<int>());
    double fractions = 0;
    for (const char* k : {"frustum", "backpatch", "occlusion", "visible"}) fractions += j["culled"][k].get<double>();
    EXPECT_NEAR(fractions, 1.0, 1e-9);
    std::set<std::string> plans;
    double best = 1e30;
    for (const json& p : j["plans"]) {
        EXPECT_EQ(json_keys(p), (std::set<std::string>{"plan", "seconds", "ratio_to_best"}));
        plans.insert(p["plan"].get<std::string>());
        EXPECT_GE(p["ratio_to_best"].get<double>(), 1.0 - 1e-12);
        best = std::min(best, p["ratio_to_best"].get<double>());
        EXPECT_GT(p["seconds"].get<double>(), 0.0);
    }
    EXPECT_EQ(plans, (std::set<std::string>{"FBH", "FHB", "BFH"}));
    EXPECT_NEAR(best, 1.0, 1e-12);
    EXPECT_TRUE(plans.count(j["best_plan"].get<std::string>()));
    const json& m = j["model"];
    EXPECT_EQ(json_keys(m), (std::set<std::string>{"seconds", "profile_seconds", "ratio_to_best", "ratio_to_oracle",
                                                   "agreement", "profiled", "choices"}));
    int chosen = 0;
    for (auto it = m["choices"].begin(); it != m["choices"].end(); ++it) {
        EXPECT_TRUE(plans.count(it.key())) << it.key();
        chosen += it.value().get<int>();
    }
    EXPECT_EQ(chosen, frames * j["fused_objects"].get<int>());
    EXPECT_EQ(m["profiled"].get<int>() >= j["fused_objects"].get<int>(), true) << "every object is profiled first";
    EXPECT_GE(m["agreement"].get<double>(), 0.0);
    EXPECT_LE(m["agreement"].get<double>(), 1.0);
    EXPECT_LE(j["oracle"]["ratio_to_best"].get<double>(), 1.0 + 1e-12);
    EXPECT_GT(j["separate"]["seconds"].get<double>(), 0.0);
}

}  // namespace

TEST(EvalFusedCli, CitySmallContractAndNoFalseCulls) {
    const std::string city = std::string(PATCHCULL_SOURCE_DIR) + "/data/scenes/city_small.json";
    const json j = run_json("eval fused " + city + " --frames 3 --size 160x90 --repeats 1 --profile-interval 2 --json");
    check_contract(j, 3);
    // Objects behind the box buildings: the Hi-Z stage culls something.
    EXPECT_GT(j["culled"]["occlusion"].get<double>(), 0.0);
}

TEST(EvalFusedCli, DefaultSceneBothSchemesAndNcone) {
    for (const std::string scheme : {"acc", "osd"}) {
        const json j =
            run_json("eval fused default --scheme " + scheme + " --frames 2 --size 128x96 --repeats 1 --json");
        check_contract(j, 2);
    }
    const json j = run_json("eval fused teapot --cone ncone --frames 2 --size 64x48 --repeats 1 --json");
    check_contract(j, 2);
    EXPECT_EQ(j["cone"], "ncone");
}

TEST(EvalFusedCli, BadFlagsAreOneLineErrors) {
    for (const std::string args : {"eval fused default --frames 0", "eval fused default --repeats x",
                                   "eval fused default --cone pcone", "eval fused default --size 0x10",
                                   "eval fused /nonexistent/scene.json", "eval fused default --profile-interval 0"}) {
        const CliRun r = run(args);
        EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
        EXPECT_TRUE(r.out.empty()) << args;
    }
}
