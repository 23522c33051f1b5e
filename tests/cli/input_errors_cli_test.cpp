// Bad input through the CLI: whatever bytes a model, an image or a path holds, the user sees one
// printable line of bounded length and exit status 2 (tools/main.cpp, patchcull/error.h).
#include "cli_test_util.h"

#include "patchcull/error.h"

using namespace patchcull::cli_test;

namespace {

// One short printable line, exit status 2.
void expect_printable_error(const CliRun& r, const std::string& must_contain) {
    expect_one_line_error(r, must_contain);
    const std::string line = r.err.substr(0, r.err.size() - 1);
    EXPECT_TRUE(patchcull::is_printable_line(line)) << patchcull::printable_line(line);
    EXPECT_LE(line.size(), 600u);
}

}  // namespace

TEST(CliInputErrors, ControlBytesInAModelAreEscaped) {
    const std::string path = write_file("control.obj", "v 0 0 0\nv 1 \x1B[2J\x07 0\n");
    expect_printable_error(run("info " + path), "control.obj:2: malformed number '\\x1B[2J\\x07'");
}

TEST(CliInputErrors, InvalidUtf8InAModelIsEscaped) {
    const std::string path = write_file("latin1.obj", "v 0 0 0\nvert\xE9x 1 2 3\n");
    expect_printable_error(run("info " + path), "latin1.obj:2: unknown record 'vert\\xE9x'");
}

TEST(CliInputErrors, AMegabyteLineIsQuotedByItsStartOnly) {
    const std::string path = write_file("long.obj", "v 0 0 0\n" + std::string(4 << 20, '\x01') + "\n");
    const CliRun r = run("info " + path);
    expect_printable_error(r, "long.obj:2: unknown record '\\x01\\x01");
    EXPECT_LE(r.err.size(), 200u);
}

TEST(CliInputErrors, AMisspeltCreaseTagIsAnError) {
    const std::string path = write_file("tag.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nt creese 2/1/0 0 1 10\n");
    expect_printable_error(run("info " + path), "tag.obj:6: unknown tag 'creese'");
}

TEST(CliInputErrors, AnUnprintablePathIsEscapedByTheLastLineOfDefence) {
    // The loaders name the path as given; main.cpp escapes the whole message before printing.
    const CliRun r = run("info \"$(printf '/nonexistent/a\\033[2J\\nb.obj')\"");
    expect_printable_error(r, "/nonexistent/a\\x1B[2J\\nb.obj: cannot open file");
}

TEST(CliInputErrors, AMalformedPngIsOneLine) {
    const std::string path = std::string(PATCHCULL_SOURCE_DIR) + "/fuzz/corpus/png/truncated_in_idat.png";
    expect_printable_error(run("cull teapot --displace " + path + " --methods frustum --views 1"),
                           "truncated_in_idat.png: cannot read image: truncated PNG chunk");
}
