// Bad input through the CLI: whatever bytes a model, an image or a path holds, the user sees one
// printable line of bounded length and exit status 2 (tools/main.cpp, patchcull/core/error.h).
#include "cli_test_util.h"

#include "patchcull/core/error.h"

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
    const std::string path =
        write_file("tag.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nt creese 2/1/0 0 1 10\n");
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

TEST(CliInputErrors, ARepeatedOptionSaysWhichAndThatItMayBeGivenOnce) {
    // CLI11 alone said "At Most 1 required but received 2"; parsing fails before any work.
    expect_printable_error(run("render default --frames 2 --frames 3"),
                           "patchcull: error: --frames may be given once (given 2 times)");
    expect_printable_error(run("cull teapot --views 1 --views 2 --views 3"),
                           "patchcull: error: --views may be given once (given 3 times)");
    expect_printable_error(run("info teapot --scheme acc --scheme osd"),
                           "patchcull: error: --scheme may be given once (given 2 times)");
}

TEST(CliInputErrors, AVertexRecordSaysHowManyValuesItHas) {
    const std::string path = write_file("five.obj", "v 0 0 0\nv 0 0 0 1 7\n");
    expect_printable_error(run("info " + path), "five.obj:2: vertex has 5 values; expected 3 (x y z), 4 (x y z w)");
}

TEST(CliInputErrors, ABadSharpnessIsCalledASharpness) {
    const std::string path =
        write_file("sharp.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nt crease 2/1/0 0 1 nan\n");
    expect_printable_error(run("info " + path), "sharp.obj:6: non-finite sharpness 'nan'");
}

TEST(CliInputErrors, NonManifoldEdgesGiveOneBasedVerticesAndTheLineWithBothSchemes) {
    const std::string path = write_file("fin.obj",
                                        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 1 -1 0\nv 0 -1 0\nv 1 0 1\n"
                                        "v 0 0 1\nf 1 2 3 4\nf 2 1 6 5\nf 1 2 7 8\n");
    for (const char* scheme : {"acc", "osd"})
        expect_printable_error(run("info " + path + " --scheme " + scheme),
                               "fin.obj:11: non-manifold edge between vertices 1 and 2: 3 faces share it");
}

TEST(CliInputErrors, ACorruptPngSaysWhatIsWrongWithIt) {
    // A PNG whose IHDR is fine and whose compressed pixel data is not.
    std::string png("\x89PNG\r\n\x1A\n", 8);
    const auto chunk = [&png](const std::string& type, const std::string& body) {
        for (int shift = 24; shift >= 0; shift -= 8) png += static_cast<char>(body.size() >> shift & 0xFF);
        png += type + body + std::string(4, '\0');
    };
    chunk("IHDR", std::string("\0\0\0\x04\0\0\0\x04\x08\0\0\0\0", 13));
    chunk("IDAT", std::string("\x78\x9C\xFD\xFF\xFF\xFF\xFF\xFF\xFF\xFF\xFF\xFF", 12) + std::string(16, '\xFF'));
    chunk("IEND", "");
    const std::string path = write_file("damaged.png", png);
    expect_printable_error(run("cull teapot --displace " + path + " --methods frustum --views 1"),
                           "damaged.png: cannot read image: corrupt PNG: its compressed pixel data");
}
