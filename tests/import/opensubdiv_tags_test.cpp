// OpenSubdiv's shape tags in OBJ files (patchcull/import/obj.h): how they are read, what each scheme
// makes of them (holes and boundary interpolation must leave out the same faces with acc as Far
// leaves out with osd), OpenSubdiv's own regression shapes (tests/data/opensubdiv), and the
// topology errors both schemes word alike.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/import/model_loader.h"
#include "patchcull/import/obj.h"
#include "patchcull/import/subdivision.h"

using namespace patchcull;

namespace {

ControlMesh parse(const std::string& text, const std::string& name = "tags.obj") {
    std::istringstream in(text);
    return parse_obj(in, name);
}

std::string parse_error(const std::string& text) {
    try {
        parse(text);
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

std::string build_error(const ControlMesh& mesh, Scheme scheme) {
    try {
        build_model(mesh, scheme);
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

std::string shape(const std::string& name) {
    return std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/opensubdiv/" + name + ".obj";
}

// An n x n grid of quads in the z = 0 plane as OBJ text: vertex (i, j) is OBJ vertex
// 1 + j (n+1) + i, face (i, j) is face j n + i (0-based, as tags count), on line (n+1)^2 + 1 + j n + i.
std::string grid_obj(int n) {
    std::string text;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i)
            text += "v " + std::to_string(i) + " " + std::to_string(j) + " " +
                    std::to_string((i * 7 + j * 3) % 5 * 0.1) + "\n";
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const int a = 1 + j * (n + 1) + i;
            text += "f " + std::to_string(a) + " " + std::to_string(a + 1) + " " + std::to_string(a + n + 2) + " " +
                    std::to_string(a + n + 1) + "\n";
        }
    return text;
}

// An open tube: `around` x `rows` quads, no boundary vertex with a single face (no corner).
std::string tube_obj(int around, int rows) {
    std::string text;
    for (int j = 0; j <= rows; ++j)
        for (int i = 0; i < around; ++i) {
            const double a = 6.283185307179586 * i / around;
            text +=
                "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " " + std::to_string(j) + "\n";
        }
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < around; ++i) {
            const int a = 1 + j * around + i, b = 1 + j * around + (i + 1) % around;
            text += "f " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(b + around) + " " +
                    std::to_string(a + around) + "\n";
        }
    return text;
}

std::set<std::uint32_t> base_faces(const SubdivisionModel& model) {
    std::set<std::uint32_t> faces;
    for (const PatchInfo& p : model.patches) faces.insert(p.base_face);
    return faces;
}

bool same_stencils(const PointStencils& a, const PointStencils& b) {
    return a.offsets == b.offsets && a.indices == b.indices && a.weights == b.weights;
}

}  // namespace

// ---- reading -----------------------------------------------------------------------------------

TEST(ObjTags, ReadsTheSubdivisionOptions) {
    const std::string grid = grid_obj(2);  // 9 vertices, 4 faces: lines 1..13
    const ControlMesh plain = parse(grid);
    EXPECT_EQ(plain.options.boundary, BoundaryInterpolation::edge_and_corner);
    EXPECT_FALSE(plain.options.chaikin_creases);
    EXPECT_FALSE(plain.options.smooth_triangles);
    EXPECT_TRUE(plain.holes.empty());

    // OpenSubdiv's shape reader: 0 none, 1 edges and corners, 2 edges only.
    EXPECT_EQ(parse(grid + "t interpolateboundary 1/0/0 0\n").options.boundary, BoundaryInterpolation::none);
    EXPECT_EQ(parse(grid + "t interpolateboundary 1/0/0 1\n").options.boundary, BoundaryInterpolation::edge_and_corner);
    const ControlMesh edge_only = parse(grid + "# a comment\nt interpolateboundary 1/0/0 2\n");
    EXPECT_EQ(edge_only.options.boundary, BoundaryInterpolation::edge_only);
    EXPECT_EQ(edge_only.options.boundary_line, 15u);

    const ControlMesh methods = parse(grid + "t creasemethod 0/0/1 chaikin\nt smoothtriangles 0/0/1 smooth\n");
    EXPECT_TRUE(methods.options.chaikin_creases);
    EXPECT_TRUE(methods.options.smooth_triangles);
    const ControlMesh defaults = parse(grid + "t creasemethod 0/0/1 normal\nt smoothtriangles 0/0/1 catmark\n");
    EXPECT_FALSE(defaults.options.chaikin_creases);
    EXPECT_FALSE(defaults.options.smooth_triangles);

    // Face-varying options: read and checked, no effect (patchcull has no face-varying data).
    const ControlMesh fvar =
        parse(grid + "t facevaryinginterpolateboundary 1/0/0 5\nt facevaryingpropagatecorners 1/0/0 1\n");
    EXPECT_EQ(fvar.options.boundary, plain.options.boundary);
    EXPECT_EQ(fvar.face_vertices, plain.face_vertices);
    EXPECT_EQ(fvar.creases.size(), 0u);
}

TEST(ObjTags, BadOptionValuesNameTheLine) {
    const std::string grid = grid_obj(2);
    EXPECT_EQ(parse_error(grid + "t interpolateboundary 1/0/0 3\n"),
              "tags.obj:14: 'interpolateboundary' 3: expected 0 (none), 1 (edges and corners) or 2 (edges only)");
    EXPECT_EQ(parse_error(grid + "t interpolateboundary 1/0/0 1\nt interpolateboundary 1/0/0 2\n"),
              "tags.obj:15: 'interpolateboundary' tag given twice (first at line 14)");
    EXPECT_EQ(
        parse_error(grid + "t interpolateboundary 0/1/0 1\n"),
        "tags.obj:14: malformed 'interpolateboundary' tag: expected 't interpolateboundary 1/0/0 m' with m 0, 1 or 2");
    EXPECT_EQ(parse_error(grid + "t creasemethod 0/0/1 smooth\n"),
              "tags.obj:14: 'creasemethod' tag 'smooth': expected normal or chaikin");
    EXPECT_EQ(parse_error(grid + "t smoothtriangles 1/0/0 1\n"),
              "tags.obj:14: malformed 'smoothtriangles' tag: expected 't smoothtriangles 0/0/1 catmark' or 'smooth'");
    EXPECT_EQ(parse_error(grid + "t facevaryinginterpolateboundary 1/0/0 6\n"),
              "tags.obj:14: 'facevaryinginterpolateboundary' tag value 6: expected 0 to 5");
    EXPECT_EQ(parse_error(grid + "t facevaryingpropagatecorners 1/0/0 2\n"),
              "tags.obj:14: 'facevaryingpropagatecorners' tag value 2: expected 0 or 1");
    EXPECT_EQ(parse_error(grid + "t hole 1/0/0 4\n"),
              "tags.obj:14: hole tag names face 4 (0-based); the file has 4 faces");
    EXPECT_EQ(parse_error(grid + "t hole 1/0/0 -1\n"), "tags.obj:14: hole face index -1 out of range (0-based)");
}

TEST(ObjTags, ACreaseOverSeveralEdgesIsReadAsVertexPairs) {
    // OpenSubdiv's shape reader reads "t crease 4/1/0 a b c d s" as the edges (a,b) and (c,d).
    const ControlMesh m = parse(grid_obj(2) + "t crease 4/1/0 0 1 4 5 2.5\n");
    ASSERT_EQ(m.creases.size(), 2u);
    EXPECT_EQ(m.creases[0].v0, 0u);
    EXPECT_EQ(m.creases[0].v1, 1u);
    EXPECT_EQ(m.creases[1].v0, 4u);
    EXPECT_EQ(m.creases[1].v1, 5u);
    for (const Crease& c : m.creases) {
        EXPECT_FLOAT_EQ(c.sharpness, 2.5f);
        EXPECT_EQ(c.line, 14u);
    }
    // Read as a chain, 1-4 would be a crease too; as pairs it is not, and the result is OpenSubdiv's.
    const SubdivisionModel pairs = build_model(m, Scheme::osd);
    ControlMesh two = parse(grid_obj(2) + "t crease 2/1/0 0 1 2.5\nt crease 2/1/0 4 5 2.5\n");
    EXPECT_TRUE(same_stencils(pairs.patch_points, build_model(two, Scheme::osd).patch_points));
}

TEST(ObjTags, ACreaseThatIsNoEdgeNamesItsLine) {
    // Vertices 0 and 4 (0-based) are diagonal in face 0.
    EXPECT_EQ(parse_error(grid_obj(2) + "t crease 2/1/0 0 1 1\nt crease 2/1/0 0 4 1\n"),
              "tags.obj:15: crease between vertices 0 and 4 (0-based, as tags count; OBJ vertices 1 and 5): no face "
              "has that edge");
}

// ---- holes ---------------------------------------------------------------------------------------

TEST(ObjTags, HoleFacesProduceNoPatchesWithEitherScheme) {
    const std::string grid = grid_obj(3);  // 9 faces, face 4 in the middle
    const ControlMesh holed = parse(grid + "t hole 2/0/0 4 4\nt hole 1/0/0 0\n");
    EXPECT_EQ(holed.holes, (std::vector<std::uint32_t>{0, 4}));
    const ControlMesh whole = parse(grid);
    for (const Scheme scheme : {Scheme::acc, Scheme::osd}) {
        const SubdivisionModel with = build_model(holed, scheme), without = build_model(whole, scheme);
        std::set<std::uint32_t> expected = base_faces(without);
        expected.erase(0);
        expected.erase(4);
        EXPECT_EQ(base_faces(with), expected) << scheme_name(scheme);
        EXPECT_LT(with.patch_count(), without.patch_count()) << scheme_name(scheme);
    }
    // acc: the other patches are those of the whole mesh (a hole still shapes its neighbours).
    const SubdivisionModel acc_with = build_model(holed, Scheme::acc), acc_without = build_model(whole, Scheme::acc);
    for (std::size_t p = 0, q = 0; p < acc_without.patch_count(); ++p) {
        const std::uint32_t f = acc_without.patches[p].base_face;
        if (f == 0 || f == 4) continue;
        for (int k = 0; k < 16; ++k) {
            const std::size_t r = 16 * p + k, s = 16 * q + k;
            const auto row = [](const PointStencils& t, std::size_t i) {
                return std::vector<float>(t.weights.begin() + t.offsets[i], t.weights.begin() + t.offsets[i + 1]);
            };
            EXPECT_EQ(row(acc_with.patch_points, s), row(acc_without.patch_points, r)) << "patch of face " << f;
        }
        ++q;
    }
    // Every face a hole: no surface, one line.
    ControlMesh all = parse(grid_obj(1) + "t hole 1/0/0 0\n");
    for (const Scheme scheme : {Scheme::acc, Scheme::osd})
        EXPECT_EQ(build_error(all, scheme),
                  "tags.obj: every face is a hole or at an uninterpolated boundary: no surface");
}

TEST(ObjTags, AHoleOpensAClosedSolid) {
    // OpenSubdiv's catmark_hole_test1: a cube with one face tagged as a hole. Through the hole the
    // inside shows: two-sided, no back-patch culling.
    const LoadedModel holed = load_model(shape("catmark_hole_test1"), Scheme::osd, 0);
    EXPECT_FALSE(holed.closed);
    // The same cube without its hole tag is a closed solid.
    const std::string path = ::testing::TempDir() + "/cube_without_hole.obj";
    {
        std::ifstream in(shape("catmark_hole_test1"));
        std::ofstream out(path);
        for (std::string line; std::getline(in, line);)
            if (!line.starts_with("t hole")) out << line << "\n";
    }
    for (const Scheme scheme : {Scheme::acc, Scheme::osd}) {
        EXPECT_TRUE(load_model(path, scheme, 0).closed) << scheme_name(scheme);
        EXPECT_FALSE(load_model(shape("catmark_hole_test1"), scheme, 0).closed) << scheme_name(scheme);
    }
}

// ---- boundary interpolation ------------------------------------------------------------------------

TEST(ObjTags, NoBoundaryInterpolationLeavesTheSameFacesOutWithBothSchemes) {
    // Far makes every face at a boundary vertex a hole; acc must leave out the same faces.
    const ControlMesh none = parse(grid_obj(4) + "t interpolateboundary 1/0/0 0\n");
    const std::set<std::uint32_t> acc = base_faces(build_model(none, Scheme::acc));
    const std::set<std::uint32_t> osd = base_faces(build_model(none, Scheme::osd));
    EXPECT_EQ(acc, osd);
    // Face (i, j) of the 4x4 grid is face 4 j + i; it touches the boundary unless i and j are 1 or 2.
    EXPECT_EQ(acc, (std::set<std::uint32_t>{5, 6, 9, 10}));

    // With a non-quad face acc goes through one OpenSubdiv refinement first: still the same faces.
    // Face 5 split into two triangles (faces 5 and 6; the faces after it move up by one).
    std::istringstream lines(grid_obj(4));
    std::string split;
    const auto add_face = [&split](std::initializer_list<std::string_view> corners) {
        split += 'f';
        for (std::string_view c : corners) (split += ' ') += c;
        split += '\n';
    };
    int face = 0;
    for (std::string line; std::getline(lines, line);) {
        if (line.starts_with("f ") && face++ == 5) {
            std::istringstream corners(line.substr(2));
            std::string a, b, c, d;
            corners >> a >> b >> c >> d;
            add_face({a, b, c});
            add_face({a, c, d});
        } else {
            split += line + "\n";
        }
    }
    const ControlMesh mixed = parse(split + "t interpolateboundary 1/0/0 0\n");
    ASSERT_FALSE(mixed.all_quads());
    const std::set<std::uint32_t> acc_mixed = base_faces(build_model(mixed, Scheme::acc));
    EXPECT_EQ(acc_mixed, base_faces(build_model(mixed, Scheme::osd)));
    EXPECT_EQ(acc_mixed, (std::set<std::uint32_t>{5, 6, 7, 10, 11}));

    // Creases sharpening every boundary edge infinitely keep the boundary faces in Far (crease
    // rules acc ignores): acc refuses, naming the tag's line and the osd scheme.
    std::string sharp = grid_obj(2) + "t interpolateboundary 1/0/0 0\n";
    for (const auto& [a, b] :
         std::vector<std::pair<int, int>>{{0, 1}, {1, 2}, {2, 5}, {5, 8}, {8, 7}, {7, 6}, {6, 3}, {3, 0}})
        sharp += "t crease 2/1/0 " + std::to_string(a) + " " + std::to_string(b) + " 10\n";
    const ControlMesh sharpened = parse(sharp);
    EXPECT_EQ(base_faces(build_model(sharpened, Scheme::osd)).size(), 4u);
    const std::string e = build_error(sharpened, Scheme::acc);
    EXPECT_EQ(e.rfind("tags.obj:14: ", 0), 0u) << e;
    EXPECT_NE(e.find("osd scheme"), std::string::npos) << e;
}

TEST(ObjTags, EdgesOnlyBoundariesAreHonouredOrRefused) {
    // A grid has corners: Far rounds them off under edges-only, so its patches change; acc keeps
    // corners sharp and refuses, naming the line and the osd scheme.
    const std::string grid = grid_obj(2);
    const ControlMesh corner = parse(grid), smooth = parse(grid + "t interpolateboundary 1/0/0 2\n");
    EXPECT_FALSE(
        same_stencils(build_model(corner, Scheme::osd).patch_points, build_model(smooth, Scheme::osd).patch_points));
    const std::string e = build_error(smooth, Scheme::acc);
    EXPECT_EQ(e.rfind("tags.obj:14: ", 0), 0u) << e;
    EXPECT_NE(e.find("osd scheme"), std::string::npos) << e;
    // A tube has no corner: edges-only is the same surface as edges-and-corners, in both schemes.
    const std::string tube = tube_obj(6, 2);
    const ControlMesh tube_default = parse(tube), tube_edges = parse(tube + "t interpolateboundary 1/0/0 2\n");
    for (const Scheme scheme : {Scheme::acc, Scheme::osd})
        EXPECT_TRUE(
            same_stencils(build_model(tube_default, scheme).patch_points, build_model(tube_edges, scheme).patch_points))
            << scheme_name(scheme);
}

TEST(ObjTags, CreaseMethodAndTriangleRuleReachOpenSubdiv) {
    // catmark_chaikin1 says "creasemethod chaikin"; catmark_smoothtris1 "smoothtriangles smooth".
    ControlMesh chaikin = load_obj(shape("catmark_chaikin1"));
    ASSERT_TRUE(chaikin.options.chaikin_creases);
    ControlMesh uniform = chaikin;
    uniform.options.chaikin_creases = false;
    EXPECT_FALSE(
        same_stencils(build_model(chaikin, Scheme::osd).patch_points, build_model(uniform, Scheme::osd).patch_points));

    ControlMesh smooth = load_obj(shape("catmark_smoothtris1"));
    ASSERT_TRUE(smooth.options.smooth_triangles);
    ControlMesh catmark = smooth;
    catmark.options.smooth_triangles = false;
    // Both schemes: acc takes triangles through one OpenSubdiv refinement, which applies the rule.
    for (const Scheme scheme : {Scheme::acc, Scheme::osd})
        EXPECT_FALSE(same_stencils(build_model(smooth, scheme).patch_points, build_model(catmark, scheme).patch_points))
            << scheme_name(scheme);
}

// ---- OpenSubdiv's regression shapes -----------------------------------------------------------

TEST(OpenSubdivShapes, LoadWithOsdAndWithAccWhereAccCanHonourTheirTags) {
    for (const char* name : {"catmark_helmet", "catmark_hole_test1", "catmark_hole_test2", "catmark_edgeonly",
                             "catmark_edgenone", "catmark_chaikin1", "catmark_cubes_infsharp", "catmark_smoothtris1"}) {
        SCOPED_TRACE(name);
        const ControlMesh mesh = load_obj(shape(name));
        const SubdivisionModel osd = build_model(mesh, Scheme::osd);
        EXPECT_GT(osd.patch_count(), 0u);
        for (const PatchInfo& p : osd.patches)
            EXPECT_FALSE(std::binary_search(mesh.holes.begin(), mesh.holes.end(), p.base_face));
        try {
            const SubdivisionModel acc = build_model(mesh, Scheme::acc);
            // Whatever acc makes of the tags, it leaves out the faces Far leaves out.
            EXPECT_EQ(base_faces(acc), base_faces(osd));
        } catch (const Error& e) {
            // Only a boundary rule acc cannot follow: one line naming the tag's line and osd.
            const std::string what = e.what();
            EXPECT_NE(mesh.options.boundary, BoundaryInterpolation::edge_and_corner) << what;
            EXPECT_EQ(what.rfind(shape(name) + ":" + std::to_string(mesh.options.boundary_line) + ": ", 0), 0u) << what;
            EXPECT_NE(what.find("osd scheme"), std::string::npos) << what;
        }
    }
    // The helmet, the shape the OBJ reader used to refuse, loads with both.
    EXPECT_GT(build_model(load_obj(shape("catmark_helmet")), Scheme::acc).patch_count(), 0u);
}

// ---- topology errors: the same words, 1-based vertices and the line, in both schemes ----------

TEST(ObjTags, NonManifoldErrorsAreWordedAlikeByBothSchemes) {
    const std::string p8 = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 1 -1 0\nv 0 -1 0\nv 1 0 1\nv 0 0 1\n";
    struct Case {
        std::string name, text, expected;
    };
    const std::vector<Case> cases = {
        {"fin.obj", p8 + "f 1 2 3 4\nf 2 1 6 5\nf 1 2 7 8\n",
         "fin.obj:11: non-manifold edge between vertices 1 and 2: 3 faces share it"},
        {"flip.obj", p8 + "f 1 2 3 4\nf 1 2 5 6\n",
         "flip.obj:10: non-manifold edge between vertices 1 and 2: this face and the one at line 9 run along it in the "
         "same direction (oriented inconsistently)"},
        {"bowtie.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv -1 0 0\nv -1 -1 0\nv 0 -1 0\nf 1 2 3 4\nf 1 5 6 7\n",
         "bowtie.obj:8: non-manifold vertex 1: its faces do not form a single fan"},
        // Triangles: acc refines them through OpenSubdiv first, which checks the same way.
        {"trifin.obj", p8 + "f 1 2 3\nf 2 1 6\nf 1 2 7\n",
         "trifin.obj:11: non-manifold edge between vertices 1 and 2: 3 faces share it"},
    };
    for (const Case& c : cases) {
        const ControlMesh mesh = parse(c.text, c.name);
        EXPECT_EQ(build_error(mesh, Scheme::acc), c.expected);
        EXPECT_EQ(build_error(mesh, Scheme::osd), c.expected);
    }
}
