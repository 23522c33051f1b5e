// Orientation from geometry (patchcull/core/mesh.h): the signed volume of closed control meshes, and
// orient_outward reversing inside-out ones, so that back-patch culling and one-sided drawing use
// the side that faces out (topology alone cannot tell inside from outside).
// Meshes of several shells are oriented shell by shell, by nesting parity.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "patchcull/core/mesh.h"

namespace patchcull {
namespace {

// An axis-aligned box [0,a] x [0,b] x [0,c] + offset, faces counter-clockwise seen from outside.
ControlMesh box(float a, float b, float c, Vec3 offset = {}) {
    ControlMesh m;
    m.name = "box";
    for (int i = 0; i < 8; ++i)
        m.positions.push_back({offset.x + (i & 1 ? a : 0), offset.y + (i & 2 ? b : 0), offset.z + (i & 4 ? c : 0)});
    const std::uint32_t faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                       {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& f : faces) {
        for (std::uint32_t v : f) m.face_vertices.push_back(v);
        m.face_offsets.push_back(static_cast<std::uint32_t>(m.face_vertices.size()));
    }
    return m;
}

TEST(Orientation, SignedVolumeOfABox) {
    const ControlMesh m = box(2, 3, 4);
    ASSERT_TRUE(m.is_closed());
    EXPECT_DOUBLE_EQ(m.signed_volume(), 24.0);
    EXPECT_EQ(classify_orientation(m), SurfaceOrientation::outward);
}

TEST(Orientation, ReversedAndMirroredBoxesAreInward) {
    ControlMesh reversed = box(2, 3, 4);
    reversed.reverse_faces();
    EXPECT_TRUE(reversed.is_closed());  // topology cannot tell
    EXPECT_DOUBLE_EQ(reversed.signed_volume(), -24.0);
    EXPECT_EQ(classify_orientation(reversed), SurfaceOrientation::inward);

    ControlMesh mirrored = box(2, 3, 4);
    for (Vec3& p : mirrored.positions) p.x = -p.x;
    EXPECT_EQ(classify_orientation(mirrored), SurfaceOrientation::inward);

    EXPECT_EQ(orient_outward(mirrored), SurfaceOrientation::outward);
    EXPECT_DOUBLE_EQ(mirrored.signed_volume(), 24.0);
    ASSERT_EQ(mirrored.warnings.size(), 1u);
    EXPECT_NE(mirrored.warnings[0].find("oriented inward"), std::string::npos);
}

TEST(Orientation, FarFromTheOriginTheSignStays) {
    // Relative coordinates: 1e6 away a float spacing is 1/16, the box still has its volume.
    const ControlMesh far = box(2, 3, 4, {1e6f, -1e6f, 1e6f});
    EXPECT_NEAR(far.signed_volume(), 24.0, 1e-9);
    EXPECT_EQ(classify_orientation(far), SurfaceOrientation::outward);
}

TEST(Orientation, FlatAndOpenMeshesAreNotSolids) {
    ControlMesh flat = box(2, 3, 0);
    EXPECT_EQ(classify_orientation(flat), SurfaceOrientation::flat);
    EXPECT_EQ(orient_outward(flat), SurfaceOrientation::flat);
    EXPECT_EQ(flat.warnings.size(), 1u);

    ControlMesh open = box(2, 3, 4);
    open.face_vertices.resize(open.face_vertices.size() - 4);  // drop the last face
    open.face_offsets.pop_back();
    EXPECT_EQ(classify_orientation(open), SurfaceOrientation::open);
    EXPECT_EQ(orient_outward(open), SurfaceOrientation::open);
    EXPECT_TRUE(open.warnings.empty());
}

TEST(Orientation, ThinSolidsKeepTheirOrientation) {
    // A plate 1e-5 as thick as it is wide, and the same squashed 100 : 1 : 0.01 (the bounding-box
    // rule called both flat): real solids, oriented outward; inverted, inward.
    EXPECT_EQ(classify_orientation(box(1, 1, 1e-5f)), SurfaceOrientation::outward);
    EXPECT_EQ(classify_orientation(box(100, 1, 0.01f)), SurfaceOrientation::outward);
    ControlMesh inverted = box(100, 1, 0.01f);
    inverted.reverse_faces();
    EXPECT_EQ(classify_orientation(inverted), SurfaceOrientation::inward);
}

TEST(Orientation, ReverseFacesKeepsTexcoordsWithTheirCorners) {
    ControlMesh m = box(1, 1, 1);
    m.texcoords = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (std::size_t c = 0; c < m.face_vertices.size(); ++c)
        m.face_texcoords.push_back(static_cast<std::uint32_t>(c % 4));
    const std::vector<std::uint32_t> vertices = m.face_vertices, texcoords = m.face_texcoords;
    m.reverse_faces();
    for (std::size_t f = 0; f < m.face_count(); ++f)
        for (std::uint32_t i = 0; i < 4; ++i) {
            EXPECT_EQ(m.face_vertices[4 * f + i], vertices[4 * f + 3 - i]);
            EXPECT_EQ(m.face_texcoords[4 * f + i], texcoords[4 * f + 3 - i]);
        }
}

// ---- meshes of several shells -----------------------------------------------------------------

// A sphere: a cube of n x n quads per side pushed onto the sphere, counter-clockwise seen from
// outside (inside out when reversed), vertices shared along the cube's edges.
ControlMesh sphere(Vec3 c, float radius, bool reversed = false, int n = 3) {
    ControlMesh m;
    m.name = "sphere";
    std::vector<int> index((n + 1) * (n + 1) * (n + 1), -1);
    auto vertex = [&](const int g[3]) {
        int& i = index[(g[0] * (n + 1) + g[1]) * (n + 1) + g[2]];
        if (i < 0) {
            const Vec3 q{2.0f * g[0] / n - 1, 2.0f * g[1] / n - 1, 2.0f * g[2] / n - 1};
            i = static_cast<int>(m.positions.size());
            m.positions.push_back(c + q * (radius / length(q)));
        }
        return static_cast<std::uint32_t>(i);
    };
    for (int axis = 0; axis < 3; ++axis)
        for (int side : {0, n})
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j) {
                    std::uint32_t q[4];
                    const int corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
                    for (int k = 0; k < 4; ++k) {
                        int g[3];
                        g[axis] = side, g[(axis + 1) % 3] = i + corner[k][0], g[(axis + 2) % 3] = j + corner[k][1];
                        q[k] = vertex(g);
                    }
                    const bool flip = (side == 0) != reversed;
                    for (int k = 0; k < 4; ++k) m.face_vertices.push_back(q[flip ? 3 - k : k]);
                    m.face_offsets.push_back(static_cast<std::uint32_t>(m.face_vertices.size()));
                }
    return m;
}

// A torus around the z axis through c (radii major, minor), counter-clockwise seen from outside.
ControlMesh torus(Vec3 c, float major, float minor, bool reversed = false, int nu = 8, int nv = 4) {
    ControlMesh m;
    m.name = "torus";
    const float two_pi = 6.28318531f;
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            const float t = two_pi * float(i) / float(nu), p = two_pi * float(j) / float(nv);
            const float r = major + minor * std::cos(p);
            m.positions.push_back(c + Vec3{r * std::cos(t), r * std::sin(t), minor * std::sin(p)});
        }
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            const int i1 = (i + 1) % nu, j1 = (j + 1) % nv;
            std::uint32_t q[4] = {std::uint32_t(i * nv + j), std::uint32_t(i1 * nv + j), std::uint32_t(i1 * nv + j1),
                                  std::uint32_t(i * nv + j1)};
            for (int k = 0; k < 4; ++k) m.face_vertices.push_back(q[reversed ? 3 - k : k]);
            m.face_offsets.push_back(static_cast<std::uint32_t>(m.face_vertices.size()));
        }
    return m;
}

// The shells one after the other in one mesh (shell s: faces [first_face[s], first_face[s+1])).
struct Shells {
    ControlMesh mesh;
    std::vector<std::size_t> first_face{0};
};

Shells join(const std::vector<ControlMesh>& parts) {
    Shells out;
    out.mesh.name = "shells";
    for (const ControlMesh& part : parts) {
        const auto base = static_cast<std::uint32_t>(out.mesh.positions.size());
        out.mesh.positions.insert(out.mesh.positions.end(), part.positions.begin(), part.positions.end());
        for (std::size_t f = 0; f < part.face_count(); ++f) {
            for (std::uint32_t c = part.face_offsets[f]; c < part.face_offsets[f + 1]; ++c)
                out.mesh.face_vertices.push_back(base + part.face_vertices[c]);
            out.mesh.face_offsets.push_back(static_cast<std::uint32_t>(out.mesh.face_vertices.size()));
        }
        out.first_face.push_back(out.mesh.face_count());
    }
    return out;
}

// Signed volume of shell s of a joined mesh (its faces' fans, as ControlMesh::signed_volume).
double shell_volume(const Shells& shells, const ControlMesh& mesh, std::size_t s) {
    const Vec3 o = mesh.positions[mesh.face_vertices[mesh.face_offsets[shells.first_face[s]]]];
    auto rel = [&](std::uint32_t c) {
        const Vec3 p = mesh.positions[mesh.face_vertices[c]];
        return std::array<double, 3>{double(p.x) - o.x, double(p.y) - o.y, double(p.z) - o.z};
    };
    double six_volume = 0;
    for (std::size_t f = shells.first_face[s]; f < shells.first_face[s + 1]; ++f) {
        const auto a = rel(mesh.face_offsets[f]);
        for (std::uint32_t c = mesh.face_offsets[f] + 1; c + 1 < mesh.face_offsets[f + 1]; ++c) {
            const auto b = rel(c), d = rel(c + 1);
            six_volume += a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0]) +
                          a[2] * (b[0] * d[1] - b[1] * d[0]);
        }
    }
    return six_volume / 6;
}

// orient_outward on the joined shells: each shell's volume must then have the sign given
// (+1 bounds the solid from outside, -1 a cavity), the faces of the shells not reversed must be
// as they were, and the warning must be there exactly when something was reversed.
void expect_oriented(const std::vector<ControlMesh>& parts, const std::vector<int>& signs, const char* what) {
    SCOPED_TRACE(what);
    Shells shells = join(parts);
    ControlMesh& m = shells.mesh;
    ASSERT_TRUE(m.is_closed());
    bool needs_reversal = false;
    for (std::size_t s = 0; s < parts.size(); ++s) needs_reversal |= (shell_volume(shells, m, s) > 0) != (signs[s] > 0);
    EXPECT_EQ(classify_orientation(m), needs_reversal ? SurfaceOrientation::inward : SurfaceOrientation::outward);
    const ControlMesh before = m;
    EXPECT_EQ(orient_outward(m), SurfaceOrientation::outward);
    EXPECT_EQ(m.warnings.size(), needs_reversal ? 1u : 0u);
    for (std::size_t s = 0; s < parts.size(); ++s) {
        const double v = shell_volume(shells, m, s);
        EXPECT_GT(v * signs[s], 0) << "shell " << s << ": volume " << v;
        const bool flipped = (shell_volume(shells, before, s) > 0) != (signs[s] > 0);
        for (std::size_t f = shells.first_face[s]; f < shells.first_face[s + 1]; ++f)
            for (std::uint32_t c = m.face_offsets[f], n = m.face_size(f), i = 0; i < n; ++i)
                EXPECT_EQ(m.face_vertices[c + i], before.face_vertices[flipped ? c + n - 1 - i : c + i])
                    << "face " << f;
    }
    EXPECT_EQ(classify_orientation(m), SurfaceOrientation::outward);  // idempotent
}

TEST(OrientationShells, TwoShellsOneReversedEndUpBothOutward) {
    // Equal spheres, the second inside out: their total volume is 0 (the whole-mesh rule called
    // the pair flat, or flipped one by rounding).
    expect_oriented({sphere({-1.5f, 0, 0}, 1), sphere({1.5f, 0, 0}, 1, true)}, {+1, +1}, "equal");
    // A large sphere inside out beside a small outward one: the total is negative, and reversing
    // the whole mesh would turn the small one inside out.
    expect_oriented({sphere({-3, 0, 0}, 2, true), sphere({1, 0, 0}, 0.5f)}, {+1, +1}, "large reversed");
    ControlMesh both = join({sphere({-1.5f, 0, 0}, 1, true), sphere({1.5f, 0, 0}, 1, true)}).mesh;
    EXPECT_EQ(orient_outward(both), SurfaceOrientation::outward);
    ASSERT_EQ(both.warnings.size(), 1u);
    EXPECT_NE(both.warnings[0].find("2 of 2 closed shells oriented inward"), std::string::npos) << both.warnings[0];
    ControlMesh one = join({sphere({-1.5f, 0, 0}, 1), sphere({1.5f, 0, 0}, 1, true)}).mesh;
    orient_outward(one);
    ASSERT_EQ(one.warnings.size(), 1u);
    EXPECT_NE(one.warnings[0].find("1 of 2 closed shells oriented inward"), std::string::npos) << one.warnings[0];
}

TEST(OrientationShells, HollowSolidsCavityFacesIntoTheCavity) {
    // The cavity's wall bounds empty space inside the solid: its normals point into the cavity,
    // away from the material, i.e. negative volume, however it was written.
    for (bool outer_reversed : {false, true})
        for (bool inner_reversed : {false, true})
            expect_oriented({sphere({0, 0, 0}, 2, outer_reversed), sphere({0.3f, -0.2f, 0.1f}, 1, inner_reversed)},
                            {+1, -1},
                            outer_reversed ? (inner_reversed ? "both reversed" : "outer reversed")
                                           : (inner_reversed ? "inner reversed" : "both written outward"));
    // Order in the file does not matter, nor do several cavities.
    expect_oriented({sphere({-0.8f, 0, 0}, 0.5f), sphere({0, 0, 0}, 3), sphere({1, 0.5f, 0}, 0.4f, true)}, {-1, +1, -1},
                    "two cavities, listed around the outer shell");
    // A hollow solid far from the origin: the nesting test works in double.
    expect_oriented({sphere({1e5f, -1e5f, 1e5f}, 20), sphere({1e5f, -1e5f, 1e5f}, 10)}, {+1, -1}, "far away");
    // And its total volume is the material's.
    ControlMesh hollow = join({sphere({0, 0, 0}, 2), sphere({0, 0, 0}, 1)}).mesh;
    orient_outward(hollow);
    EXPECT_NEAR(hollow.signed_volume(),
                join({sphere({0, 0, 0}, 2)}).mesh.signed_volume() - join({sphere({0, 0, 0}, 1)}).mesh.signed_volume(),
                1e-9);
}

TEST(OrientationShells, NestedSpheresAlternateByNestingParity) {
    // Depths 0, 1, 2, 3: solid, cavity, an island in the cavity, a cavity in the island.
    const float radii[4] = {4, 3, 2, 1};
    for (int written = 0; written < 16; ++written) {  // every combination of written orientations
        std::vector<ControlMesh> parts;
        parts.reserve(4);
        for (int s = 0; s < 4; ++s)
            parts.push_back(sphere({0.05f * float(s), 0, 0}, radii[s], (written >> s & 1) != 0));
        expect_oriented(parts, {+1, -1, +1, -1}, ("written " + std::to_string(written)).c_str());
    }
    // Listed inner first.
    expect_oriented({sphere({0, 0, 0}, 1), sphere({0, 0, 0}, 2), sphere({0, 0, 0}, 3)}, {+1, -1, +1}, "inner first");
}

TEST(OrientationShells, TwoToriEndUpBothOutward) {
    // The whole-mesh rule called this pair flat (total volume 0) and drew it two-sided.
    expect_oriented({torus({-2.5f, 0, 0}, 1.5f, 0.5f), torus({2.5f, 0, 0}, 1.5f, 0.5f, true)}, {+1, +1},
                    "side by side");
    // Linked like two chain links (each through the other's hole): neither is inside the other.
    // Swapping y and z turns the second's axis along y, through the first's hole, and mirrors it:
    // inside out.
    ControlMesh link = torus({0, 0, 0}, 1.5f, 0.4f);
    for (Vec3& p : link.positions) p = {p.x + 1.5f, p.z, p.y};
    expect_oriented({torus({0, 0, 0}, 1.5f, 0.4f), link}, {+1, +1}, "linked");
    // A sphere in a torus's hole lies within its bounds but outside the solid.
    expect_oriented({torus({0, 0, 0}, 2, 0.5f, true), sphere({0, 0, 0}, 0.3f, true)}, {+1, +1}, "sphere in the hole");
    // A torus inside a sphere bounds a cavity.
    expect_oriented({sphere({0, 0, 0}, 3), torus({0, 0, 0}, 1.5f, 0.5f)}, {+1, -1}, "toroidal cavity");
}

TEST(OrientationShells, IntersectingShellsAreEachOrientedOnTheirOwn) {
    // A small sphere through the large one's surface, within its bounds: partly inside, partly
    // outside, so not nested (some of its vertices are inside, so one sample alone could err).
    expect_oriented({sphere({0, 0, 0}, 2), sphere({1.45f, 1.45f, 0}, 0.3f, true)}, {+1, +1}, "crossing the surface");
    // Sunk into it, only a cap poking out (a character's eye or tooth), written inside out.
    const float d = 1.7f / std::sqrt(3.0f);
    expect_oriented({sphere({0, 0, 0}, 2), sphere({d, d, d}, 0.5f, true)}, {+1, +1}, "sunk in, a cap poking out");
    // Two equal spheres overlapping by half.
    expect_oriented({sphere({0, 0, 0}, 1, true), sphere({1, 0, 0}, 1)}, {+1, +1}, "overlapping");
    // Coincident copies (duplicated shells, separate vertices): each outward.
    expect_oriented({sphere({0, 0, 0}, 1), sphere({0, 0, 0}, 1, true)}, {+1, +1}, "coincident");
}

TEST(OrientationShells, ShellsSharingOnlyAVertexAreTwo) {
    // Two boxes touching at a corner, the vertex shared (index 7 of the first), the second inside
    // out: shells are connected over edges, so only the second is reversed.
    Shells shells = join({box(1, 1, 1), box(1, 1, 1, {1, 1, 1})});
    ControlMesh& m = shells.mesh;
    for (std::size_t c = m.face_offsets[shells.first_face[1]]; c < m.face_vertices.size(); ++c)
        if (m.face_vertices[c] == 8) m.face_vertices[c] = 7;
    for (std::size_t f = shells.first_face[1]; f < m.face_count(); ++f)
        std::reverse(m.face_vertices.begin() + m.face_offsets[f], m.face_vertices.begin() + m.face_offsets[f + 1]);
    ASSERT_TRUE(m.is_closed());
    EXPECT_EQ(orient_outward(m), SurfaceOrientation::outward);
    EXPECT_DOUBLE_EQ(shell_volume(shells, m, 0), 1.0);
    EXPECT_DOUBLE_EQ(shell_volume(shells, m, 1), 1.0);
    ASSERT_EQ(m.warnings.size(), 1u);
    EXPECT_NE(m.warnings[0].find("1 of 2"), std::string::npos) << m.warnings[0];
}

TEST(OrientationShells, ManyHollowCubesEachWithItsCavity) {
    // A voxel-like model: 12 x 12 x 12 hollow boxes (2 shells each, 3456 in all) written with
    // every combination of orientations; each box's cavity must face into it, whatever the
    // neighbours (whose bounds do not hold it) are.
    std::vector<ControlMesh> parts;
    std::vector<int> signs;
    for (int i = 0; i < 12 * 12 * 12; ++i) {
        const int x = i % 12, y = i / 12 % 12, z = i / 144;
        const Vec3 corner{float(x) * 3, float(y) * 3, float(z) * 3};
        ControlMesh outer = box(2, 2, 2, corner), inner = box(1, 1, 1, corner + Vec3{0.5f, 0.5f, 0.5f});
        if (i % 3 == 1) outer.reverse_faces();
        if (i % 2 == 1) inner.reverse_faces();
        parts.push_back(outer);
        parts.push_back(inner);
        signs.push_back(+1);
        signs.push_back(-1);
    }
    expect_oriented(parts, signs, "voxels");
}

TEST(OrientationShells, AFlatShellMakesTheMeshTwoSided) {
    Shells shells = join({sphere({0, 0, 0}, 1), box(2, 3, 0, {5, 0, 0})});
    EXPECT_EQ(classify_orientation(shells.mesh), SurfaceOrientation::flat);
    EXPECT_EQ(orient_outward(shells.mesh), SurfaceOrientation::flat);
    ASSERT_EQ(shells.mesh.warnings.size(), 1u);
    EXPECT_NE(shells.mesh.warnings[0].find("a closed shell encloses no volume"), std::string::npos);
    // An open shell beside a closed one: the mesh is open.
    ControlMesh open = box(2, 3, 4, {5, 0, 0});
    open.face_vertices.resize(open.face_vertices.size() - 4);
    open.face_offsets.pop_back();
    EXPECT_EQ(classify_orientation(join({sphere({0, 0, 0}, 1), open}).mesh), SurfaceOrientation::open);
}

}  // namespace
}  // namespace patchcull
