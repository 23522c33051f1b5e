// ControlMesh::is_closed (patchcull/core/mesh.h): closed, consistently oriented meshes only, of one
// shell or several.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "patchcull/core/mesh.h"

using namespace patchcull;

namespace {

// A unit cube of 6 quads, counter-clockwise from outside.
ControlMesh cube() {
    ControlMesh m;
    m.name = "cube";
    m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    const std::vector<std::vector<std::uint32_t>> faces = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                                           {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}};
    for (const auto& f : faces) {
        m.face_vertices.insert(m.face_vertices.end(), f.begin(), f.end());
        m.face_offsets.push_back(static_cast<std::uint32_t>(m.face_vertices.size()));
    }
    return m;
}

ControlMesh without_last_face(ControlMesh m) {
    m.face_vertices.resize(m.face_offsets[m.face_count() - 1]);
    m.face_offsets.pop_back();
    return m;
}

}  // namespace

TEST(ControlMesh, CubeIsClosed) { EXPECT_TRUE(cube().is_closed()); }

TEST(ControlMesh, OpenFlippedDuplicatedAndEmptyMeshesAreNotClosed) {
    EXPECT_FALSE(without_last_face(cube()).is_closed());  // a boundary loop
    ControlMesh flipped = cube();
    std::swap(flipped.face_vertices[1], flipped.face_vertices[3]);  // face 0 now clockwise
    EXPECT_FALSE(flipped.is_closed());
    ControlMesh doubled = cube();  // face 0 twice: its edges have three faces
    doubled.face_vertices.insert(doubled.face_vertices.end(), {0, 3, 2, 1});
    doubled.face_offsets.push_back(static_cast<std::uint32_t>(doubled.face_vertices.size()));
    EXPECT_FALSE(doubled.is_closed());
    EXPECT_FALSE(ControlMesh{}.is_closed());
}

TEST(ControlMesh, SeveralShellsAreClosedWhenEachIsClosedAndConsistent) {
    // Two disjoint cubes, the second inside out: closed (each edge once each way, in its own
    // shell); orientation is decided per shell (orientation_test.cpp), not by is_closed.
    ControlMesh two = cube();
    const ControlMesh second = cube();
    const auto base = static_cast<std::uint32_t>(two.positions.size());
    for (const Vec3& p : second.positions) two.positions.push_back({p.x + 3, p.y, p.z});
    for (std::size_t f = 0; f < second.face_count(); ++f) {
        for (std::uint32_t c = second.face_offsets[f + 1]; c-- > second.face_offsets[f];)
            two.face_vertices.push_back(base + second.face_vertices[c]);
        two.face_offsets.push_back(static_cast<std::uint32_t>(two.face_vertices.size()));
    }
    EXPECT_TRUE(two.is_closed());
    // One face of the second shell wound against its neighbours: that shell, so the mesh, is not
    // consistently oriented.
    ControlMesh inconsistent = two;
    std::reverse(inconsistent.face_vertices.end() - 4, inconsistent.face_vertices.end());
    EXPECT_FALSE(inconsistent.is_closed());
    EXPECT_EQ(classify_orientation(inconsistent), SurfaceOrientation::open);
}
