// Internal: half-edge adjacency of an all-quad mesh (see quad_topology.h).
//
// Half-edge h = 4*f + k runs from corner k to corner k+1 of face f. With counter-clockwise faces,
// the next outgoing half-edge counter-clockwise around the start vertex of h is the twin of the
// half-edge that ends there in the same face: twin(prev(h)).
//
// Twins are found in the per-vertex lists of outgoing half-edges (flat, in half-edge order): the
// twin of a -> b is the half-edge of b's list that ends at a. Lists are as long as the valence
// (bounded by kMaxValence, subdivision.h), so this is linear in the mesh and allocates four flat
// arrays, where hash maps over the half-edges cost ~100 bytes and an allocation per half-edge.
#include "import/quad_topology.h"

#include <algorithm>
#include <string>

#include "import/mesh_messages.h"
#include "patchcull/core/error.h"

namespace patchcull::acc_detail {

namespace {

[[noreturn]] void fail(const ControlMesh& mesh, const std::string& what) { throw Error(mesh.name + ": " + what); }

}  // namespace

QuadTopology build_quad_topology(const ControlMesh& mesh) {
    const std::size_t nf = mesh.face_count();
    const std::size_t nv = mesh.positions.size();
    if (nf == 0) fail(mesh, "mesh has no faces");
    if (mesh.face_vertices.size() != 4 * nf) fail(mesh, "ACC needs an all-quad mesh here");
    if (4 * nf + nv > 0xffffffffu) fail(mesh, "mesh too large (more than 2^32 corners)");

    const auto vert = [&](std::size_t h) { return mesh.face_vertices[h]; };
    const auto next = [](std::size_t h) { return (h & ~std::size_t{3}) | ((h + 1) & 3); };
    const auto prev = [](std::size_t h) { return (h & ~std::size_t{3}) | ((h + 3) & 3); };

    for (std::size_t f = 0; f < nf; ++f) {
        if (mesh.face_size(f) != 4) fail(mesh, "face " + std::to_string(f) + " is not a quad");
        for (int k = 0; k < 4; ++k) {
            const std::uint32_t v = vert(4 * f + k);
            if (v >= nv)
                fail(mesh, "face " + std::to_string(f) + " uses vertex " + std::to_string(v) + " out of range (" +
                               std::to_string(nv) + " vertices)");
            for (int j = 0; j < k; ++j)
                if (vert(4 * f + j) == v)
                    fail(mesh, "face " + std::to_string(f) + " repeats vertex " + std::to_string(v));
        }
    }

    // Outgoing half-edges of vertex v: out[out_begin[v] .. out_begin[v+1]), in increasing order.
    QuadTopology topo;
    std::vector<std::uint32_t>& out_begin = topo.face_begin;  // a vertex's corners are its ring faces
    out_begin.assign(nv + 1, 0);
    for (std::size_t h = 0; h < 4 * nf; ++h) ++out_begin[vert(h) + 1];
    for (std::size_t v = 0; v < nv; ++v) out_begin[v + 1] += out_begin[v];
    std::vector<std::uint32_t> out(4 * nf);
    {
        std::vector<std::uint32_t> fill(out_begin.begin(), out_begin.end() - 1);
        for (std::size_t h = 0; h < 4 * nf; ++h) out[fill[vert(h)]++] = static_cast<std::uint32_t>(h);
    }
    // Calls visit(h') for each half-edge a -> b, in increasing order, while it returns true.
    const auto for_each_directed = [&](std::uint32_t a, std::uint32_t b, auto&& visit) {
        for (std::uint32_t k = out_begin[a]; k < out_begin[a + 1]; ++k)
            if (vert(next(out[k])) == b && !visit(out[k])) return;
    };

    // An edge used by three or more half-edges is non-manifold; reported at the half-edge that
    // is its third use, the first such in half-edge order.
    for (std::size_t h = 0; h < 4 * nf; ++h) {
        const std::uint32_t a = vert(h), b = vert(next(h));
        int earlier = 0;
        const auto count_earlier = [&](std::uint32_t g) {
            if (g >= h) return false;
            ++earlier;
            return true;
        };
        for_each_directed(a, b, count_earlier);
        for_each_directed(b, a, count_earlier);
        if (earlier >= 2) {
            std::size_t faces = 0;
            const auto count = [&](std::uint32_t) { return ++faces, true; };
            for_each_directed(a, b, count);
            for_each_directed(b, a, count);
            throw Error(detail::edge_shared_message(mesh, h / 4, a, b, faces));
        }
    }
    // A directed edge used twice: two neighbours with opposite orientation.
    for (std::size_t h = 0; h < 4 * nf; ++h) {
        const std::uint32_t a = vert(h), b = vert(next(h));
        std::uint32_t first = static_cast<std::uint32_t>(h);
        for_each_directed(a, b, [&](std::uint32_t g) {
            first = g;
            return false;
        });
        if (first != h) throw Error(detail::edge_orientation_message(mesh, first / 4, h / 4, a, b));
    }
    constexpr std::uint32_t kNone = ~std::uint32_t{0};
    std::vector<std::uint32_t> twin(4 * nf, kNone);
    for (std::size_t h = 0; h < 4 * nf; ++h)
        for_each_directed(vert(next(h)), vert(h), [&](std::uint32_t g) {
            twin[h] = g;
            return false;
        });

    topo.face_vertices.assign(4 * nf, 0);
    topo.edge_vertices.assign(4 * nf + nv, 0);
    topo.boundary.assign(nv, 0);
    topo.corner_ring_slot.assign(4 * nf, 0);
    for (std::uint32_t v = 0; v < nv; ++v) {
        const std::uint32_t corner_count = out_begin[v + 1] - out_begin[v];
        if (corner_count == 0) continue;
        const std::size_t any_outgoing = out[out_begin[v + 1] - 1];  // the last, as a map would keep it
        // Rotate clockwise to the first edge of the fan: a boundary edge with no face before it,
        // or back to the start for an interior vertex.
        std::size_t start = any_outgoing;
        bool boundary = false;
        for (std::uint32_t steps = 0;; ++steps) {
            const std::uint32_t t = twin[start];
            if (t == kNone) {
                boundary = true;
                break;
            }
            const std::size_t cw = next(t);  // outgoing half-edge of v in the face clockwise of start
            if (cw == any_outgoing || steps > corner_count) break;
            start = cw;
        }
        topo.boundary[v] = boundary ? 1 : 0;
        std::uint32_t* const faces_out = topo.face_vertices.data() + out_begin[v];
        std::uint32_t* const edges_out = topo.edge_vertices.data() + out_begin[v] + v;
        std::uint32_t faces = 0, edges = 0;
        const auto not_one_fan = [&] { throw Error(detail::vertex_fan_message(mesh, out[out_begin[v]] / 4, v)); };
        std::size_t h = start;
        for (;;) {
            // A vertex whose faces form several fans (a "bowtie") is non-manifold; a walk that
            // passes more faces than the vertex has cannot be one fan either.
            if (faces == corner_count) not_one_fan();
            topo.corner_ring_slot[h] = faces;
            faces_out[faces++] = vert(next(next(h)));
            edges_out[edges++] = vert(next(h));
            const std::uint32_t t = twin[prev(h)];
            if (t == kNone) {
                edges_out[edges++] = vert(prev(h));  // closing boundary edge
                break;
            }
            if (t == start) break;
            h = t;
        }
        if (faces != corner_count) not_one_fan();
        if (boundary && edges != faces + 1) not_one_fan();
    }
    return topo;
}

}  // namespace patchcull::acc_detail
