// ACC: approximate Catmull-Clark surfaces with one bicubic Bezier patch per quad
// (patchcull/subdivision.h, Scheme::acc).
//
// Source: C. Loop and S. Schaefer, "Approximating Catmull-Clark Subdivision Surfaces with Bicubic
// Patches", ACM TOG 27(1), 2008, the scheme seed 002 (Sathe, "View Frustum Culling of
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

#include "import/quad_topology.h"
#include "patchcull/error.h"
#include "patchcull/subdivision.h"

namespace patchcull {

namespace {

using acc_detail::QuadTopology;
using acc_detail::VertexRing;

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

// Sorts by vertex and merges duplicates, so rows stay short and deterministic.
Terms compact(Terms t) {
    std::sort(t.begin(), t.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    Terms out;
    for (const auto& [index, weight] : t) {
        if (!out.empty() && out.back().first == index) out.back().second += weight;
        else out.emplace_back(index, weight);
    }
    std::erase_if(out, [](const auto& p) { return p.second == 0.0; });
    return out;
}

// Everything the patches need from one vertex's one-ring (see the file comment for the masks).
struct VertexRule {
    bool regular = false;
    double edge_cos = 0;          // c in t_{i-1} + t_{i+1} = 2 c t_i, for interior edges
    Terms limit;                  // limit position
    std::vector<Terms> interior;  // per ring face
    std::vector<Terms> edge;      // per ring edge: Bezier point next to v on that edge
    std::vector<Terms> tangent;   // per ring edge: limit tangent pointing along that edge
};

constexpr double kPi = std::numbers::pi;

Terms interior_point(std::uint32_t v, const VertexRing& r, std::size_t i, double n) {
    const std::size_t ne = r.edge_vertices.size();
    return {{v, n / (n + 5)},
            {r.edge_vertices[i], 2 / (n + 5)},
            {r.edge_vertices[(i + 1) % ne], 2 / (n + 5)},
            {r.face_vertices[i], 1 / (n + 5)}};
}

VertexRule interior_rule(std::uint32_t v, const VertexRing& r) {
    VertexRule rule;
    const std::size_t n = r.face_count();
    const double dn = static_cast<double>(n);
    rule.regular = n == 4;
    rule.edge_cos = std::cos(2 * kPi / dn);
    rule.limit.emplace_back(v, dn / (dn + 5));
    for (std::size_t j = 0; j < n; ++j) {
        rule.limit.emplace_back(r.edge_vertices[j], 4 / (dn * (dn + 5)));
        rule.limit.emplace_back(r.face_vertices[j], 1 / (dn * (dn + 5)));
    }
    for (std::size_t i = 0; i < n; ++i) rule.interior.push_back(interior_point(v, r, i, dn));
    for (std::size_t i = 0; i < n; ++i) {
        Terms e = scaled(0.5, rule.interior[(i + n - 1) % n]);
        axpy(e, 0.5, rule.interior[i]);
        rule.edge.push_back(std::move(e));
    }
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
    const Terms along0 = {{v, 2.0 / 3}, {m0, 1.0 / 3}};
    const Terms alongk = {{v, 2.0 / 3}, {mk, 1.0 / 3}};
    if (k == 1) {
        // Corner: interpolated, its patch is the exact B-spline patch with extrapolated phantoms.
        rule.regular = true;
        rule.limit = {{v, 1.0}};
        rule.interior.push_back(interior_point(v, r, 0, 4));
        rule.edge = {along0, alongk};
        rule.tangent = {{{m0, 1.0}, {v, -1.0}}, {{mk, 1.0}, {v, -1.0}}};
        return rule;
    }
    const double dk = static_cast<double>(k);
    rule.regular = k == 2;
    rule.edge_cos = std::cos(kPi / dk);
    rule.limit = {{m0, 1.0 / 6}, {v, 4.0 / 6}, {mk, 1.0 / 6}};
    for (std::size_t i = 0; i < k; ++i) rule.interior.push_back(interior_point(v, r, i, 2 * dk));
    rule.edge.push_back(along0);
    for (std::size_t i = 1; i < k; ++i) {
        Terms e = scaled(0.5, rule.interior[i - 1]);
        axpy(e, 0.5, rule.interior[i]);
        rule.edge.push_back(std::move(e));
    }
    rule.edge.push_back(alongk);

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
    int i, j;          // corner point
    int ni, nj;        // step towards the next corner
    int pi, pj;        // step towards the previous corner
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

// The models built on an all-quad mesh, before any composition with refinement stencils.
struct QuadPatches {
    std::vector<Terms> points;    // 16 per patch
    std::vector<Terms> tangents;  // 24 per extraordinary patch
    std::vector<PatchInfo> info;
};

QuadPatches build_quad_patches(const ControlMesh& mesh) {
    const QuadTopology topo = acc_detail::build_quad_topology(mesh);
    std::vector<VertexRule> rules(topo.rings.size());
    for (std::uint32_t v = 0; v < topo.rings.size(); ++v) {
        const VertexRing& r = topo.rings[v];
        if (r.faces.empty()) continue;
        rules[v] = r.boundary ? boundary_rule(v, r) : interior_rule(v, r);
    }

    QuadPatches out;
    const std::size_t nf = mesh.face_count();
    out.points.reserve(16 * nf);
    out.info.reserve(nf);
    for (std::size_t f = 0; f < nf; ++f) {
        Terms net[16];
        bool regular = true;
        std::uint32_t corner_vertex[4];
        std::uint32_t slot[4];
        for (int q = 0; q < 4; ++q) {
            corner_vertex[q] = mesh.face_vertices[4 * f + q];
            slot[q] = topo.corner_ring_slot[4 * f + q];
            const VertexRule& rule = rules[corner_vertex[q]];
            const std::size_t edges = rule.edge.size();
            const CornerFrame& c = kCorners[q];
            net[4 * c.j + c.i] = rule.limit;
            net[4 * (c.j + c.nj) + c.i + c.ni] = rule.edge[slot[q]];
            net[4 * (c.j + c.pj) + c.i + c.pi] = rule.edge[(slot[q] + 1) % edges];
            net[4 * (c.j + c.nj + c.pj) + c.i + c.ni + c.pi] = rule.interior[slot[q]];
            regular = regular && rule.regular;
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
        for (Terms& t : net) out.points.push_back(compact(std::move(t)));

        if (!regular) {
            const Terms* b = &out.points[out.points.size() - 16];
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
                const VertexRule& rule = rules[corner_vertex[q]];
                const std::size_t edges = rule.tangent.size();
                const SignedRow to_next = kEdges[q].along[0];
                const SignedRow to_prev = kEdges[(q + 3) % 4].along[2];
                rows[to_next.row] = scaled(to_next.sign, rule.tangent[slot[q]]);
                rows[to_prev.row] = scaled(-to_prev.sign, rule.tangent[(slot[q] + 1) % edges]);
            }
            // Interior edges: split lambda(u) d(u) evenly between the two cross tangents.
            for (int q = 0; q < 4; ++q) {
                const VertexRing& r0 = topo.rings[corner_vertex[q]];
                if (r0.boundary && slot[q] == 0) continue;  // edge 0 of a boundary ring: no neighbour
                const double c0 = rules[corner_vertex[q]].edge_cos;
                const double c1 = rules[corner_vertex[(q + 1) % 4]].edge_cos;
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
            info.tangent_index = static_cast<std::int32_t>(out.tangents.size() / 24);
            for (Terms& t : rows) out.tangents.push_back(compact(std::move(t)));
        }
        out.info.push_back(info);
    }
    return out;
}

void add_rows(PointStencils& table, const std::vector<Terms>& rows, const PointStencils* through) {
    std::vector<std::pair<std::uint32_t, float>> row;
    Terms composed;
    for (const Terms& t : rows) {
        const Terms* src = &t;
        if (through) {
            composed.clear();
            for (const auto& [r, w] : t)
                for (std::uint32_t k = through->offsets[r]; k < through->offsets[r + 1]; ++k)
                    composed.emplace_back(through->indices[k], w * static_cast<double>(through->weights[k]));
            composed = compact(std::move(composed));
            src = &composed;
        }
        row.clear();
        for (const auto& [index, weight] : *src) row.emplace_back(index, static_cast<float>(weight));
        table.add_row(row);
    }
}

}  // namespace

SubdivisionModel build_acc_model(const ControlMesh& mesh) {
    SubdivisionModel model;
    model.name = mesh.name;
    model.scheme = Scheme::acc;
    model.mesh = mesh;
    if (mesh.face_count() == 0) throw Error(mesh.name + ": mesh has no faces");
    check_preprocessing_limits(mesh);  // rules and rows below cost ~valence^2 per vertex

    QuadPatches quads;
    if (mesh.all_quads()) {
        quads = build_quad_patches(mesh);
        add_rows(model.patch_points, quads.points, nullptr);
        add_rows(model.tangent_points, quads.tangents, nullptr);
    } else {
        // Far numbers the children of face f consecutively, one per corner of f.
        RefinedMesh refined = refine_uniform_once(mesh);
        quads = build_quad_patches(refined.mesh);
        std::vector<std::uint32_t> parent;
        parent.reserve(refined.mesh.face_count());
        for (std::size_t f = 0; f < mesh.face_count(); ++f) parent.insert(parent.end(), mesh.face_size(f), static_cast<std::uint32_t>(f));
        if (parent.size() != quads.info.size())
            throw Error(mesh.name + ": unexpected face count after Catmull-Clark refinement");
        for (PatchInfo& p : quads.info) p.base_face = parent[p.base_face];
        add_rows(model.patch_points, quads.points, &refined.stencils);
        add_rows(model.tangent_points, quads.tangents, &refined.stencils);
        model.mesh.warnings = refined.mesh.warnings;
    }
    model.patches = std::move(quads.info);
    if (!mesh.creases.empty() || !mesh.corners.empty())
        model.mesh.warnings.push_back(mesh.name + ": the acc scheme ignores " + std::to_string(mesh.creases.size()) +
                                      " crease(s) and " + std::to_string(mesh.corners.size()) +
                                      " corner(s); use the osd scheme for sharp features");
    return model;
}

}  // namespace patchcull
