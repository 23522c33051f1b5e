// Orientation from geometry (patchcull/mesh.h): the signed volume of closed control meshes, and
// orient_outward reversing inside-out ones, so that back-patch culling and one-sided drawing use
// the side that faces out (issue 9, class 2: topology alone cannot tell inside from outside).
#include <gtest/gtest.h>

#include "patchcull/mesh.h"

namespace patchcull {
namespace {

// An axis-aligned box [0,a] x [0,b] x [0,c] + offset, faces counter-clockwise seen from outside.
ControlMesh box(float a, float b, float c, Vec3 offset = {}) {
    ControlMesh m;
    m.name = "box";
    for (int i = 0; i < 8; ++i)
        m.positions.push_back({offset.x + (i & 1 ? a : 0), offset.y + (i & 2 ? b : 0), offset.z + (i & 4 ? c : 0)});
    const std::uint32_t faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
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
    for (std::size_t c = 0; c < m.face_vertices.size(); ++c) m.face_texcoords.push_back(static_cast<std::uint32_t>(c % 4));
    const std::vector<std::uint32_t> vertices = m.face_vertices, texcoords = m.face_texcoords;
    m.reverse_faces();
    for (std::size_t f = 0; f < m.face_count(); ++f)
        for (std::uint32_t i = 0; i < 4; ++i) {
            EXPECT_EQ(m.face_vertices[4 * f + i], vertices[4 * f + 3 - i]);
            EXPECT_EQ(m.face_texcoords[4 * f + i], texcoords[4 * f + 3 - i]);
        }
}

}  // namespace
}  // namespace patchcull
