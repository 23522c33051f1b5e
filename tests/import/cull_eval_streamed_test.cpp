// evaluate_cull with the streamed ground truth gives the answers of the eager one it
// replaced: the culled patch-view counts below are those printed by `patchcull cull ... --json`
// built at 18c0849, before the change (cull_rate * patches * views; every false-cull count was 0),
// for teapot and BigGuy, acc and osd, displaced and not, free and distance views. The
// undisplaced cases run every method, so both truths (surface samples, tangent planes) are judged; the teapot
// cases run 300 views, more than one block, so the per-block sums are covered.
//
// The commands (M = data/models, all = frustum,frustum-disp,tcone,ncone,ptp,ptp-pcnt):
//   cull teapot --scheme acc --views 300 --view-mode free --methods $all
//   cull teapot --scheme osd --displace procedural --views 300 --view-mode free
//   cull $M/bigguy.obj --scheme acc --views 40 --view-mode free --methods $all
//   cull $M/bigguy.obj --scheme osd --displace procedural --views 6 --view-mode free
//   cull $M/bigguy.obj --scheme acc --displace procedural --views 12 --view-mode free --seed 5
//   cull $M/bigguy.obj --scheme acc --views 20 --view-mode distance --methods $all --seed 9
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "patchcull/core/displacement.h"
#include "patchcull/core/error.h"
#include "patchcull/eval/cull_eval.h"
#include "patchcull/import/model_loader.h"

using namespace patchcull;

namespace {

const std::vector<std::string> kAll = {"frustum", "frustum-disp", "tcone", "ncone", "ptp", "ptp-pcnt"};

struct OldRun {
    const char* model;  // "teapot" or a shipped model's file name
    Scheme scheme;
    bool displaced;  // --displace procedural at the CLI's default scale
    ViewMode mode;
    bool distance;  // --view-mode distance (default range)
    int views;
    std::uint64_t seed;
    bool all_methods;
    std::map<std::string, std::uint64_t> culled;
};

void expect_same_as_old(const OldRun& run) {
    const std::string spec = std::string(run.model) == "teapot" ? "teapot" : shipped_model_path(run.model);
    const LoadedModel model = load_model(spec, run.scheme, 0);
    DisplacementMap displacement;
    if (run.displaced) {  // tools/model_options.cpp: 2% of the patches' box diagonal, 512^2 map
        const Bounds b = patch_bounds(model.rest);
        displacement = make_procedural_displacement(512, 0.02f * length(b.max - b.min));
    }
    CullEvalOptions options;
    options.views = run.views;
    options.seed = run.seed;
    options.mode = run.mode;
    if (run.distance) options.distance = DistanceViews{};
    if (run.all_methods) options.methods = kAll;
    const CullEvalResult r = evaluate_cull(model.rest, run.displaced ? &displacement : nullptr, options);
    ASSERT_EQ(r.methods.size(), run.culled.size()) << run.model;
    for (const CullMethodResult& m : r.methods) {
        const std::string what = std::string(run.model) + " " + m.name;
        ASSERT_TRUE(run.culled.count(m.name)) << what;
        EXPECT_EQ(m.culled, run.culled.at(m.name)) << what;
        EXPECT_EQ(m.false_culls, 0u) << what;
        EXPECT_EQ(m.cull_rate, double(m.culled) / (double(r.patches) * run.views)) << what;
    }
}

}  // namespace

TEST(CullEvalStreamed, TeapotAccEveryMethodEqualsTheEagerTruths) {
    expect_same_as_old({"teapot",
                        Scheme::acc,
                        false,
                        ViewMode::free,
                        false,
                        300,
                        1,
                        true,
                        {{"frustum", 6495},
                         {"frustum-disp", 6168},
                         {"tcone", 97},
                         {"ncone", 428},
                         {"ptp", 1496},
                         {"ptp-pcnt", 2047}}});
}

TEST(CullEvalStreamed, TeapotOsdDisplacedEqualsTheEagerTruth) {
    expect_same_as_old({"teapot",
                        Scheme::osd,
                        true,
                        ViewMode::free,
                        false,
                        300,
                        1,
                        false,
                        {{"frustum", 6317}, {"frustum-disp", 5911}}});
}

TEST(CullEvalStreamed, BigGuyAccEveryMethodEqualsTheEagerTruths) {
    expect_same_as_old({"bigguy.obj",
                        Scheme::acc,
                        false,
                        ViewMode::free,
                        false,
                        40,
                        1,
                        true,
                        {{"frustum", 49515},
                         {"frustum-disp", 49045},
                         {"tcone", 15108},
                         {"ncone", 21488},
                         {"ptp", 26035},
                         {"ptp-pcnt", 26035}}});
}

TEST(CullEvalStreamed, BigGuyOsdDisplacedEqualsTheEagerTruth) {
    expect_same_as_old({"bigguy.obj",
                        Scheme::osd,
                        true,
                        ViewMode::free,
                        false,
                        6,
                        1,
                        false,
                        {{"frustum", 30158}, {"frustum-disp", 30006}}});
}

TEST(CullEvalStreamed, BigGuyAccDisplacedEqualsTheEagerTruth) {
    expect_same_as_old({"bigguy.obj",
                        Scheme::acc,
                        true,
                        ViewMode::free,
                        false,
                        12,
                        5,
                        false,
                        {{"frustum", 12853}, {"frustum-disp", 12712}}});
}

TEST(CullEvalStreamed, BigGuyDistanceViewsEqualTheEagerTruths) {
    expect_same_as_old(
        {"bigguy.obj",
         Scheme::acc,
         false,
         ViewMode::contain,
         true,
         20,
         9,
         true,
         {{"frustum", 0}, {"frustum-disp", 0}, {"tcone", 5988}, {"ncone", 8799}, {"ptp", 10442}, {"ptp-pcnt", 10442}}});
}

// Progress comes per block of views: increasing, ending at the view count, more than once for
// 300 views of a small model (blocks of at most 256).
TEST(CullEvalStreamed, ProgressReportsEachBlockUpToTheViewCount) {
    const LoadedModel model = load_model("teapot", Scheme::acc, 0);
    CullEvalOptions options;
    options.views = 300;
    options.mode = ViewMode::free;
    std::vector<int> reported;
    options.on_view_done = [&](int done) { reported.push_back(done); };
    evaluate_cull(model.rest, nullptr, options);
    ASSERT_GE(reported.size(), 2u);
    for (std::size_t k = 1; k < reported.size(); ++k) EXPECT_GT(reported[k], reported[k - 1]);
    EXPECT_GT(reported.front(), 0);
    EXPECT_EQ(reported.back(), 300);
}

TEST(CullEvalStreamed, GridOutsideItsRangeThrows) {
    const LoadedModel model = load_model("teapot", Scheme::acc, 0);
    CullEvalOptions options;
    options.views = 1;
    options.ground_truth_grid = 0;
    EXPECT_THROW(evaluate_cull(model.rest, nullptr, options), Error);
    options.ground_truth_grid = 1025;
    EXPECT_THROW(evaluate_cull(model.rest, nullptr, options), Error);
}
