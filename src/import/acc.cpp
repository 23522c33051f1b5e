// ACC: approximate Catmull-Clark surfaces with one bicubic Bezier patch per quad
// (patchcull/import/subdivision.h, Scheme::acc).
//
// Source: C. Loop and S. Schaefer, "Approximating Catmull-Clark Subdivision Surfaces with Bicubic
// Patches", ACM TOG 27(1), 2008, the scheme Sathe ("View Frustum Culling of
// Catmull-Clark Patches in DirectX 11") renders and culls. tests/import/acc_test.cpp checks the
// formulas against OpenSubdiv wherever ACC is exact (regular and regular-boundary patches, corner
// positions, corner normals) and checks watertightness and normal continuity everywhere else.
//
// Geometry patch (valence n vertex v, edge neighbours m_i, face neighbours c_i, face i between
// edges i and i+1):
//   corner   = Catmull-Clark limit position (n^2 v + 4 sum m_j + sum c_j) / (n (n+5))
//   interior = (n v + 2 (m_i + m_{i+1}) + c_i) / (n+5)            (Bezier point next to the corner)
//   edge     = (2n v + 4 m_i + 2 (m_{i-1} + m_{i+1}) + c_{i-1} + c_i) / (2n+10),
//              i.e. the mean of the two interior points beside edge i.
// For n = 4 this is the exact B-spline-to-Bezier conversion, so regular patches are the exact limit
// surface. Because an edge point is the mean of the interior points on either side, the geometry
// patches are C0 everywhere and C1 across edges between regular vertices.
//
// Tangent patches (extraordinary patches only): du (degree 2,3) and dv (degree 3,2) start as the
// derivatives of the geometry patch. Their corners are replaced by Catmull-Clark limit tangents
//   t_i = sum_j A cos(2 pi (j-i)/n) m_j + B cos((2 pi (j-i) + pi)/n) c_j,
//   B = 1 / (n sqrt(4 + cos^2(pi/n))), A = 1/n + cos(pi/n) B
// (for n = 4 exactly the B-spline derivative), so du x dv is the limit normal at every corner.
// Limit tangents satisfy t_{i-1} + t_{i+1} = 2 cos(2 pi/n) t_i. Along each interior edge with end
// valences n0, n1 the two cross-boundary tangent curves are made to satisfy
//   cross(u) + cross'(u) = lambda(u) d(u),  lambda(u) = 2 cos(2 pi/n0) (1-u) - 2 cos(2 pi/n1) u,
// with d the along-edge tangent (quadratic) shared by both patches: the geometry cross tangents are
// already antisymmetric at the two inner control points (edge point = mean of interior points), so
// each side adds half of the degree-raised product, (2 c0 d1 - c1 d0)/3 and (c0 d2 - 2 c1 d1)/3.
// Then both normals along the edge are d x cross = -d x cross' up to orientation: the normal field
// is continuous (its direction; its length is not).
//
// Boundaries (our choice; Loop & Schaefer treat closed meshes): Catmull-Clark boundary rules as
// OpenSubdiv's EDGE_AND_CORNER: the boundary is the cubic B-spline of the boundary vertices (edge
// points (2v + m)/3 on boundary edges, limit position (m_0 + 4v + m_k)/6), a corner (boundary vertex
// with one face) stays put. A boundary vertex with k faces is treated as half of an interior vertex
// of valence 2k for the interior and inner edge points (k = 2 gives the exact regular boundary
// B-spline patch, k = 1 the exact corner patch). Its limit tangents are t_j = cos(pi j/k) r0 +
// sin(pi j/k) r1, r0 along the boundary, r1 the smooth-boundary cross tangent of Biermann, Levin &
// Zorin 2000 (the mask OpenSubdiv also uses), which satisfy t_{j-1} + t_{j+1} = 2 cos(pi/k) t_j, so
// the same edge rule applies with cos(pi/k). A patch is regular (no tangent patches) when every
// corner is regular: interior valence 4, boundary with 2 faces, or corner with 1 face. Everything
// else is marked extraordinary and gets tangent patches.
//
// Holes (ControlMesh::holes) and faces that OpenSubdiv leaves without surface under
// BoundaryInterpolation::none produce no patches; edges-only boundaries are honoured where they
// change nothing (no corner) and refused elsewhere (faces_left_out below).
//
// Not handled by ACC: creases and corner sharpness (ignored, with a warning), non-manifold meshes
// (patchcull::Error). Meshes with non-quad faces are refined once with OpenSubdiv first
// (refine_uniform_once) and our stencils are multiplied through its stencils, so the model stays
// a linear function of the original control vertices (animation deforms those).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "import/huge_pages.h"
#include "import/quad_topology.h"
#include "patchcull/core/error.h"
#include "patchcull/core/parallel.h"
#include "patchcull/import/subdivision.h"

namespace patchcull {

namespace {

using acc_detail::QuadTopology;
using acc_detail::VertexRing;
using detail::advise_huge_pages;

// A stencil under construction: weights over vertex indices, in double (build time only).
using Terms = std::vector<std::pair<std::uint32_t, double>>;

void axpy(Terms& dst, double w, const Terms& src) {
    for (const auto& [index, weight] : src) dst.emplace_back(index, w * weight);
}

Terms scaled(double w, const Terms& src) {
    Terms out;
    axpy(out, w, src);
    return out;
}

// Sorts t by vertex and merges duplicates into out, so rows stay short and deterministic. The
// duplicates' sum order is std::sort's on t's sequence: every row is built as the same sequence
// of terms in the same fixed order, so every weight keeps its bits (tested).
void compact_into(Terms& t, Terms& out) {
    std::sort(t.begin(), t.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    out.clear();
    for (const auto& [index, weight] : t) {
        if (!out.empty() && out.back().first == index)
            out.back().second += weight;
        else
            out.emplace_back(index, weight);
    }
    std::erase_if(out, [](const auto& p) { return p.second == 0.0; });
}

constexpr double kPi = std::numbers::pi;

// ---- Point rows of one vertex (see the file comment for the masks) ------------------------------
// Each appends the row's terms to out in a fixed order (so that their sums keep
// their bits). Called per patch corner with reused buffers: computing
// them again for each of a vertex's faces costs less than storing them per vertex (~400 bytes).

// Valence used by the interior and edge masks: n for an interior vertex, 2k for a boundary vertex
// with k > 1 faces, 4 for a corner (its patch is the B-spline patch with extrapolated phantoms).
double mask_valence(const VertexRing& r) {
    const std::size_t k = r.face_count();
    if (!r.boundary) return static_cast<double>(k);
    return k == 1 ? 4.0 : 2 * static_cast<double>(k);
}

void interior_point(std::uint32_t v, const VertexRing& r, std::size_t i, double n, Terms& out) {
    const std::size_t ne = r.edge_vertices.size();
    out.emplace_back(v, n / (n + 5));
    out.emplace_back(r.edge_vertices[i], 2 / (n + 5));
    out.emplace_back(r.edge_vertices[(i + 1) % ne], 2 / (n + 5));
    out.emplace_back(r.face_vertices[i], 1 / (n + 5));
}

void limit_point(std::uint32_t v, const VertexRing& r, Terms& out) {
    const std::size_t n = r.face_count();
    if (r.boundary) {
        if (n == 1) {
            out.emplace_back(v, 1.0);  // a corner is interpolated
        } else {
            out.emplace_back(r.edge_vertices.front(), 1.0 / 6);
            out.emplace_back(v, 4.0 / 6);
            out.emplace_back(r.edge_vertices.back(), 1.0 / 6);
        }
        return;
    }
    const double dn = static_cast<double>(n);
    out.emplace_back(v, dn / (dn + 5));
    for (std::size_t j = 0; j < n; ++j) {
        out.emplace_back(r.edge_vertices[j], 4 / (dn * (dn + 5)));
        out.emplace_back(r.face_vertices[j], 1 / (dn * (dn + 5)));
    }
}

// Bezier point next to v on ring edge i: on a boundary edge (2v + m)/3, else the mean of the two
// interior points beside the edge.
void edge_point(std::uint32_t v, const VertexRing& r, std::size_t i, Terms& out) {
    const std::size_t n = r.face_count();
    if (r.boundary && (i == 0 || i == n)) {
        out.emplace_back(v, 2.0 / 3);
        out.emplace_back(r.edge_vertices[i], 1.0 / 3);
        return;
    }
    const std::size_t before = r.boundary ? i - 1 : (i + n - 1) % n;
    const double valence = mask_valence(r);
    const std::size_t first = out.size();
    interior_point(v, r, before, valence, out);
    interior_point(v, r, i, valence, out);
    for (std::size_t k = first; k < out.size(); ++k) out[k].second = 0.5 * out[k].second;
}

// Whether v's patches are exact B-spline patches at v: interior valence 4, or a boundary vertex
// with 2 faces, or a corner.
bool regular_vertex(const VertexRing& r) { return r.boundary ? r.face_count() <= 2 : r.face_count() == 4; }

// What an extraordinary patch needs from one vertex's one-ring beyond its point rows.
struct VertexRule {
    double edge_cos = 0;         // c in t_{i-1} + t_{i+1} = 2 c t_i, for interior edges
    std::vector<Terms> tangent;  // per ring edge: limit tangent pointing along that edge
};

VertexRule interior_rule(const VertexRing& r) {
    VertexRule rule;
    const std::size_t n = r.face_count();
    const double dn = static_cast<double>(n);
    rule.edge_cos = std::cos(2 * kPi / dn);
    const double cp = std::cos(kPi / dn);
    const double b = 1 / (dn * std::sqrt(4 + cp * cp));
    const double a = 1 / dn + cp * b;
    for (std::size_t i = 0; i < n; ++i) {
        Terms t;
        for (std::size_t j = 0; j < n; ++j) {
            const double l = static_cast<double>((j + n - i) % n);
            t.emplace_back(r.edge_vertices[j], a * std::cos(2 * kPi * l / dn));
            t.emplace_back(r.face_vertices[j], b * std::cos((2 * kPi * l + kPi) / dn));
        }
        rule.tangent.push_back(std::move(t));
    }
    return rule;
}

VertexRule boundary_rule(std::uint32_t v, const VertexRing& r) {
    VertexRule rule;
    const std::size_t k = r.face_count();  // edges 0..k, edges 0 and k on the boundary
    const std::uint32_t m0 = r.edge_vertices.front(), mk = r.edge_vertices.back();
    if (k == 1) {
        rule.tangent = {{{m0, 1.0}, {v, -1.0}}, {{mk, 1.0}, {v, -1.0}}};
        return rule;
    }
    const double dk = static_cast<double>(k);
    rule.edge_cos = std::cos(kPi / dk);

    // r0: derivative of the boundary B-spline towards m0; r1: cross-boundary tangent.
    const Terms r0 = {{m0, 0.5}, {mk, -0.5}};
    const double c = std::cos(kPi / dk), s = std::sin(kPi / dk), den = 3 * dk + c;
    Terms r1 = {{v, -4 * s / den}};
    for (std::size_t i = 0; i <= k; ++i) {
        const double alpha = (i == 0 || i == k) ? -(1 + 2 * c) * std::sqrt(1 + c) / (den * std::sqrt(1 - c))
                                                : 4 * std::sin(kPi * static_cast<double>(i) / dk) / den;
        r1.emplace_back(r.edge_vertices[i], alpha);
    }
    for (std::size_t i = 0; i < k; ++i) {
        const double di = static_cast<double>(i);
        r1.emplace_back(r.face_vertices[i], (std::sin(kPi * di / dk) + std::sin(kPi * (di + 1) / dk)) / den);
    }
    for (std::size_t j = 0; j <= k; ++j) {
        const double angle = kPi * static_cast<double>(j) / dk;
        Terms t = scaled(std::cos(angle), r0);
        axpy(t, std::sin(angle), r1);
        rule.tangent.push_back(std::move(t));
    }
    return rule;
}

// Grid positions of the four quad corners in the 4x4 Bezier net, and the grid steps towards the
// next corner (counter-clockwise) and the previous one. Corner k of face (v0 v1 v2 v3) sits at
// (u,v) = (0,0), (1,0), (1,1), (0,1).
struct CornerFrame {
    int i, j;    // corner point
    int ni, nj;  // step towards the next corner
    int pi, pj;  // step towards the previous corner
};
constexpr CornerFrame kCorners[4] = {
    {0, 0, 1, 0, 0, 1}, {3, 0, 0, 1, -1, 0}, {3, 3, -1, 0, 0, -1}, {0, 3, 0, -1, 1, 0}};

// Tangent block rows: du(i,j) = row 3*j + i (i < 3), dv(i,j) = row 12 + 4*j + i (j < 3).
constexpr int du_row(int i, int j) { return 3 * j + i; }
constexpr int dv_row(int i, int j) { return 12 + 4 * j + i; }

struct SignedRow {
    int row;
    double sign;
};
// Per quad edge q (corner q -> corner q+1): the along-edge tangent d_0..d_2 oriented from corner q
// to corner q+1, and the cross tangent x_0..x_3 pointing into the patch, as signed tangent rows.
struct EdgeFrame {
    SignedRow along[3];
    SignedRow cross[4];
};
constexpr EdgeFrame kEdges[4] = {
    {{{du_row(0, 0), 1}, {du_row(1, 0), 1}, {du_row(2, 0), 1}},
     {{dv_row(0, 0), 1}, {dv_row(1, 0), 1}, {dv_row(2, 0), 1}, {dv_row(3, 0), 1}}},
    {{{dv_row(3, 0), 1}, {dv_row(3, 1), 1}, {dv_row(3, 2), 1}},
     {{du_row(2, 0), -1}, {du_row(2, 1), -1}, {du_row(2, 2), -1}, {du_row(2, 3), -1}}},
    {{{du_row(2, 3), -1}, {du_row(1, 3), -1}, {du_row(0, 3), -1}},
     {{dv_row(3, 2), -1}, {dv_row(2, 2), -1}, {dv_row(1, 2), -1}, {dv_row(0, 2), -1}}},
    {{{dv_row(0, 2), -1}, {dv_row(0, 1), -1}, {dv_row(0, 0), -1}},
     {{du_row(0, 3), 1}, {du_row(0, 2), 1}, {du_row(0, 1), 1}, {du_row(0, 0), 1}}},
};

// Appends a compacted double row to a stencil table as PointStencils::add_row appends a sorted row
// without duplicates: each weight rounded to float (add_row's merge sum 0.0f + w, bit for bit),
// zeros dropped.
void append_row(PointStencils& table, const Terms& row) {
    for (const auto& [index, weight] : row) {
        const float w = 0.0f + static_cast<float>(weight);
        if (w == 0.0f) continue;
        table.indices.push_back(index);
        table.weights.push_back(w);
    }
    table.offsets.push_back(static_cast<std::uint32_t>(table.indices.size()));
}

// compact_into followed by append_row, without the intermediate row: the same sort, the same
// sums in the same order, the same zeros dropped.
void append_compacted(Terms& t, PointStencils& table) {
    std::sort(t.begin(), t.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::size_t k = 0; k < t.size();) {
        const std::uint32_t index = t[k].first;
        double weight = t[k].second;
        for (++k; k < t.size() && t[k].first == index; ++k) weight += t[k].second;
        if (weight == 0.0) continue;
        const float w = 0.0f + static_cast<float>(weight);
        if (w == 0.0f) continue;
        table.indices.push_back(index);
        table.weights.push_back(w);
    }
    table.offsets.push_back(static_cast<std::uint32_t>(table.indices.size()));
}

// Writes rows to a table, composed through the refinement stencils first when there are any
// (a row over refined vertices becomes a row over the original ones).
class RowWriter {
public:
    RowWriter(PointStencils& table, const PointStencils* through) : table_(table), through_(through) {}
    /// A compacted row.
    void write(const Terms& row) {
        if (!through_) return append_row(table_, row);
        composed_.clear();
        for (const auto& [r, w] : row)
            for (std::uint32_t k = through_->offsets[r]; k < through_->offsets[r + 1]; ++k)
                composed_.emplace_back(through_->indices[k], w * static_cast<double>(through_->weights[k]));
        compact_into(composed_, compacted_);
        append_row(table_, compacted_);
    }
    /// A row as built (compacted here; raw is sorted in place).
    void write_raw(Terms& raw) {
        if (!through_) return append_compacted(raw, table_);
        compact_into(raw, row_);
        write(row_);
    }

private:
    PointStencils& table_;
    const PointStencils* through_;
    Terms composed_, compacted_, row_;
};

// Terms a patch's 16 point rows can have before merging: an upper bound of what they write.
std::size_t raw_point_terms(const VertexRing& r) {
    const std::size_t n = r.face_count();
    const std::size_t limit = r.boundary ? (n == 1 ? 1 : 3) : 1 + 2 * n;
    const std::size_t edge = r.boundary && n == 1 ? 2 : 8;  // a boundary edge row has 2
    return limit + 2 * edge + 4;
}

// What one worker builds for a run of consecutive faces: the rows of their patches (offsets from
// 0), their records (tangent_index counted from the run's first tangent block).
struct PatchRun {
    PointStencils points, tangents;
    std::vector<PatchInfo> info;
    void clear() {
        points.offsets.assign(1, 0);
        points.indices.clear();
        points.weights.clear();
        tangents.offsets.assign(1, 0);
        tangents.indices.clear();
        tangents.weights.clear();
        info.clear();
    }
};

// Appends a run's rows to a table (its offsets shifted by the table's terms so far).
void append_run(PointStencils& table, const PointStencils& run) {
    const std::uint32_t base = static_cast<std::uint32_t>(table.indices.size());
    table.indices.insert(table.indices.end(), run.indices.begin(), run.indices.end());
    table.weights.insert(table.weights.end(), run.weights.begin(), run.weights.end());
    for (std::size_t r = 1; r < run.offsets.size(); ++r) table.offsets.push_back(base + run.offsets[r]);
}

// The patches of the faces [first, last) of an all-quad mesh. rule_index/rules hold the rules of
// every vertex of an extraordinary patch (built before, read only here).
void build_run(const ControlMesh& mesh, const QuadTopology& topo, const PointStencils* through,
               const std::vector<std::uint32_t>& rule_index, const std::vector<VertexRule>& rules, std::size_t first,
               std::size_t last, PatchRun& run) {
    run.clear();
    run.info.reserve(last - first);
    RowWriter points(run.points, through), tangents(run.tangents, through);
    Terms raw, net[16];
    for (std::size_t f = first; f < last; ++f) {
        bool regular = true;
        std::uint32_t corner_vertex[4];
        std::uint32_t slot[4];
        for (int q = 0; q < 4; ++q) {
            corner_vertex[q] = mesh.face_vertices[4 * f + q];
            slot[q] = topo.corner_ring_slot[4 * f + q];
            regular = regular && regular_vertex(topo.ring(corner_vertex[q]));
        }
        // Point rows: each ring mask once, in the Bezier net's order 4*j + i. A regular patch
        // writes them as they are built; an extraordinary one keeps them (compacted, in double)
        // for its tangent rows.
        for (int q = 0; q < 4; ++q) {
            const std::uint32_t v = corner_vertex[q];
            const VertexRing r = topo.ring(v);
            const std::size_t s = slot[q];
            const CornerFrame& c = kCorners[q];
            const int at[4] = {4 * c.j + c.i, 4 * (c.j + c.nj) + c.i + c.ni, 4 * (c.j + c.pj) + c.i + c.pi,
                               4 * (c.j + c.nj + c.pj) + c.i + c.ni + c.pi};
            for (int k = 0; k < 4; ++k) net[at[k]].clear();
            limit_point(v, r, net[at[0]]);
            edge_point(v, r, s, net[at[1]]);
            edge_point(v, r, (s + 1) % r.edge_vertices.size(), net[at[2]]);
            interior_point(v, r, s, mask_valence(r), net[at[3]]);
        }
        PatchInfo info;
        info.base_face = static_cast<std::uint32_t>(f);
        info.extraordinary = !regular;
        if (mesh.has_texcoords()) {
            const auto tc = [&](int q) { return mesh.texcoords[mesh.face_texcoords[4 * f + q]]; };
            info.uv[0] = tc(0);
            info.uv[1] = tc(1);
            info.uv[2] = tc(3);
            info.uv[3] = tc(2);
        }
        if (regular) {
            for (Terms& t : net) points.write_raw(t);
            run.info.push_back(info);
            continue;
        }

        Terms b[16];
        for (int k = 0; k < 16; ++k) {
            compact_into(net[k], b[k]);
            points.write(b[k]);
        }
        const VertexRule* rule[4];
        for (int q = 0; q < 4; ++q) rule[q] = &rules[rule_index[corner_vertex[q]]];
        Terms rows[24];
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 3; ++i) {
                rows[du_row(i, j)] = scaled(3, b[4 * j + i + 1]);
                axpy(rows[du_row(i, j)], -3, b[4 * j + i]);
            }
        for (int j = 0; j < 3; ++j)
            for (int i = 0; i < 4; ++i) {
                rows[dv_row(i, j)] = scaled(3, b[4 * (j + 1) + i]);
                axpy(rows[dv_row(i, j)], -3, b[4 * j + i]);
            }
        // Corners: limit tangents along the two edges of each corner (signed to +u / +v).
        // Corner q: along-edge row of edge q (start) and of edge q-1 (end).
        for (int q = 0; q < 4; ++q) {
            const std::size_t edges = rule[q]->tangent.size();
            const SignedRow to_next = kEdges[q].along[0];
            const SignedRow to_prev = kEdges[(q + 3) % 4].along[2];
            rows[to_next.row] = scaled(to_next.sign, rule[q]->tangent[slot[q]]);
            rows[to_prev.row] = scaled(-to_prev.sign, rule[q]->tangent[(slot[q] + 1) % edges]);
        }
        // Interior edges: split lambda(u) d(u) evenly between the two cross tangents.
        for (int q = 0; q < 4; ++q) {
            if (topo.boundary[corner_vertex[q]] && slot[q] == 0) continue;  // edge 0 of a boundary ring: no neighbour
            const double c0 = rule[q]->edge_cos;
            const double c1 = rule[(q + 1) % 4]->edge_cos;
            if (c0 == 0 && c1 == 0) continue;
            const EdgeFrame& e = kEdges[q];
            Terms d[3];
            for (int k = 0; k < 3; ++k) d[k] = scaled(e.along[k].sign, rows[e.along[k].row]);
            Terms x1 = scaled(2 * c0 / 3, d[1]);
            axpy(x1, -c1 / 3, d[0]);
            Terms x2 = scaled(c0 / 3, d[2]);
            axpy(x2, -2 * c1 / 3, d[1]);
            axpy(rows[e.cross[1].row], e.cross[1].sign, x1);
            axpy(rows[e.cross[2].row], e.cross[2].sign, x2);
        }
        info.tangent_index = static_cast<std::int32_t>(run.tangents.rows() / 24);
        for (Terms& t : rows) tangents.write_raw(t);
        run.info.push_back(info);
    }
}

// Faces per run: big enough that a run's rows (~100 terms per patch) amortise a task, small
// enough that the runs in flight stay a few megabytes.
constexpr std::size_t kFacesPerRun = 4096;

// Builds the patches of an all-quad mesh into model (patch_points, tangent_points, patches),
// each row composed through `through` when the mesh is a refinement of model.mesh.
//
// Speed and memory: nothing is stored per vertex except the rules of the vertices of
// extraordinary patches; each patch's rows are built in reused buffers. Runs of consecutive faces
// are built in parallel, a few at a time, and appended in face order, so the tables are exactly
// the sequential ones. The point table is reserved for an upper bound of its terms: on Linux the
// reserved but untouched tail costs address space, not memory.
void build_quad_patches(const ControlMesh& mesh, const PointStencils* through, SubdivisionModel& model) {
    const QuadTopology topo = acc_detail::build_quad_topology(mesh);
    const std::size_t nf = mesh.face_count();

    model.patch_points.offsets.reserve(16 * nf + 1);
    advise_huge_pages(model.patch_points.offsets.data(), (16 * nf + 1) * sizeof(std::uint32_t));
    model.patches.reserve(nf);
    if (!through) {
        std::size_t bound = 0;
        for (std::size_t c = 0; c < 4 * nf; ++c) bound += raw_point_terms(topo.ring(mesh.face_vertices[c]));
        model.patch_points.indices.reserve(bound);
        model.patch_points.weights.reserve(bound);
        advise_huge_pages(model.patch_points.indices.data(), bound * sizeof(std::uint32_t));
        advise_huge_pages(model.patch_points.weights.data(), bound * sizeof(float));
    }

    // Rules of the vertices of extraordinary patches, before the parallel part reads them.
    constexpr std::uint32_t kNone = ~std::uint32_t{0};
    std::vector<std::uint32_t> rule_index(topo.vertex_count(), kNone);
    std::vector<VertexRule> rules;
    for (std::size_t f = 0; f < nf; ++f) {
        const std::uint32_t* corners = &mesh.face_vertices[4 * f];
        if (std::all_of(corners, corners + 4, [&](std::uint32_t v) { return regular_vertex(topo.ring(v)); })) continue;
        for (int q = 0; q < 4; ++q) {
            const std::uint32_t v = corners[q];
            if (rule_index[v] != kNone) continue;
            const VertexRing r = topo.ring(v);
            rule_index[v] = static_cast<std::uint32_t>(rules.size());
            rules.push_back(r.boundary ? boundary_rule(v, r) : interior_rule(r));
        }
    }

    const std::size_t runs_at_once = static_cast<std::size_t>(std::max(1, hardware_threads())) * 2;
    std::vector<PatchRun> runs(std::min(runs_at_once, (nf + kFacesPerRun - 1) / kFacesPerRun));
    for (std::size_t first = 0; first < nf; first += runs.size() * kFacesPerRun) {
        const std::size_t count = std::min(runs.size(), (nf - first + kFacesPerRun - 1) / kFacesPerRun);
        parallel_for_ranges(count, 1, [&](std::size_t begin, std::size_t end) {
            for (std::size_t k = begin; k < end; ++k) {
                const std::size_t f0 = first + k * kFacesPerRun;
                build_run(mesh, topo, through, rule_index, rules, f0, std::min(nf, f0 + kFacesPerRun), runs[k]);
            }
        });
        for (std::size_t k = 0; k < count; ++k) {
            const std::int32_t tangent_base = static_cast<std::int32_t>(model.tangent_points.rows() / 24);
            append_run(model.patch_points, runs[k].points);
            append_run(model.tangent_points, runs[k].tangents);
            for (PatchInfo info : runs[k].info) {
                if (info.tangent_index >= 0) info.tangent_index += tangent_base;
                model.patches.push_back(info);
            }
        }
    }
}

// Faces whose patches the acc scheme leaves out, as OpenSubdiv leaves them out: hole faces
// (ControlMesh::holes) and, under BoundaryInterpolation::none, every face at a boundary vertex
// that has a boundary edge not infinitely sharp (Far's TopologyRefinerFactory makes those holes).
// A left-out face still shapes its neighbours: ACC builds every patch from the one-rings of its
// corners, so the other patches are those of the whole mesh. Returns an empty vector when every
// face keeps its patches. Refuses the boundary options ACC cannot honour: edges-only boundaries
// where the mesh has a corner (a vertex with one face, which ACC's boundary rules keep sharp),
// and no boundary interpolation where creases sharpen all boundary edges of a vertex (Far then
// keeps its faces under crease rules ACC ignores); both name the tag's line and the osd scheme.
std::vector<std::uint8_t> faces_left_out(const ControlMesh& mesh) {
    const std::size_t nf = mesh.face_count();
    std::vector<std::uint8_t> out;
    const BoundaryInterpolation boundary = mesh.options.boundary;
    if (mesh.holes.empty() && boundary == BoundaryInterpolation::edge_and_corner) return out;
    out.assign(nf, 0);
    for (const std::uint32_t f : mesh.holes)
        if (f < nf) out[f] = 1;
    if (boundary == BoundaryInterpolation::edge_and_corner) return out;

    std::string where = mesh.name;  // built with += : GCC 12 warns falsely (-Wrestrict) on ":" + std::string
    if (mesh.options.boundary_line) {
        where += ":";
        where += std::to_string(mesh.options.boundary_line);
    }
    where += ": ";
    const std::size_t nv = mesh.positions.size();
    if (boundary == BoundaryInterpolation::edge_only) {
        std::vector<std::uint32_t> faces_at(nv, 0);
        for (const std::uint32_t v : mesh.face_vertices)
            if (v < nv) ++faces_at[v];
        for (std::uint32_t v = 0; v < nv; ++v)
            if (faces_at[v] == 1)
                throw Error(where +
                            "boundary interpolation 'edges only' (interpolateboundary 2) keeps corners smooth; the acc "
                            "scheme keeps them sharp (vertex " +
                            std::to_string(v + 1) + " has one face): use the osd scheme");
        return out;  // no corner: the same surface as edges and corners
    }
    // none: boundary edges are the edges of one face.
    const auto key = [](std::uint32_t a, std::uint32_t b) {
        return std::uint64_t{std::min(a, b)} << 32 | std::max(a, b);
    };
    std::vector<std::uint64_t> edges;
    edges.reserve(mesh.face_vertices.size());
    for (std::size_t f = 0; f < nf; ++f) {
        const std::uint32_t b = mesh.face_offsets[f], n = mesh.face_size(f);
        for (std::uint32_t k = 0; k < n; ++k)
            edges.push_back(key(mesh.face_vertices[b + k], mesh.face_vertices[b + (k + 1) % n]));
    }
    std::sort(edges.begin(), edges.end());
    std::vector<std::uint64_t> infinite;  // edges with an infinitely sharp crease (Sdc: sharpness >= 10)
    for (const Crease& c : mesh.creases)
        if (c.sharpness >= 10.0f) infinite.push_back(key(c.v0, c.v1));
    std::sort(infinite.begin(), infinite.end());
    std::vector<std::uint8_t> state(nv, 0);  // bit 1: on a boundary, bit 2: has a boundary edge not infinitely sharp
    for (std::size_t i = 0; i < edges.size();) {
        std::size_t j = i + 1;
        while (j < edges.size() && edges[j] == edges[i]) ++j;
        if (j - i == 1) {
            const std::uint8_t bits = std::binary_search(infinite.begin(), infinite.end(), edges[i]) ? 1 : 3;
            for (const std::uint64_t v : {edges[i] >> 32, edges[i] & 0xffffffffu})
                if (v < nv) state[v] |= bits;
        }
        i = j;
    }
    for (std::uint32_t v = 0; v < nv; ++v)
        if (state[v] == 1)
            throw Error(where +
                        "with no boundary interpolation (interpolateboundary 0), creases sharpen every boundary edge "
                        "of vertex " +
                        std::to_string(v + 1) + ", which the acc scheme ignores: use the osd scheme");
    for (std::size_t f = 0; f < nf; ++f)
        for (std::uint32_t c = mesh.face_offsets[f]; c < mesh.face_offsets[f + 1]; ++c)
            if (mesh.face_vertices[c] < nv && state[mesh.face_vertices[c]] != 0) out[f] = 1;
    return out;
}

// Removes the patches whose base face is left out (their point rows, and their tangent blocks,
// renumbering the others').
void drop_patches(SubdivisionModel& model, const std::vector<std::uint8_t>& left_out) {
    PointStencils points, tangents;
    std::vector<PatchInfo> kept;
    const auto copy_rows = [](const PointStencils& from, std::size_t first, std::size_t count, PointStencils& to) {
        for (std::size_t r = first; r < first + count; ++r) {
            for (std::uint32_t k = from.offsets[r]; k < from.offsets[r + 1]; ++k) {
                to.indices.push_back(from.indices[k]);
                to.weights.push_back(from.weights[k]);
            }
            to.offsets.push_back(static_cast<std::uint32_t>(to.indices.size()));
        }
    };
    for (std::size_t p = 0; p < model.patches.size(); ++p) {
        PatchInfo info = model.patches[p];
        if (left_out[info.base_face]) continue;
        copy_rows(model.patch_points, 16 * p, 16, points);
        if (info.tangent_index >= 0) {
            copy_rows(model.tangent_points, 24 * static_cast<std::size_t>(info.tangent_index), 24, tangents);
            info.tangent_index = static_cast<std::int32_t>(tangents.rows() / 24 - 1);
        }
        kept.push_back(info);
    }
    if (kept.empty()) throw Error(model.name + ": every face is a hole or at an uninterpolated boundary: no surface");
    model.patch_points = std::move(points);
    model.tangent_points = std::move(tangents);
    model.patches = std::move(kept);
}

}  // namespace

SubdivisionModel build_acc_model(const ControlMesh& mesh) {
    SubdivisionModel model;
    model.name = mesh.name;
    model.scheme = Scheme::acc;
    model.mesh = mesh;
    if (mesh.face_count() == 0) throw Error(mesh.name + ": mesh has no faces");
    check_preprocessing_limits(mesh);  // rules and rows below cost ~valence^2 per vertex
    const std::vector<std::uint8_t> left_out = faces_left_out(mesh);

    if (mesh.all_quads()) {
        build_quad_patches(mesh, nullptr, model);
    } else {
        // Far numbers the children of face f consecutively, one per corner of f.
        RefinedMesh refined = refine_uniform_once(mesh);
        build_quad_patches(refined.mesh, &refined.stencils, model);
        std::vector<std::uint32_t> parent;
        parent.reserve(refined.mesh.face_count());
        for (std::size_t f = 0; f < mesh.face_count(); ++f)
            parent.insert(parent.end(), mesh.face_size(f), static_cast<std::uint32_t>(f));
        if (parent.size() != model.patches.size())
            throw Error(mesh.name + ": unexpected face count after Catmull-Clark refinement");
        for (PatchInfo& p : model.patches) p.base_face = parent[p.base_face];
        model.mesh.warnings = refined.mesh.warnings;
    }
    if (!left_out.empty()) drop_patches(model, left_out);
    if (!mesh.creases.empty() || !mesh.corners.empty())
        model.mesh.warnings.push_back(mesh.name + ": the acc scheme ignores " + std::to_string(mesh.creases.size()) +
                                      " crease(s) and " + std::to_string(mesh.corners.size()) +
                                      " corner(s); use the osd scheme for sharp features");
    return model;
}

}  // namespace patchcull
