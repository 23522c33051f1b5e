// One uniform Catmull-Clark refinement through OpenSubdiv Far (patchcull/import/subdivision.h).
//
// Source: OpenSubdiv 3.5 Far: TopologyRefiner::RefineUniform(level 1), StencilTableFactory for
// the level-1 vertex stencils over the control vertices, PrimvarRefiner::InterpolateFaceVarying
// for texture coordinates (FVAR_LINEAR_ALL, i.e. linear). Sathe's ACC setup pre-refines non-quad
// meshes once so every face becomes a quad; the ACC scheme (src/import/acc.cpp) is the user.
//
// Why stencils: animation moves the control vertices, so the refined positions must stay a
// linear function of them (RefinedMesh::stencils); positions are also evaluated at rest.
//
// Creases: the refined mesh carries Far's level-1 sharpness (already decremented by Far's
// Chaikin/uniform creasing rules) as ControlMesh creases and corners, so building osd on the
// refined mesh describes the same limit surface. Boundary edges (implicitly infinitely sharp
// under EDGE_AND_CORNER) are not listed; corner vertices that Far itself sharpened (boundary
// vertices with one face) are listed, which is redundant but harmless.
#include <memory>

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/stencilTableFactory.h>
#include <opensubdiv/far/topologyRefiner.h>

#include "import/osd_topology.h"
#include "patchcull/core/error.h"
#include "patchcull/import/subdivision.h"

namespace patchcull {

namespace {

namespace Far = OpenSubdiv::Far;

// Face-varying texture coordinate for Far::PrimvarRefiner (needs Clear and AddWithWeight).
struct FVarUV {
    double u = 0, v = 0;
    void Clear(void* = nullptr) { u = v = 0; }
    void AddWithWeight(const FVarUV& src, double w) {
        u += w * src.u;
        v += w * src.v;
    }
};

}  // namespace

RefinedMesh refine_uniform_once(const ControlMesh& mesh) {
    RefinedMesh out;
    out.mesh.name = mesh.name;
    out.mesh.origin = mesh.origin;  // refined positions are stencils of the local ones
    out.mesh.warnings = mesh.warnings;
    check_preprocessing_limits(mesh);  // Far's factorized stencils cost up to ~n^3 (subdivision.h)
    osd_detail::RefinerPtr refiner = osd_detail::create_refiner(mesh, &out.mesh.warnings);

    Far::TopologyRefiner::UniformOptions uniform(1);
    uniform.fullTopologyInLastLevel = true;  // edges of level 1 are needed for its creases
    refiner->RefineUniform(uniform);
    const Far::TopologyLevel& level = refiner->GetLevel(1);

    // Stencils of the level-1 vertices only, each directly over the control vertices. Computed
    // in double, stored as float.
    Far::StencilTableFactoryReal<double>::Options sopt;
    sopt.generateIntermediateLevels = false;
    sopt.generateOffsets = true;
    sopt.generateControlVerts = false;
    std::unique_ptr<const Far::StencilTableReal<double>> table(
        Far::StencilTableFactoryReal<double>::Create(*refiner, sopt));
    const int nv = level.GetNumVertices();
    if (!table || table->GetNumStencils() != nv)
        throw Error(mesh.name + ": OpenSubdiv produced an unexpected number of refinement stencils");
    std::vector<std::pair<std::uint32_t, float>> terms;
    for (int r = 0; r < nv; ++r) {
        const auto s = table->GetStencil(r);
        terms.clear();
        for (int k = 0; k < s.GetSize(); ++k)
            terms.emplace_back(static_cast<std::uint32_t>(s.GetVertexIndices()[k]),
                               static_cast<float>(s.GetWeights()[k]));
        out.stencils.add_row(terms);
    }
    out.mesh.positions.resize(static_cast<std::size_t>(nv));
    out.stencils.apply(mesh.positions.data(), out.mesh.positions.data());

    // Faces: Far keeps the orientation of the parent face (counter-clockwise stays so).
    const int nf = level.GetNumFaces();
    out.mesh.face_offsets.reserve(static_cast<std::size_t>(nf) + 1);
    for (int f = 0; f < nf; ++f) {
        const auto fv = level.GetFaceVertices(f);
        for (int k = 0; k < fv.size(); ++k) out.mesh.face_vertices.push_back(static_cast<std::uint32_t>(fv[k]));
        if (mesh.has_texcoords()) {
            const auto ft = level.GetFaceFVarValues(f, 0);
            for (int k = 0; k < ft.size(); ++k) out.mesh.face_texcoords.push_back(static_cast<std::uint32_t>(ft[k]));
        }
        out.mesh.face_offsets.push_back(static_cast<std::uint32_t>(out.mesh.face_vertices.size()));
        if (level.IsFaceHole(f)) out.mesh.holes.push_back(static_cast<std::uint32_t>(f));  // children of holes
    }
    out.mesh.options = mesh.options;
    out.mesh.options.boundary_line = 0;  // no line in the refined mesh

    if (mesh.has_texcoords()) {
        std::vector<FVarUV> src(mesh.texcoords.size());
        for (std::size_t i = 0; i < src.size(); ++i) src[i] = {mesh.texcoords[i].x, mesh.texcoords[i].y};
        std::vector<FVarUV> dst(static_cast<std::size_t>(level.GetNumFVarValues(0)));
        const FVarUV* src_ptr = src.data();
        FVarUV* dst_ptr = dst.data();
        Far::PrimvarRefinerReal<double>(*refiner).InterpolateFaceVarying(1, src_ptr, dst_ptr, 0);
        out.mesh.texcoords.resize(dst.size());
        for (std::size_t i = 0; i < dst.size(); ++i)
            out.mesh.texcoords[i] = {static_cast<float>(dst[i].u), static_cast<float>(dst[i].v)};
    }

    for (int e = 0; e < level.GetNumEdges(); ++e) {
        const float s = level.GetEdgeSharpness(e);
        if (s <= 0 || level.IsEdgeBoundary(e)) continue;
        const auto ev = level.GetEdgeVertices(e);
        out.mesh.creases.push_back({static_cast<std::uint32_t>(ev[0]), static_cast<std::uint32_t>(ev[1]), s});
    }
    for (int v = 0; v < nv; ++v) {
        const float s = level.GetVertexSharpness(v);
        if (s > 0) out.mesh.corners.push_back({static_cast<std::uint32_t>(v), 0, s});
    }
    return out;
}

}  // namespace patchcull
