// The osd scheme: the Catmull-Clark limit surface through OpenSubdiv 3.5 Far, as bicubic Bezier
// patches given by stencils over the control vertices (patchcull/import/subdivision.h).
//
// Source: OpenSubdiv 3.5 Far (feature-adaptive refinement, PatchTableFactory with
// ENDCAP_BSPLINE_BASIS, StencilTableFactory + AppendLocalPointStencilTable, PtexIndices), the
// patch setup of Niessner & Loop and Loop, Niessner & Eisenacher (bicubic Bezier patches from a
// Catmull-Clark control mesh). The boundary extrapolation mirrors Far's own B-spline basis
// evaluation (PatchParam boundary mask: the phantom row/column is 2*P1 - P2), so our Bezier patch
// equals PatchTable::EvaluateBasis over the whole patch domain (tests/import/osd_test.cpp checks this).
//
// Pipeline, and why:
// 1. ControlMesh -> Far::TopologyRefiner (import/osd_topology.h: validation, creases, corners,
//    EDGE_AND_CORNER boundaries). Far's callbacks are captured so errors name mesh.name.
// 2. RefineAdaptive to kIsolationLevel and PatchTableFactory with ENDCAP_BSPLINE_BASIS: every
//    patch is then a 16-point B-spline patch (type REGULAR); patches around extraordinary
//    vertices (and unresolved semi-sharp features) at the isolation level are "end caps": B-spline
//    approximations whose points are local points with their own stencils.
// 3. Stencils for every refined vertex over the level above, with the local-point stencils
//    appended; each patch point is composed through the levels into a row over control vertices
//    (StencilExpander: time linear in the terms touched, where Far's own factorization is cubic
//    in the valence).
// 4. Per patch: extrapolate the phantom points of boundary edges, convert B-spline -> Bezier per
//    direction with [1 4 1 0; 0 4 2 0; 0 2 4 0; 0 1 4 1]/6, and emit 16 rows cp[4*j+i].
//    Far orders the 16 points of a patch as 4*row + column with the column along the patch's s
//    (= ptex u) and the row along t (= ptex v), the same layout as BezierPatch (i along u), and
//    OpenSubdiv 3 has no per-patch rotation: (s,t) of the Bezier patch is Far's (s,t).
//    With isLeftHanded = false and counter-clockwise faces, ptex u runs from face corner 0 to
//    corner 1 and v from corner 0 to the last corner, so du x dv points outward.
//
// Isolation level: kIsolationLevel = 2 (measurements and reasons at the constant).
//
// PatchInfo:
// - base_face: the control-mesh face whose ptex face holds the patch.
// - uv[4]: the mesh's texture coordinates at the patch's corners, interpolated bilinearly over
//   the base face's ptex face: for a quad, bilinear in the face corners' texcoords; for an
//   n-gon (n != 4), ptex sub-face k is the quad (corner k, midpoint of edge k->k+1, centroid,
//   midpoint of edge k-1->k) and the texcoords are those of the same points (corner,
//   midpoints, centroid of the corners' texcoords), interpolated bilinearly. This equals Far's
//   face-varying evaluation with FVAR_LINEAR_ALL (tested). Without texcoords uv[] holds the
//   patch's corners in the (u,v) unit square of its ptex face.
// - extraordinary: the patch is not one regular B-spline patch covering a whole base quad, i.e.
//   it is an end cap (PatchParam::IsRegular() false) or it comes from feature-adaptive
//   isolation (depth > 0: the base face is a non-quad or touches an extraordinary vertex, a
//   semi-sharp or non-boundary sharp feature).
// - tangent_index: -1 (the osd patches are exact polynomial patches; normals come from their
//   own derivatives).
#include <algorithm>
#include <memory>
#include <vector>

#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/stencilTableFactory.h>
#include <opensubdiv/far/topologyRefiner.h>

#include "import/osd_topology.h"
#include "patchcull/core/error.h"
#include "patchcull/import/subdivision.h"

namespace patchcull {

namespace {

namespace Far = OpenSubdiv::Far;

// Feature-adaptive isolation level. The only non-exact patches are the end caps at the
// isolation level (B-spline approximations around extraordinary vertices and semi-sharp features
// not resolved by then); every other patch is the exact limit surface, whatever the level. The
// end caps have the same count at every level but shrink by half per level, and so does their
// error. Measured against a level-8 evaluation (200k samples in end caps, error relative to the
// bounding radius) and patch counts:
//
//   level | bigguy patches | max end-cap error | monsterfrog patches | max end-cap error
//     1   |      3226      |      3.7e-3       |        3584         |      3.0e-3
//     2   |      5554      |      1.5e-3       |        6896         |      1.5e-3
//     3   |      7882      |      8.2e-4       |       10208         |      9.1e-4
//     4   |     10210      |      3.4e-4       |       13520         |      3.8e-4
//
// (776 / 1104 of them end caps at every level.) End caps join their neighbours without cracks
// (gaps across patch edges inside ptex faces ~4e-10 of the radius in Far at levels 1-4; across
// all patch edges of our float Bezier patches at level 2 <= 2.5e-7, tested). Level 1 is enough
// to split non-quad faces into quads but leaves end caps over half of every face around an
// extraordinary vertex; level 2 is the smallest that also resolves semi-sharp creases up to
// sharpness 2 exactly and keeps the end-cap deviation near 0.1% of the model size. Each further
// level adds ~40% more patches (culling cost is linear in patches) for a halving of an error that
// is already below what the cull bounds can use, so we stop at 2.
constexpr int kIsolationLevel = osd_detail::kOsdIsolationLevel;

// B-spline -> Bezier for one direction: Bezier point r = sum_c kBsplineToBezier[r][c] * B_c.
constexpr double kBsplineToBezier[4][4] = {
    {1.0 / 6, 4.0 / 6, 1.0 / 6, 0},
    {0, 4.0 / 6, 2.0 / 6, 0},
    {0, 2.0 / 6, 4.0 / 6, 0},
    {0, 1.0 / 6, 4.0 / 6, 1.0 / 6},
};

// Phantom-point extrapolation for one direction, as Far's B-spline basis does it for a boundary
// edge: low end (P0 := 2 P1 - P2) and/or high end (P3 := 2 P2 - P1). Returns E with
// extrapolated point r = sum_c E[r][c] * P_c.
void extrapolation(bool low, bool high, double e[4][4]) {
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) e[r][c] = r == c ? 1.0 : 0.0;
    if (low) {
        e[0][0] = 0;
        e[0][1] = 2;
        e[0][2] = -1;
    }
    if (high) {
        e[3][3] = 0;
        e[3][2] = 2;
        e[3][1] = -1;
    }
}

// Texture coordinate at (u,v) of ptex face `sub` of face f (see the file comment).
Vec2 ptex_texcoord(const ControlMesh& mesh, std::uint32_t f, int sub, double u, double v) {
    const std::uint32_t b = mesh.face_offsets[f];
    const std::uint32_t n = mesh.face_size(f);
    auto tc = [&](std::uint32_t k) { return mesh.texcoords[mesh.face_texcoords[b + (k % n)]]; };
    Vec2 c[4];
    if (n == 4) {
        for (std::uint32_t k = 0; k < 4; ++k) c[k] = tc(k);
    } else {
        Vec2 centroid{};
        for (std::uint32_t k = 0; k < n; ++k) centroid = centroid + tc(k);
        centroid = centroid * (1.0f / static_cast<float>(n));
        const std::uint32_t k = static_cast<std::uint32_t>(sub);
        c[0] = tc(k);
        c[1] = (tc(k) + tc(k + 1)) * 0.5f;
        c[2] = centroid;
        c[3] = (tc(k + n - 1) + tc(k)) * 0.5f;
    }
    // Ptex corners: (0,0) c0, (1,0) c1, (1,1) c2, (0,1) c3.
    const double w0 = (1 - u) * (1 - v), w1 = u * (1 - v), w2 = u * v, w3 = (1 - u) * v;
    return {static_cast<float>(w0 * c[0].x + w1 * c[1].x + w2 * c[2].x + w3 * c[3].x),
            static_cast<float>(w0 * c[0].y + w1 * c[1].y + w2 * c[2].y + w3 * c[3].y)};
}

// Composes weighted sums of stencil rows into one row over the control vertices. The rows of
// level 0 are the control vertices themselves (identity stencils); a row of level L > 0 is a
// stencil over level L-1 (indices within that level), a local point one over absolute rows. Terms are accumulated
// densely and expanded from the highest touched row down, so each touched row is expanded once: the cost is the sum of
// the touched rows' sizes.
class StencilExpander {
public:
    /// Rows: base's (level by level, level 0 the control vertices), then local's (null: none).
    StencilExpander(const ControlMesh& mesh, const Far::TopologyRefiner& refiner,
                    const Far::StencilTableReal<double>& base, const Far::StencilTableReal<double>* local)
        : mesh_(mesh),
          base_(base),
          local_(local),
          base_count_(base.GetNumStencils()),
          control_count_(refiner.GetLevel(0).GetNumVertices()),
          acc_(static_cast<std::size_t>(base_count_ + (local ? local->GetNumStencils() : 0)), 0.0),
          seen_(acc_.size(), 0) {
        for (int l = 0, start = 0; l <= refiner.GetMaxLevel(); ++l) {
            level_start_.push_back(start);
            start += refiner.GetLevel(l).GetNumVertices();
        }
    }

    void add(int row, double w) {
        if (row < 0 || static_cast<std::size_t>(row) >= acc_.size())
            throw Error(mesh_.name + ": OpenSubdiv produced a stencil source out of range");
        if (!seen_[static_cast<std::size_t>(row)]) {
            seen_[static_cast<std::size_t>(row)] = 1;
            if (row < control_count_) {
                control_.push_back(static_cast<std::uint32_t>(row));
            } else {
                pending_.push_back(row);
                std::push_heap(pending_.begin(), pending_.end());
            }
        }
        acc_[static_cast<std::size_t>(row)] += w;
    }

    /// The accumulated row over the control vertices (sorted, zeros dropped); resets the scratch.
    void finish(std::vector<std::pair<std::uint32_t, float>>& terms) {
        while (!pending_.empty()) {
            std::pop_heap(pending_.begin(), pending_.end());
            const int row = pending_.back();
            pending_.pop_back();
            const double w = acc_[static_cast<std::size_t>(row)];
            acc_[static_cast<std::size_t>(row)] = 0.0;
            seen_[static_cast<std::size_t>(row)] = 0;
            if (w == 0.0) continue;
            const bool is_local = row >= base_count_;
            const auto s = is_local ? local_->GetStencil(row - base_count_) : base_.GetStencil(row);
            // A refined vertex's sources are numbered within the level above it.
            const int source_offset = is_local ? 0 : level_start_[level_of(row) - 1];
            for (int k = 0; k < s.GetSize(); ++k) {
                const int source = source_offset + s.GetVertexIndices()[k];
                if (source >= row || source < 0)
                    throw Error(mesh_.name + ": OpenSubdiv produced a stencil that is not over earlier points");
                add(source, w * s.GetWeights()[k]);
            }
        }
        std::sort(control_.begin(), control_.end());
        terms.clear();
        for (std::uint32_t v : control_) {
            if (acc_[v] != 0.0) terms.emplace_back(v, static_cast<float>(acc_[v]));
            acc_[v] = 0.0;
            seen_[v] = 0;
        }
        control_.clear();
    }

private:
    int level_of(int row) const {
        return static_cast<int>(std::upper_bound(level_start_.begin(), level_start_.end(), row) -
                                level_start_.begin()) -
               1;
    }

    const ControlMesh& mesh_;
    const Far::StencilTableReal<double>& base_;
    const Far::StencilTableReal<double>* local_;
    int base_count_;
    int control_count_;
    std::vector<double> acc_;
    std::vector<std::uint8_t> seen_;
    std::vector<int> level_start_;  // first base row of each refinement level
    std::vector<int> pending_;      // max-heap of touched rows above the control vertices
    std::vector<std::uint32_t> control_;
};

}  // namespace

SubdivisionModel build_osd_model(const ControlMesh& mesh) {
    SubdivisionModel model;
    model.name = mesh.name;
    model.scheme = Scheme::osd;
    model.mesh = mesh;
    check_preprocessing_limits(mesh);  // end caps cost ~valence^2 per vertex (subdivision.h)
    osd_detail::RefinerPtr refiner = osd_detail::create_refiner(mesh, &model.mesh.warnings);

    Far::PatchTableFactory::Options popt(kIsolationLevel);
    popt.SetEndCapType(Far::PatchTableFactory::Options::ENDCAP_BSPLINE_BASIS);
    popt.SetPatchPrecision<double>();
    popt.useSingleCreasePatch = false;  // single-crease patches are not B-spline patches
    popt.useInfSharpPatch = false;
    popt.generateVaryingTables = false;
    popt.generateFVarTables = false;
    refiner->RefineAdaptive(popt.GetRefineAdaptiveOptions());

    std::unique_ptr<const Far::PatchTable> table(Far::PatchTableFactory::Create(*refiner, popt));
    if (!table) throw Error(mesh.name + ": OpenSubdiv could not build the patch table");

    // Stencils of all vertices (control vertices, every refined level), then the end caps' local
    // points: patch-point index k is row k of that sequence. Not factorized: each refined vertex
    // is a stencil over the level above, each local point one over refined vertices, so every row's
    // sources are lower rows (checked in StencilExpander). Far's factorization merges each term
    // into the growing stencil with a linear search: around a vertex of valence n (or an n-gon,
    // whose face point has valence n) its rows have O(n) terms over sources with O(n) terms, and
    // the end caps' O(n) local points each cost up to O(n^3) (measured with the CLI's info
    // command: 9.6 s for one 200-sided face, over 60 s for a valence-256 vertex of an all-quad
    // fan, almost all inside appendLocalPointStencilTable). StencilExpander composes each patch
    // point through the levels instead, in time linear in the terms it touches.
    Far::StencilTableFactoryReal<double>::Options sopt;
    sopt.generateOffsets = true;
    sopt.generateControlVerts = true;
    sopt.generateIntermediateLevels = true;
    sopt.factorizeIntermediateLevels = false;
    std::unique_ptr<const Far::StencilTableReal<double>> base(
        Far::StencilTableFactoryReal<double>::Create(*refiner, sopt));
    if (!base || base->GetNumStencils() != refiner->GetNumVerticesTotal())
        throw Error(mesh.name + ": OpenSubdiv produced an unexpected number of refinement stencils");
    // Local points are stencils over absolute vertex indices (control vertices included), the
    // rows of base; Far's non-factorizing AppendLocalPointStencilTable crashes in 3.5, so the
    // expander reads the two tables side by side.
    const Far::StencilTableReal<double>* local = table->GetLocalPointStencilTable<double>();

    // ptex face -> (base face, sub-face).
    const Far::PtexIndices ptex(*refiner);
    std::vector<std::uint32_t> ptex_face(static_cast<std::size_t>(ptex.GetNumFaces()));
    std::vector<int> ptex_sub(ptex_face.size());
    for (std::uint32_t f = 0; f < mesh.face_count(); ++f) {
        const int first = ptex.GetFaceId(static_cast<int>(f));
        const int count = mesh.face_size(f) == 4 ? 1 : static_cast<int>(mesh.face_size(f));
        for (int k = 0; k < count; ++k) {
            ptex_face[static_cast<std::size_t>(first) + static_cast<std::size_t>(k)] = f;
            ptex_sub[static_cast<std::size_t>(first) + static_cast<std::size_t>(k)] = k;
        }
    }

    StencilExpander expander(mesh, *refiner, *base, local);
    std::vector<std::pair<std::uint32_t, float>> terms;
    model.patches.reserve(static_cast<std::size_t>(table->GetNumPatchesTotal()));

    for (int a = 0; a < table->GetNumPatchArrays(); ++a) {
        const Far::PatchDescriptor desc = table->GetPatchArrayDescriptor(a);
        if (desc.GetType() != Far::PatchDescriptor::REGULAR || desc.GetNumControlVertices() != 16)
            throw Error(mesh.name + ": OpenSubdiv produced a patch type other than a 16-point B-spline patch");
        for (int p = 0; p < table->GetNumPatches(a); ++p) {
            const Far::ConstIndexArray cvs = table->GetPatchVertices(a, p);
            const Far::PatchParam param = table->GetPatchParam(a, p);
            const unsigned boundary = param.GetBoundary();
            // Boundary bits as in Far's basis: 1 = t low edge (row 0), 2 = s high (column 3),
            // 4 = t high (row 3), 8 = s low (column 0).
            double es[4][4], et[4][4];
            extrapolation((boundary & 8) != 0, (boundary & 2) != 0, es);
            extrapolation((boundary & 1) != 0, (boundary & 4) != 0, et);
            // Per direction: Bezier = kBsplineToBezier * E.
            double ms[4][4], mt[4][4];
            for (int r = 0; r < 4; ++r)
                for (int c = 0; c < 4; ++c) {
                    ms[r][c] = mt[r][c] = 0;
                    for (int k = 0; k < 4; ++k) {
                        ms[r][c] += kBsplineToBezier[r][k] * es[k][c];
                        mt[r][c] += kBsplineToBezier[r][k] * et[k][c];
                    }
                }

            for (int j = 0; j < 4; ++j)        // Bezier row (v)
                for (int i = 0; i < 4; ++i) {  // Bezier column (u)
                    for (int row = 0; row < 4; ++row)
                        for (int col = 0; col < 4; ++col) {
                            const double w = mt[j][row] * ms[i][col];
                            if (w != 0.0) expander.add(cvs[4 * row + col], w);
                        }
                    expander.finish(terms);
                    model.patch_points.add_row(terms);
                }

            PatchInfo info;
            const int pf = param.GetFaceId();
            if (pf < 0 || static_cast<std::size_t>(pf) >= ptex_face.size())
                throw Error(mesh.name + ": OpenSubdiv produced a patch with an invalid ptex face");
            info.base_face = ptex_face[static_cast<std::size_t>(pf)];
            for (int k = 0; k < 4; ++k) {
                double u = (k & 1) ? 1.0 : 0.0, v = (k & 2) ? 1.0 : 0.0;
                param.Unnormalize(u, v);
                info.uv[k] = mesh.has_texcoords()
                                 ? ptex_texcoord(mesh, info.base_face, ptex_sub[static_cast<std::size_t>(pf)], u, v)
                                 : Vec2{static_cast<float>(u), static_cast<float>(v)};
            }
            info.extraordinary = !param.IsRegular() || param.GetDepth() > 0;
            info.tangent_index = -1;
            info.depth = static_cast<std::uint8_t>(param.GetDepth());
            model.patches.push_back(info);
        }
    }
    if (model.patches.empty())  // Far builds no patch for a hole (ControlMesh::holes)
        throw Error(mesh.name + ": every face is a hole or at an uninterpolated boundary: no surface");
    return model;
}

}  // namespace patchcull
