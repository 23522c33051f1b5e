// Strict OBJ reader: accepted forms, and one-line file:line errors for every malformed input.
#include <gtest/gtest.h>

#include <chrono>
#include <sstream>

#include "patchcull/core/error.h"
#include "patchcull/import/obj.h"

using namespace patchcull;

namespace {

ControlMesh parse(const std::string& text) {
    std::istringstream in(text);
    return parse_obj(in, "mesh.obj");
}

std::string error_of(const std::string& text) {
    try {
        parse(text);
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

}  // namespace

TEST(Obj, ReadsQuadWithTexcoordsAndNegativeIndices) {
    const ControlMesh m = parse(
        "# comment\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
        "vn 0 0 1\ng group\ns 1\nf -4/-4/1 -3/-3/1 -2/-2/1 -1/-1/1\n");
    ASSERT_EQ(m.positions.size(), 4u);
    ASSERT_EQ(m.face_count(), 1u);
    EXPECT_EQ(m.face_size(0), 4u);
    EXPECT_TRUE(m.has_texcoords());
    EXPECT_EQ(m.face_vertices, (std::vector<std::uint32_t>{0, 1, 2, 3}));
    EXPECT_EQ(m.face_texcoords, (std::vector<std::uint32_t>{0, 1, 2, 3}));
    EXPECT_TRUE(m.all_quads());
}

TEST(Obj, ReadsMixedPolygonsWithoutTexcoords) {
    const ControlMesh m =
        parse("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nvn 0 0 1\nf 1 2 3 4\nf 2 5 3\nf 1//1 2//1 3//1\n");
    EXPECT_EQ(m.face_count(), 3u);
    EXPECT_FALSE(m.has_texcoords());
    EXPECT_FALSE(m.all_quads());
}

TEST(Obj, DropsTexcoordsWhenOnlySomeFacesHaveThemAndWarns) {
    const ControlMesh m = parse("v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nf 1/1 2/1 3/1\nf 1 3 2\n");
    EXPECT_FALSE(m.has_texcoords());
    ASSERT_EQ(m.warnings.size(), 1u);
}

TEST(Obj, ReadsCreaseAndCornerTags) {
    const ControlMesh m =
        parse("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nt crease 2/1/0 0 1 2.5\nt corner 1/1/0 3 10\n");
    ASSERT_EQ(m.creases.size(), 1u);
    EXPECT_EQ(m.creases[0].v0, 0u);
    EXPECT_EQ(m.creases[0].v1, 1u);
    EXPECT_FLOAT_EQ(m.creases[0].sharpness, 2.5f);
    ASSERT_EQ(m.corners.size(), 1u);
    EXPECT_EQ(m.corners[0].v0, 3u);
}

TEST(Obj, MalformedNumberNamesFileAndLine) {
    EXPECT_EQ(error_of("v 0 0 0\nv 1 abc 0\n"), "mesh.obj:2: malformed number 'abc'");
}

TEST(Obj, NonFiniteCoordinatesAreErrors) {
    EXPECT_EQ(error_of("v 0 0 0\nv nan 0 0\n"), "mesh.obj:2: non-finite coordinate 'nan'");
    EXPECT_EQ(error_of("v inf 0 0\n"), "mesh.obj:1: non-finite coordinate 'inf'");
    EXPECT_EQ(error_of("v 1e999 0 0\n"), "mesh.obj:1: number out of range '1e999'");
    EXPECT_EQ(error_of("v 0 0 0\nvt 0 -nan\n"), "mesh.obj:2: non-finite coordinate '-nan'");
}

TEST(Obj, FaceIndexOutOfRangeIsAnError) {
    EXPECT_EQ(error_of("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 4\n"), "mesh.obj:4: vertex index 4 out of range (have 3)");
    EXPECT_EQ(error_of("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 0\n"), "mesh.obj:4: vertex index 0 out of range (have 3)");
    EXPECT_EQ(error_of("v 0 0 0\nv 1 0 0\nv 1 1 0\nf -4 1 2\n"), "mesh.obj:4: vertex index -4 out of range (have 3)");
    EXPECT_EQ(error_of("v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nf 1/1 2/2 3/1\n"),
              "mesh.obj:5: texture coordinate index 2 out of range (have 1)");
}

TEST(Obj, OtherMalformedLines) {
    EXPECT_EQ(error_of("v 0 0\n"),
              "mesh.obj:1: vertex has 2 values; expected 3 (x y z), 4 (x y z w), 6 (x y z r g b) or 7 (x y z r g b a)");
    EXPECT_EQ(error_of("v 0 0 0\nv 1 0 0\nf 1 2\n"), "mesh.obj:3: face needs at least 3 vertices");
    EXPECT_EQ(error_of("v 0 0 0\nv 1 0 0\nf 1 2 1\n"), "mesh.obj:3: face uses vertex 1 twice");
    EXPECT_EQ(error_of("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 x 3\n"), "mesh.obj:4: malformed vertex index 'x'");
    EXPECT_EQ(error_of("hello world\n"), "mesh.obj:1: unknown record 'hello'");
    EXPECT_EQ(error_of("v 0 0 0\n"), "mesh.obj: no faces");
    EXPECT_EQ(error_of("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nt crease 2/1/0 0 7 1\n"),
              "mesh.obj:5: tag vertex index 7 out of range (0-based; have 3 vertices so far)");
}

TEST(Obj, MissingFileNamesThePath) {
    try {
        load_obj("/nonexistent/dir/model.obj");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "/nonexistent/dir/model.obj: cannot open file");
    }
}

TEST(Obj, LoadsShippedModels) {
    const ControlMesh bigguy = load_obj(std::string(PATCHCULL_SOURCE_DIR) + "/data/models/bigguy.obj");
    EXPECT_EQ(bigguy.positions.size(), 1452u);
    EXPECT_EQ(bigguy.face_count(), 1450u);
    EXPECT_TRUE(bigguy.all_quads());
    EXPECT_TRUE(bigguy.has_texcoords());
    const ControlMesh frog = load_obj(std::string(PATCHCULL_SOURCE_DIR) + "/data/models/monsterfrog.obj");
    EXPECT_EQ(frog.positions.size(), 1308u);
    EXPECT_EQ(frog.face_count(), 1292u);
    EXPECT_TRUE(frog.all_quads());
}

TEST(Obj, AcceptsVertexColoursAndPointRecords) {
    const ControlMesh m = parse("v 0 0 0 0.5 0.4 0.3\nv 1 0 0 1 1 1 1\nv 1 1 0 1.0\np 1 2\nl 1 2\nf 1 2 3\n");
    EXPECT_EQ(m.positions.size(), 3u);
    EXPECT_EQ(m.positions[1].x, 1.0f);
    EXPECT_EQ(m.face_count(), 1u);
    EXPECT_EQ(error_of("v 0 0 0 1 nan 1\n"), "mesh.obj:1: non-finite coordinate 'nan'");
    // The count as found, not the minimum.
    EXPECT_EQ(error_of("v 0 0 0 1 7\n"),
              "mesh.obj:1: vertex has 5 values; expected 3 (x y z), 4 (x y z w), 6 (x y z r g b) or 7 (x y z r g b a)");
    EXPECT_EQ(error_of("v\n"),
              "mesh.obj:1: vertex has 0 values; expected 3 (x y z), 4 (x y z w), 6 (x y z r g b) or 7 (x y z r g b a)");
}

namespace {
const char* kQuad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
}  // namespace

TEST(Obj, NormalIndicesAreChecked) {
    // Normals are dropped, but a corner naming one that does not exist is a broken file.
    EXPECT_EQ(error_of("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//999999999\n"),
              "mesh.obj:5: normal index 999999999 out of range (have 1)");
    EXPECT_EQ(error_of("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1/abc 2/1/1 3/1/1\n"),
              "mesh.obj:5: malformed normal index 'abc'");
    EXPECT_EQ(error_of("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n"),
              "mesh.obj:4: normal index 1 out of range (have 0)");
    EXPECT_EQ(error_of("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//-2 2//1 3//1\n"),
              "mesh.obj:5: normal index -2 out of range (have 1)");
    const ControlMesh m = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nvn 0 1 0\nf 1/1/1 2/1/-1 3/-1/2\n");
    EXPECT_EQ(m.face_count(), 1u);
    EXPECT_TRUE(m.has_texcoords());
}

TEST(Obj, MalformedFaceCornersAreErrors) {
    const std::string prefix = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n";
    const std::string expected = " (expected v, v/vt, v//vn or v/vt/vn)";
    EXPECT_EQ(error_of(prefix + "f 1/ 2/ 3/\n"), "mesh.obj:6: malformed face corner '1/'" + expected);
    EXPECT_EQ(error_of(prefix + "f 1// 2 3\n"), "mesh.obj:6: malformed face corner '1//'" + expected);
    EXPECT_EQ(error_of(prefix + "f 1/1/1/1 2 3\n"), "mesh.obj:6: malformed face corner '1/1/1/1'" + expected);
    EXPECT_EQ(error_of(prefix + "f /1 2 3\n"), "mesh.obj:6: malformed face corner '/1'" + expected);
    EXPECT_EQ(error_of(prefix + "f 1/x 2 3\n"), "mesh.obj:6: malformed texture index 'x'");
}

TEST(Obj, UnknownAndUnsupportedTagsAreErrors) {
    // A misspelt crease used to be ignored: the crease the user asked for silently vanished.
    EXPECT_EQ(error_of(std::string(kQuad) + "t creese 2/1/0 0 1 10\n"),
              "mesh.obj:6: unknown tag 'creese' (expected crease, corner, hole, interpolateboundary, creasemethod, "
              "smoothtriangles, facevaryinginterpolateboundary or facevaryingpropagatecorners)");
    // Hierarchical edits were OpenSubdiv 2's; OpenSubdiv 3 has none.
    EXPECT_EQ(error_of(std::string(kQuad) + "t vertexedit 1/0/0 0\n"),
              "mesh.obj:6: unsupported tag 'vertexedit' (hierarchical edits are not part of OpenSubdiv 3)");
    EXPECT_EQ(error_of(std::string(kQuad) + "t crease\n"),
              "mesh.obj:6: malformed tag line (expected 't NAME ints/floats/strings arguments...', e.g. 't crease "
              "2/1/0 v0 v1 sharpness')");
}

TEST(Obj, TagArgumentCountsAreChecked) {
    const std::string q = kQuad;
    EXPECT_EQ(error_of(q + "t crease 2/1/0 0 1\n"),
              "mesh.obj:6: malformed 'crease' tag: 2 arguments for counts '2/1/0'");
    EXPECT_EQ(error_of(q + "t crease 2/1/0 0 1 2 3\n"),
              "mesh.obj:6: malformed 'crease' tag: 4 arguments for counts '2/1/0'");
    EXPECT_EQ(error_of(q + "t crease 3/1/0 0 1 2 1\n"),
              "mesh.obj:6: 'crease' tag over an odd number of vertices (3): OpenSubdiv's shape format lists a crease's "
              "edges as vertex pairs");
    EXPECT_EQ(error_of(q + "t crease 2/2/0 0 1 1 1\n"),
              "mesh.obj:6: 'crease' tag with 2 sharpness values: give one for all its edges, or one tag per edge");
    EXPECT_EQ(
        error_of(q + "t crease 2/1/1 0 1 1 x\n"),
        "mesh.obj:6: malformed 'crease' tag: expected 't crease 2/1/0 v0 v1 sharpness' (or n/1/0 with n vertices, "
        "read as n/2 edges)");
    EXPECT_EQ(error_of(q + "t crease 2/1 0 1 1\n"), "mesh.obj:6: malformed tag argument counts '2/1'");
    EXPECT_EQ(error_of(q + "t crease 2/1/0/0 0 1 1\n"), "mesh.obj:6: malformed tag argument counts '2/1/0/0'");
    EXPECT_EQ(error_of(q + "t crease 2/-1/0 0 1 1\n"), "mesh.obj:6: malformed tag argument counts '2/-1/0'");
    EXPECT_EQ(
        error_of(q + "t corner 9223372036854775807/9223372036854775807/0 0 1\n"),
        "mesh.obj:6: malformed 'corner' tag: 2 arguments for counts '9223372036854775807/9223372036854775807/'...");
    EXPECT_EQ(
        error_of(q + "t corner 0/1/0 1\n"),
        "mesh.obj:6: malformed 'corner' tag: expected 't corner 1/1/0 v sharpness' (or n/1/0 or n/n/0 for n vertices)");
    EXPECT_EQ(error_of(q + "t crease 2/1/0 0 1 -1\n"), "mesh.obj:6: negative sharpness '-1'");
    // A sharpness is not a coordinate.
    EXPECT_EQ(error_of(q + "t crease 2/1/0 0 1 nan\n"), "mesh.obj:6: non-finite sharpness 'nan'");
    EXPECT_EQ(error_of(q + "t corner 1/1/0 0 inf\n"), "mesh.obj:6: non-finite sharpness 'inf'");
}

TEST(Obj, CreaseFromAVertexToItselfIsAnError) {
    EXPECT_EQ(error_of(std::string(kQuad) + "t crease 2/1/0 2 2 1\n"),
              "mesh.obj:6: crease from vertex 2 to itself (0-based)");
}

TEST(Obj, CornerTagsWithSeveralVertices) {
    const ControlMesh m = parse(std::string(kQuad) + "t corner 2/1/0 0 2 10\nt corner 2/2/0 1 3 0.5 2\n");
    ASSERT_EQ(m.corners.size(), 4u);
    EXPECT_EQ(m.corners[1].v0, 2u);
    EXPECT_FLOAT_EQ(m.corners[1].sharpness, 10.0f);
    EXPECT_EQ(m.corners[3].v0, 3u);
    EXPECT_FLOAT_EQ(m.corners[3].sharpness, 2.0f);
    EXPECT_EQ(
        error_of(std::string(kQuad) + "t corner 2/3/0 0 1 1 1 1\n"),
        "mesh.obj:6: malformed 'corner' tag: expected 't corner 1/1/0 v sharpness' (or n/1/0 or n/n/0 for n vertices)");
}

TEST(Obj, AcceptsAUtf8ByteOrderMark) {
    const ControlMesh m = parse("\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    EXPECT_EQ(m.positions.size(), 3u);
    EXPECT_EQ(m.face_count(), 1u);
    // Only at the start of the file: elsewhere it is an invisible character, shown escaped.
    EXPECT_EQ(error_of("v 0 0 0\n\xEF\xBB\xBFv 1 0 0\n"), "mesh.obj:2: unknown record '\\uFEFFv'");
}

TEST(Obj, ErrorsQuoteInputEscapedAndShort) {
    EXPECT_EQ(error_of("v 0 \x1B[2J 0\n"), "mesh.obj:1: malformed number '\\x1B[2J'");
    EXPECT_EQ(error_of("v 0 0 0\x01\n"), "mesh.obj:1: malformed number '0\\x01'");
    EXPECT_EQ(error_of("\xFF\xFE\n"), "mesh.obj:1: unknown record '\\xFF\\xFE'");
    // A token of a megabyte (no newline in sight) is quoted by its first few dozen bytes only.
    const std::string message = error_of("v 0 0 " + std::string(1 << 20, '7') + "\n");
    EXPECT_EQ(message, "mesh.obj:1: number out of range '" + std::string(40, '7') + "'...");
}

TEST(Obj, HugeFacesCostNLogN) {
    // A face of 400000 corners: the repeated-vertex check used to compare every pair (8e10
    // comparisons, minutes); sorted it takes milliseconds.
    const int n = 400000;
    std::string text;
    for (int i = 0; i < n; ++i) text += "v " + std::to_string(i) + " 0 0\n";
    text += "f";
    for (int i = 1; i <= n; ++i) {  // += twice: GCC 12 warns falsely (-Wrestrict) on " " + std::string
        text += ' ';
        text += std::to_string(i);
    }
    text += "\n";
    const auto start = std::chrono::steady_clock::now();
    const ControlMesh m = parse(text);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(m.face_size(0), static_cast<std::uint32_t>(n));
    EXPECT_LT(seconds, 5.0);
    text.back() = ' ';  // the same face, with vertex 17 once more
    text += "17\n";
    EXPECT_EQ(error_of(text), "mesh.obj:400001: face uses vertex 17 twice");
}
