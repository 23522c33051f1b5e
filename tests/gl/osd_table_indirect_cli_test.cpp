// `patchcull render MODEL --scheme osd --patch-source osd-table --draw indirect`
// (tools/render_osd_table.h, gl_osd/osd_gl_draw.h): each draw pass's survivors listed per OpenSubdiv
// patch array by CompactPass and drawn indirectly with OpenSubdiv's own patch shaders, under the
// strict --verify of tests/gl/indirect_draw_cli_test.cpp: no false cull, only depth ties differ
// from the unculled draw, and every frame issues exactly the patches it draws (submitted ==
// drawn), on closed BigGuy (drawn one-sided, back-patch culling) in every --cull mode, back-patch
// method and clip depth, and on an open OpenSubdiv regression shape (drawn two-sided); the flag
// path (the default here) counts the same patches culled and drawn frame by frame while issuing
// every patch; --compact applies with --draw indirect only.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"

namespace osd_table_indirect_cli {

using namespace patchcull::cli_test;

struct Totals {
    long submitted = 0, drawn = 0, culled = 0, frames = 0;
    std::vector<nlohmann::json> frame_stats;  // the counters per frame, submitted left out
};

// One strict run (exit 0, no false cull, differing_pixels == depth_ties, submitted == drawn with
// indirect, every patch each pass with flags).
Totals osd_render(const std::string& model_args, const std::string& draw, const std::string& extra = "") {
    Totals t;
    const std::string command = "render " + model_args + " --scheme osd --patch-source osd-table --size 96x64" +
                                (draw.empty() ? "" : " --draw " + draw) + extra + " --verify --json";
    const CliRun r = run(command);
    EXPECT_EQ(r.status, 0) << command << "\n" << r.err;
    if (r.out.empty()) return t;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["draw"], draw.empty() ? "flags" : draw) << command;
    EXPECT_EQ(j["false_culls"], 0) << command;
    const long patches = j["patches"].get<long>();
    for (const nlohmann::json& f : j["frames"]) {
        const std::string where = command + ", frame " + f["frame"].dump();
        const long submitted = f["submitted"]["pass1"].get<long>() + f["submitted"]["pass2"].get<long>();
        const long drawn = f["pass1_drawn"].get<long>() + f["pass2_drawn"].get<long>();
        EXPECT_EQ(f["false_culls"], 0) << where;
        EXPECT_EQ(f["differing_pixels"], f["depth_ties"]) << where;
        if (j["draw"] == "indirect") {
            EXPECT_EQ(f["submitted"]["pass1"], f["pass1_drawn"]) << where;
            EXPECT_EQ(f["submitted"]["pass2"], f["pass2_drawn"]) << where;
        } else {
            EXPECT_EQ(f["submitted"]["pass1"].get<long>(), patches) << where;
        }
        EXPECT_GT(drawn, 0) << where;
        t.submitted += submitted;
        t.drawn += drawn;
        t.culled +=
            f["frustum_culled"].get<long>() + f["backpatch_culled"].get<long>() + f["occlusion_culled"].get<long>();
        ++t.frames;
        nlohmann::json stats = f;
        stats.erase("submitted");
        t.frame_stats.push_back(stats);
    }
    return t;
}

}  // namespace osd_table_indirect_cli

namespace oti = osd_table_indirect_cli;
using patchcull::cli_test::expect_one_line_error;
using patchcull::cli_test::run;

// BigGuy (closed): every --cull mode and back-patch method, each clip depth, both list orders.
TEST(OsdTableIndirectCli, ClosedBigGuyVerifiesInEveryModeAndClipDepth) {
    const std::string bigguy = "bigguy --frames 3 --tess 4";
    long culled = 0;
    for (const char* depth : {"zero-to-one", "minus-one-to-one", "reversed", "reversed-infinite"}) {
        culled += oti::osd_render(bigguy, "indirect", std::string(" --cull all --clip-depth ") + depth).culled;
        culled += oti::osd_render(bigguy, "indirect", std::string(" --cull occlusion --clip-depth ") + depth).culled;
    }
    for (const char* backpatch : {"tcone", "ncone", "ptp"})
        culled += oti::osd_render(bigguy, "indirect", std::string(" --cull backpatch --backpatch ") + backpatch).culled;
    oti::osd_render(bigguy, "indirect", " --cull frustum");
    const oti::Totals none = oti::osd_render(bigguy, "indirect", " --cull none");
    EXPECT_EQ(none.culled, 0);
    oti::osd_render(bigguy, "indirect", " --cull all --compact append --clip-depth reversed");
    EXPECT_GT(culled, 0);
}

// An open OpenSubdiv regression shape (holes, boundaries, Gregory-basis end caps; drawn
// two-sided, so --cull all leaves back-patch culling off), in both list orders and clip depths.
TEST(OsdTableIndirectCli, OpenShapeVerifies) {
    const std::string helmet = std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/opensubdiv/catmark_helmet.obj";
    long culled = 0;
    for (const char* depth : {"zero-to-one", "reversed"})
        culled +=
            oti::osd_render(helmet + " --frames 3 --tess 4", "indirect", std::string(" --clip-depth ") + depth).culled;
    oti::osd_render(helmet + " --frames 2 --tess 6", "indirect", " --compact append --cull occlusion");
    oti::osd_render(helmet + " --frames 2 --tess 2", "indirect", " --cull frustum --clip-depth minus-one-to-one");
    EXPECT_GT(culled, 0);
}

// The flag path (still the default with osd-table) and the compacted draw cull and draw the same
// patches frame by frame; only what is issued differs.
TEST(OsdTableIndirectCli, IndirectCountsEqualTheFlagPath) {
    const std::string helmet = std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/opensubdiv/catmark_helmet.obj";
    for (const std::string& args : {std::string("bigguy --frames 3 --tess 4"), helmet + " --frames 3 --tess 4"}) {
        const oti::Totals flags = oti::osd_render(args, "");
        const oti::Totals indirect = oti::osd_render(args, "indirect");
        EXPECT_EQ(indirect.frame_stats, flags.frame_stats) << args;
        EXPECT_EQ(indirect.submitted, indirect.drawn) << args;
        EXPECT_LT(indirect.submitted, flags.submitted) << args;
        EXPECT_GT(indirect.culled, 0) << args;
    }
}

// OpenSubdiv's largest uniform level (16: 32 on patches of refinement level 0): llvmpipe gets a
// draw of more than 65536 / 33^2 such patches wrong, so both draw modes split there (before that
// split the flag path's unculled reference itself drew wrong pixels: 9 false culls on BigGuy).
TEST(OsdTableIndirectCli, TessellationSixteenVerifiesInBothDrawModes) {
    for (const char* draw : {"", "indirect"}) {
        const oti::Totals t = oti::osd_render("bigguy --frames 2 --tess 16", draw);
        EXPECT_GT(t.culled, 0) << draw;
    }
}

TEST(OsdTableIndirectCli, CompactWithoutIndirectIsAOneLineError) {
    const std::string args = "render bigguy --scheme osd --patch-source osd-table --frames 1 --size 16x16 ";
    expect_one_line_error(run(args + "--compact append"), "--compact needs --draw indirect");
    expect_one_line_error(run(args + "--draw flags --compact scan"), "--compact needs --draw indirect");
    expect_one_line_error(run(args + "--draw indirect --compact atomic"), "--compact");
    expect_one_line_error(run(args + "--draw indirect --compact fused"), "--compact fused");
}
