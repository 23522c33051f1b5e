// Internal: half-edge adjacency of an all-quad mesh (see quad_topology.h).
//
// Half-edge h = 4*f + k runs from corner k to corner k+1 of face f. With counter-clockwise faces,
// the next outgoing half-edge counter-clockwise around the start vertex of h is the twin of the
// half-edge that ends there in the same face: twin(prev(h)).
#include "import/quad_topology.h"

#include <algorithm>
#include <string>
#include <unordered_map>

#include "patchcull/error.h"

namespace patchcull::acc_detail {

namespace {

[[noreturn]] void fail(const ControlMesh& mesh, const std::string& what) { throw Error(mesh.name + ": " + what); }

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) { return (std::uint64_t{a} << 32) | b; }

std::string edge_name(std::uint32_t a, std::uint32_t b) {
    std::string s = "(";  // built with += : GCC 12 warns falsely (-Wrestrict) on "(" + std::string
    s += std::to_string(a);
    s += ", ";
    s += std::to_string(b);
    s += ")";
    return s;
}

}  // namespace

QuadTopology build_quad_topology(const ControlMesh& mesh) {
    const std::size_t nf = mesh.face_count();
    const std::size_t nv = mesh.positions.size();
    if (nf == 0) fail(mesh, "mesh has no faces");
    if (mesh.face_vertices.size() != 4 * nf) fail(mesh, "ACC needs an all-quad mesh here");

    const auto vert = [&](std::size_t h) { return mesh.face_vertices[h]; };
    const auto next = [](std::size_t h) { return (h & ~std::size_t{3}) | ((h + 1) & 3); };
    const auto prev = [](std::size_t h) { return (h & ~std::size_t{3}) | ((h + 3) & 3); };

    // Directed edge -> half-edge; a directed edge seen twice means either a non-manifold edge
    // (three or more faces) or two neighbours with opposite orientation.
    std::unordered_map<std::uint64_t, std::uint32_t> directed;
    directed.reserve(4 * nf);
    std::unordered_map<std::uint64_t, int> undirected_uses;
    undirected_uses.reserve(4 * nf);
    for (std::size_t f = 0; f < nf; ++f) {
        if (mesh.face_size(f) != 4) fail(mesh, "face " + std::to_string(f) + " is not a quad");
        for (int k = 0; k < 4; ++k) {
            const std::uint32_t v = vert(4 * f + k);
            if (v >= nv)
                fail(mesh, "face " + std::to_string(f) + " uses vertex " + std::to_string(v) + " out of range (" +
                               std::to_string(nv) + " vertices)");
            for (int j = 0; j < k; ++j)
                if (vert(4 * f + j) == v) fail(mesh, "face " + std::to_string(f) + " repeats vertex " + std::to_string(v));
        }
    }
    for (std::size_t h = 0; h < 4 * nf; ++h) {
        const std::uint32_t a = vert(h), b = vert(next(h));
        const int uses = ++undirected_uses[edge_key(std::min(a, b), std::max(a, b))];
        if (uses > 2) fail(mesh, "non-manifold edge " + edge_name(a, b) + " shared by more than two faces");
    }
    for (std::size_t h = 0; h < 4 * nf; ++h) {
        const std::uint32_t a = vert(h), b = vert(next(h));
        if (!directed.emplace(edge_key(a, b), static_cast<std::uint32_t>(h)).second)
            fail(mesh, "inconsistent face orientation at edge " + edge_name(a, b) + " (faces " +
                           std::to_string(directed[edge_key(a, b)] / 4) + " and " + std::to_string(h / 4) + ")");
    }
    constexpr std::uint32_t kNone = ~std::uint32_t{0};
    std::vector<std::uint32_t> twin(4 * nf, kNone);
    for (std::size_t h = 0; h < 4 * nf; ++h) {
        const auto it = directed.find(edge_key(vert(next(h)), vert(h)));
        if (it != directed.end()) twin[h] = it->second;
    }

    // One outgoing half-edge per vertex, and how many face corners each vertex has.
    std::vector<std::uint32_t> any_outgoing(nv, kNone), corner_count(nv, 0);
    for (std::size_t h = 0; h < 4 * nf; ++h) {
        any_outgoing[vert(h)] = static_cast<std::uint32_t>(h);
        ++corner_count[vert(h)];
    }

    QuadTopology topo;
    topo.rings.resize(nv);
    topo.corner_ring_slot.assign(4 * nf, 0);
    for (std::uint32_t v = 0; v < nv; ++v) {
        if (any_outgoing[v] == kNone) continue;
        // Rotate clockwise to the first edge of the fan: a boundary edge with no face before it,
        // or back to the start for an interior vertex.
        std::size_t start = any_outgoing[v];
        bool boundary = false;
        for (std::uint32_t steps = 0;; ++steps) {
            const std::uint32_t t = twin[start];
            if (t == kNone) {
                boundary = true;
                break;
            }
            const std::size_t cw = next(t);  // outgoing half-edge of v in the face clockwise of start
            if (cw == any_outgoing[v] || steps > corner_count[v]) break;
            start = cw;
        }
        VertexRing& ring = topo.rings[v];
        ring.boundary = boundary;
        std::size_t h = start;
        for (;;) {
            const std::size_t f = h / 4;
            topo.corner_ring_slot[h] = static_cast<std::uint32_t>(ring.faces.size());
            ring.faces.push_back(static_cast<std::uint32_t>(f));
            ring.edge_vertices.push_back(vert(next(h)));
            ring.face_vertices.push_back(vert(next(next(h))));
            const std::uint32_t t = twin[prev(h)];
            if (t == kNone) {
                ring.edge_vertices.push_back(vert(prev(h)));  // closing boundary edge
                break;
            }
            if (t == start || ring.faces.size() > corner_count[v]) break;
            h = t;
        }
        // A vertex whose faces form several fans (a "bowtie") is non-manifold.
        if (ring.faces.size() != corner_count[v])
            fail(mesh, "non-manifold vertex " + std::to_string(v) + " (its faces do not form a single fan)");
        if (boundary && ring.edge_vertices.size() != ring.faces.size() + 1)
            fail(mesh, "non-manifold vertex " + std::to_string(v));
    }
    return topo;
}

}  // namespace patchcull::acc_detail
