// Internal (src/import only): half-edge adjacency of an all-quad control mesh, as the ACC scheme
// (src/import/acc.cpp) needs it: the ordered one-ring of every vertex.
//
// Why our own adjacency instead of Far's: ACC needs, per vertex, its edge neighbours m_i and face
// neighbours c_i in rotational order starting at a fixed edge, plus, per face corner, where that
// face sits in the ring. Far::TopologyLevel gives the pieces, but building a refiner for an
// all-quad mesh just to read its level 0 costs more than these ~150 lines, and validation errors
// must be one-line patchcull::Error messages naming mesh.name anyway.
#pragma once

#include <cstdint>
#include <vector>

#include "patchcull/mesh.h"

namespace patchcull::acc_detail {

/// One-ring of a vertex in counter-clockwise order (seen from outside, faces CCW).
/// Interior vertex of valence n: n edges, n faces; face i lies between edge i and edge i+1 (mod n).
/// Boundary vertex with k faces: k+1 edges, k faces; edge 0 and edge k are boundary edges and
/// face i lies between edge i and edge i+1.
struct VertexRing {
    bool boundary = false;
    std::vector<std::uint32_t> edge_vertices;  ///< m_i: the other end of edge i
    std::vector<std::uint32_t> face_vertices;  ///< c_i: the corner of face i opposite this vertex
    std::vector<std::uint32_t> faces;          ///< face i
    std::size_t face_count() const { return faces.size(); }
};

struct QuadTopology {
    /// Per vertex; vertices no face uses have an empty ring.
    std::vector<VertexRing> rings;
    /// Per face corner (4*f + k): index of face f in the ring of its corner k.
    std::vector<std::uint32_t> corner_ring_slot;
};

/// Builds the adjacency of an all-quad mesh. Throws patchcull::Error("<mesh.name>: ...") for a
/// face that is not a quad, an out-of-range or repeated vertex index, an edge with more than two
/// faces, inconsistently oriented neighbouring faces, or a vertex whose faces do not form one fan.
QuadTopology build_quad_topology(const ControlMesh& mesh);

}  // namespace patchcull::acc_detail
