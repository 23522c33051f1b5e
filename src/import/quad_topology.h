// Internal (src/import only): half-edge adjacency of an all-quad control mesh, as the ACC scheme
// (src/import/acc.cpp) needs it: the ordered one-ring of every vertex.
//
// Why our own adjacency instead of Far's: ACC needs, per vertex, its edge neighbours m_i and face
// neighbours c_i in rotational order starting at a fixed edge, plus, per face corner, where that
// face sits in the ring. Far::TopologyLevel gives the pieces, but building a refiner for an
// all-quad mesh just to read its level 0 costs more than these ~200 lines, and validation errors
// must be one-line patchcull::Error messages naming mesh.name anyway.
//
// Why flat arrays: a 1M-quad mesh has 1M rings; one std::vector per ring and per list (and hash
// maps over 4M half-edges) cost gigabytes and most of the build time in malloc. The
// rings live in three arrays indexed by per-vertex offsets; a ring is a view into them.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "patchcull/core/mesh.h"

namespace patchcull::acc_detail {

/// One-ring of a vertex in counter-clockwise order (seen from outside, faces CCW).
/// Interior vertex of valence n: n edges, n faces; face i lies between edge i and edge i+1 (mod n).
/// Boundary vertex with k faces: k+1 edges, k faces; edge 0 and edge k are boundary edges and
/// face i lies between edge i and edge i+1. A view into QuadTopology: valid while it lives.
struct VertexRing {
    bool boundary = false;
    std::span<const std::uint32_t> edge_vertices;  ///< m_i: the other end of edge i
    std::span<const std::uint32_t> face_vertices;  ///< c_i: the corner of face i opposite this vertex
    std::size_t face_count() const { return face_vertices.size(); }
};

struct QuadTopology {
    /// Vertex v's ring faces are slots [face_begin[v], face_begin[v+1]) of face_vertices (size
    /// nv+1; a vertex no face uses has none). Its edges start at face_begin[v] + v in
    /// edge_vertices (one spare slot per vertex: a boundary ring has one edge more than faces).
    std::vector<std::uint32_t> face_begin;
    std::vector<std::uint32_t> face_vertices;
    std::vector<std::uint32_t> edge_vertices;
    std::vector<std::uint8_t> boundary;  ///< per vertex
    /// Per face corner (4*f + k): index of face f in the ring of its corner k.
    std::vector<std::uint32_t> corner_ring_slot;

    std::size_t vertex_count() const { return boundary.size(); }
    VertexRing ring(std::uint32_t v) const {
        const std::uint32_t b = face_begin[v], n = face_begin[v + 1] - b;
        return {boundary[v] != 0, {edge_vertices.data() + b + v, n + boundary[v]}, {face_vertices.data() + b, n}};
    }
};

/// Builds the adjacency of an all-quad mesh. Throws patchcull::Error("<mesh.name>: ...") for a
/// face that is not a quad, an out-of-range or repeated vertex index, an edge with more than two
/// faces, inconsistently oriented neighbouring faces, or a vertex whose faces do not form one fan
/// (checked in that order; the first offender in face-corner order is named).
QuadTopology build_quad_topology(const ControlMesh& mesh);

}  // namespace patchcull::acc_detail
