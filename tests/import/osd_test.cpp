// The osd scheme (src/import/osd.cpp) and the uniform refinement (src/import/refine.cpp) against
// OpenSubdiv Far's own evaluation.
//
// Source of the reference: OpenSubdiv 3.5 Far, the standard evaluation path of its tutorials:
// TopologyDescriptor -> RefineAdaptive -> PatchTable (ENDCAP_BSPLINE_BASIS), refined vertices by
// PrimvarRefiner::Interpolate level by level, end-cap local points by the patch table's local
// point stencils, then PatchMap::FindPatch + PatchTable::EvaluateBasis at (ptex face, u, v).
// That path never uses our stencil tables or our B-spline -> Bezier conversion, so agreement
// checks the conversion, the boundary extrapolation, the (u,v) orientation and the stencils
// (the patch setup of Niessner & Loop, "Patch-Based Occlusion Culling for Hardware Tessellation", and
// Loop, Niessner & Eisenacher, "Effective Back-Patch Culling for Hardware Tessellation": bicubic Bezier
// patches of the Catmull-Clark limit surface).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <random>
#include <string>
#include <tuple>
#include <unordered_map>
#include <vector>

#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include "import/osd_topology.h"
#include "patchcull/core/error.h"
#include "patchcull/core/patch.h"
#include "patchcull/import/obj.h"
#include "patchcull/import/subdivision.h"

using namespace patchcull;
namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

namespace {

// ---- procedural meshes (counter-clockwise faces seen from outside) ----------------------------

void add_face(ControlMesh& m, std::initializer_list<std::uint32_t> verts) {
    for (std::uint32_t v : verts) m.face_vertices.push_back(v);
    m.face_offsets.push_back(static_cast<std::uint32_t>(m.face_vertices.size()));
}

// Gives every face corner its own texcoord, a smooth function of the corner's position, so
// texcoords are per-face (seams everywhere: the strictest face-varying case).
void add_corner_texcoords(ControlMesh& m) {
    m.texcoords.clear();
    m.face_texcoords.clear();
    for (std::size_t c = 0; c < m.face_vertices.size(); ++c) {
        const Vec3 p = m.positions[m.face_vertices[c]];
        m.texcoords.push_back({0.3f * p.x + 0.1f * p.z + 0.01f * static_cast<float>(c % 7), 0.2f * p.y - 0.05f * p.z});
        m.face_texcoords.push_back(static_cast<std::uint32_t>(c));
    }
}

ControlMesh cube() {
    ControlMesh m;
    m.name = "cube";
    m.positions = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}};
    add_face(m, {0, 3, 2, 1});
    add_face(m, {4, 5, 6, 7});
    add_face(m, {0, 1, 5, 4});
    add_face(m, {2, 3, 7, 6});
    add_face(m, {0, 4, 7, 3});
    add_face(m, {1, 2, 6, 5});
    return m;
}

// Cube with a sharp crease, semi-sharp creases (one resolved within the isolation level, one
// beyond it) and a semi-sharp corner.
ControlMesh creased_cube() {
    ControlMesh m = cube();
    m.name = "creased_cube";
    m.creases = {{4, 5, 10.0f}, {5, 6, 10.0f}, {6, 7, 1.5f}, {0, 1, 2.7f}, {2, 3, 0.5f}};
    m.corners = {{3, 0, 3.0f}, {1, 0, 10.0f}};
    return m;
}

// Pentagonal prism: pentagon bottom, five side quads, a roof of five triangles around an apex.
ControlMesh pentagon_house() {
    ControlMesh m;
    m.name = "pentagon_house";
    const float pi = 3.14159265f;
    for (int ring = 0; ring < 2; ++ring)
        for (int k = 0; k < 5; ++k) {
            const float a = 2 * pi * static_cast<float>(k) / 5;
            m.positions.push_back({std::cos(a), std::sin(a), ring == 0 ? -1.0f : 1.0f});
        }
    m.positions.push_back({0, 0, 1.8f});
    add_face(m, {4, 3, 2, 1, 0});  // bottom, seen from below
    for (std::uint32_t k = 0; k < 5; ++k) add_face(m, {k, (k + 1) % 5, 5 + (k + 1) % 5, 5 + k});
    for (std::uint32_t k = 0; k < 5; ++k) add_face(m, {5 + k, 5 + (k + 1) % 5, 10});
    return m;
}

ControlMesh tetrahedron() {
    ControlMesh m;
    m.name = "tetrahedron";
    m.positions = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
    add_face(m, {0, 1, 2});
    add_face(m, {0, 3, 1});
    add_face(m, {0, 2, 3});
    add_face(m, {1, 3, 2});
    return m;
}

// Open n x n quad grid on a bump: boundaries, boundary corners, interior regular vertices.
ControlMesh open_grid(int n) {
    ControlMesh m;
    m.name = "open_grid";
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const float x = static_cast<float>(i) / static_cast<float>(n),
                        y = static_cast<float>(j) / static_cast<float>(n);
            m.positions.push_back({x, y, 0.3f * std::sin(3 * x) * std::cos(2 * y)});
            m.texcoords.push_back({x, y});
        }
    const auto id = [n](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            add_face(m, {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
            for (std::uint32_t k = m.face_offsets[m.face_offsets.size() - 2]; k < m.face_vertices.size(); ++k)
                m.face_texcoords.push_back(m.face_vertices[k]);
        }
    return m;
}

// An open mesh with an n-gon, a triangle and a boundary vertex of valence 3 (extraordinary).
ControlMesh open_ngon_fan() {
    ControlMesh m;
    m.name = "open_ngon_fan";
    m.positions = {{0, 0, 0},     {1, 0, 0.1f}, {1.5f, 1, 0},    {0.5f, 1.7f, 0.2f},
                   {-0.6f, 1, 0}, {2, 0, 0},    {2.5f, 1, 0.3f}, {2.2f, 2, 0}};
    add_face(m, {0, 1, 2, 3, 4});  // pentagon
    add_face(m, {1, 5, 6, 2});     // quad
    add_face(m, {2, 6, 7});        // triangle
    add_face(m, {2, 7, 3});        // triangle
    return m;
}

ControlMesh load_model(const char* file) {
    return load_obj(std::string(PATCHCULL_SOURCE_DIR) + "/data/models/" + file);
}

// ---- OpenSubdiv reference ---------------------------------------------------------------------

struct DPoint {
    double x = 0, y = 0, z = 0;
    void Clear(void* = nullptr) { x = y = z = 0; }
    void AddWithWeight(const DPoint& p, double w) {
        x += w * p.x;
        y += w * p.y;
        z += w * p.z;
    }
};

struct DUV {
    double u = 0, v = 0;
    void Clear(void* = nullptr) { u = v = 0; }
    void AddWithWeight(const DUV& p, double w) {
        u += w * p.u;
        v += w * p.v;
    }
};

std::unique_ptr<Far::TopologyRefiner> reference_refiner(const ControlMesh& m) {
    std::vector<int> nverts;
    for (std::size_t f = 0; f < m.face_count(); ++f) nverts.push_back(static_cast<int>(m.face_size(f)));
    std::vector<int> fverts(m.face_vertices.begin(), m.face_vertices.end());
    std::vector<int> cpairs, cverts, ftc(m.face_texcoords.begin(), m.face_texcoords.end());
    std::vector<float> cw, vw;
    for (const Crease& c : m.creases) {
        cpairs.push_back(static_cast<int>(c.v0));
        cpairs.push_back(static_cast<int>(c.v1));
        cw.push_back(c.sharpness);
    }
    for (const Crease& c : m.corners) {
        cverts.push_back(static_cast<int>(c.v0));
        vw.push_back(c.sharpness);
    }
    Far::TopologyDescriptor d;
    d.numVertices = static_cast<int>(m.positions.size());
    d.numFaces = static_cast<int>(m.face_count());
    d.numVertsPerFace = nverts.data();
    d.vertIndicesPerFace = fverts.data();
    d.numCreases = static_cast<int>(cw.size());
    d.creaseVertexIndexPairs = cpairs.data();
    d.creaseWeights = cw.data();
    d.numCorners = static_cast<int>(vw.size());
    d.cornerVertexIndices = cverts.data();
    d.cornerWeights = vw.data();
    Far::TopologyDescriptor::FVarChannel ch;
    if (m.has_texcoords()) {
        ch.numValues = static_cast<int>(m.texcoords.size());
        ch.valueIndices = ftc.data();
        d.numFVarChannels = 1;
        d.fvarChannels = &ch;
    }
    Sdc::Options o;
    o.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
    o.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_ALL);
    std::unique_ptr<Far::TopologyRefiner> r(Far::TopologyRefinerFactory<Far::TopologyDescriptor>::Create(
        d, Far::TopologyRefinerFactory<Far::TopologyDescriptor>::Options(Sdc::SCHEME_CATMARK, o)));
    return r;
}

// Far's own limit evaluation of a mesh with the osd scheme's patch options.
struct Reference {
    std::unique_ptr<Far::TopologyRefiner> refiner;
    std::unique_ptr<const Far::PatchTable> table;
    std::unique_ptr<Far::PatchMap> map;
    std::vector<DPoint> verts;  // all levels, then local points
    std::vector<DUV> fvar;      // all levels (texcoords, linear)
    int ptex_faces = 0;

    explicit Reference(const ControlMesh& m) {
        refiner = reference_refiner(m);
        Far::PatchTableFactory::Options po(osd_detail::kOsdIsolationLevel);
        po.SetEndCapType(Far::PatchTableFactory::Options::ENDCAP_BSPLINE_BASIS);
        po.SetPatchPrecision<double>();
        po.generateFVarTables = m.has_texcoords();
        refiner->RefineAdaptive(po.GetRefineAdaptiveOptions());
        table.reset(Far::PatchTableFactory::Create(*refiner, po));
        map = std::make_unique<Far::PatchMap>(*table);
        ptex_faces = Far::PtexIndices(*refiner).GetNumFaces();

        const int total = refiner->GetNumVerticesTotal();
        verts.resize(static_cast<std::size_t>(total) + static_cast<std::size_t>(table->GetNumLocalPoints()));
        for (std::size_t v = 0; v < m.positions.size(); ++v)
            verts[v] = {m.positions[v].x, m.positions[v].y, m.positions[v].z};
        Far::PrimvarRefinerReal<double> primvar(*refiner);
        DPoint* src = verts.data();
        for (int level = 1; level <= refiner->GetMaxLevel(); ++level) {
            DPoint* dst = src + refiner->GetLevel(level - 1).GetNumVertices();
            primvar.Interpolate(level, src, dst);
            src = dst;
        }
        if (const auto* local = table->GetLocalPointStencilTable<double>())
            local->UpdateValues(verts.data(), verts.data() + total);

        if (m.has_texcoords()) {
            fvar.resize(static_cast<std::size_t>(refiner->GetNumFVarValuesTotal(0)));
            for (std::size_t t = 0; t < m.texcoords.size(); ++t) fvar[t] = {m.texcoords[t].x, m.texcoords[t].y};
            DUV* fsrc = fvar.data();
            for (int level = 1; level <= refiner->GetMaxLevel(); ++level) {
                DUV* fdst = fsrc + refiner->GetLevel(level - 1).GetNumFVarValues(0);
                primvar.InterpolateFaceVarying(level, fsrc, fdst, 0);
                fsrc = fdst;
            }
            EXPECT_EQ(table->GetNumLocalPointsFaceVarying(0), 0);  // linear face-varying: no local points
        }
    }

    struct Sample {
        int patch = -1;
        DPoint p, du, dv;  // derivatives with respect to the ptex face's (u, v)
        DUV uv;
    };

    Sample eval(int face, double u, double v) const {
        Sample s;
        const Far::PatchTable::PatchHandle* h = map->FindPatch(face, u, v);
        if (!h) return s;
        s.patch = h->patchIndex;
        double w[20], wu[20], wv[20];
        table->EvaluateBasis(*h, u, v, w, wu, wv);
        const Far::ConstIndexArray cv = table->GetPatchVertices(*h);
        for (int k = 0; k < cv.size(); ++k) {
            s.p.AddWithWeight(verts[static_cast<std::size_t>(cv[k])], w[k]);
            s.du.AddWithWeight(verts[static_cast<std::size_t>(cv[k])], wu[k]);
            s.dv.AddWithWeight(verts[static_cast<std::size_t>(cv[k])], wv[k]);
        }
        if (!fvar.empty()) {
            double fw[20];
            table->EvaluateBasisFaceVarying(*h, u, v, fw, nullptr, nullptr, nullptr, nullptr, nullptr, 0);
            const Far::ConstIndexArray fv = table->GetPatchFVarValues(*h, 0);
            for (int k = 0; k < fv.size(); ++k) s.uv.AddWithWeight(fvar[static_cast<std::size_t>(fv[k])], fw[k]);
        }
        return s;
    }
};

double dist(Vec3 a, DPoint b) {
    const double dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z;
    return std::sqrt(dx * dx + dy * dy + dz * dz);
}
double norm(DPoint a) { return std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z); }

// Bilinear interpolation of a patch's corner texcoords (PatchInfo::uv order).
Vec2 bilinear(const Vec2 c[4], float u, float v) {
    const Vec2 bottom = c[0] * (1 - u) + c[1] * u;
    const Vec2 top = c[2] * (1 - u) + c[3] * u;
    return bottom * (1 - v) + top * v;
}

// Checks model against Far at random (ptex face, u, v) and at every patch's corners and edge
// midpoints: position, both derivatives and texcoords, to float precision relative to the
// model's size. Returns the largest position error relative to the bounding radius.
double expect_matches_far(const ControlMesh& mesh, int samples = 4000) {
    const SubdivisionModel model = build_osd_model(mesh);
    const Reference ref(mesh);
    EXPECT_EQ(model.patch_count(), static_cast<std::size_t>(ref.table->GetNumPatchesTotal())) << mesh.name;
    EXPECT_EQ(model.patch_points.rows(), 16 * model.patch_count()) << mesh.name;
    PatchFrame frame;
    evaluate_patches(model, mesh.positions, 0, frame);
    const double radius = std::max(1e-6, static_cast<double>(compute_bounds(mesh.positions).radius()));
    const double tol = 2e-5 * radius;

    std::mt19937 rng(1234);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::uniform_int_distribution<int> face(0, ref.ptex_faces - 1);
    double worst = 0;
    int failures = 0;
    const auto check = [&](int f, double u, double v) {
        const Reference::Sample s = ref.eval(f, u, v);
        if (s.patch < 0 || static_cast<std::size_t>(s.patch) >= model.patch_count()) {
            ADD_FAILURE() << mesh.name << ": no patch at ptex " << f << " (" << u << ", " << v << ")";
            return;
        }
        const Far::PatchParam param = ref.table->GetPatchParamTable()[static_cast<std::size_t>(s.patch)];
        double pu = u, pv = v;
        param.Normalize(pu, pv);
        const SurfacePoint sp = evaluate_surface(frame.patches[static_cast<std::size_t>(s.patch)],
                                                 static_cast<float>(pu), static_cast<float>(pv));
        // Our derivatives are per patch parameter; Far scales its derivatives by 2^depth (for
        // non-quad base faces too, where a ptex sub-face counts as half the face's parameter
        // range, so this is not 1 / GetParamFraction() there).
        const double scale = static_cast<double>(1 << param.GetDepth());
        const double e = dist(sp.position, s.p);
        const double edu = dist(sp.du * static_cast<float>(scale), s.du);
        const double edv = dist(sp.dv * static_cast<float>(scale), s.dv);
        const double dtol = tol * 8 * scale + 1e-5 * (norm(s.du) + norm(s.dv));
        worst = std::max(worst, e / radius);
        const PatchInfo& info = model.patches[static_cast<std::size_t>(s.patch)];
        bool ok = e <= tol && edu <= dtol && edv <= dtol;
        if (mesh.has_texcoords()) {
            const Vec2 t = bilinear(info.uv, static_cast<float>(pu), static_cast<float>(pv));
            ok = ok && std::abs(t.x - s.uv.u) < 1e-5 && std::abs(t.y - s.uv.v) < 1e-5;
        }
        if (!ok && ++failures <= 5)
            ADD_FAILURE() << mesh.name << ": patch " << s.patch << " ptex " << f << " (" << u << ", " << v
                          << ") boundary " << param.GetBoundary() << " depth " << param.GetDepth()
                          << ": position error " << e << ", du error " << edu << ", dv error " << edv << " (tolerance "
                          << tol << ")";
    };
    for (int k = 0; k < samples; ++k) check(face(rng), unit(rng), unit(rng));
    // Every patch at its corners, edge midpoints and centre (slightly inside, so PatchMap picks it).
    const double in[3] = {1e-4, 0.5, 1 - 1e-4};
    for (std::size_t p = 0; p < model.patch_count(); ++p) {
        const Far::PatchParam param = ref.table->GetPatchParamTable()[p];
        for (double a : in)
            for (double b : in) {
                double u = a, v = b;
                param.Unnormalize(u, v);
                check(param.GetFaceId(), u, v);
            }
    }
    EXPECT_EQ(failures, 0) << mesh.name;
    return worst;
}

// ---- refinement reference ---------------------------------------------------------------------

std::vector<DPoint> far_uniform_level1(const ControlMesh& m, std::unique_ptr<Far::TopologyRefiner>& refiner) {
    refiner = reference_refiner(m);
    refiner->RefineUniform(Far::TopologyRefiner::UniformOptions(1));
    std::vector<DPoint> all(static_cast<std::size_t>(refiner->GetNumVerticesTotal()));
    for (std::size_t v = 0; v < m.positions.size(); ++v)
        all[v] = {m.positions[v].x, m.positions[v].y, m.positions[v].z};
    const DPoint* src = all.data();
    DPoint* dst = all.data() + m.positions.size();
    Far::PrimvarRefinerReal<double>(*refiner).Interpolate(1, src, dst);
    return {all.begin() + static_cast<std::ptrdiff_t>(m.positions.size()), all.end()};
}

std::string error_of(const ControlMesh& m, bool refine) {
    try {
        if (refine)
            refine_uniform_once(m);
        else
            build_osd_model(m);
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

}  // namespace

// ---- osd: agreement with Far's limit evaluation ------------------------------------------------

TEST(Osd, MatchesFarOnBigguy) {
    const ControlMesh mesh = load_model("bigguy.obj");
    const SubdivisionModel model = build_osd_model(mesh);
    std::cout << "[ osd      ] bigguy: " << model.patch_count() << " patches, " << model.extraordinary_count()
              << " extraordinary, isolation level " << osd_detail::kOsdIsolationLevel << "\n";
    expect_matches_far(mesh, 6000);
}

TEST(Osd, MatchesFarOnMonsterfrog) {
    const ControlMesh mesh = load_model("monsterfrog.obj");
    const SubdivisionModel model = build_osd_model(mesh);
    std::cout << "[ osd      ] monsterfrog: " << model.patch_count() << " patches, " << model.extraordinary_count()
              << " extraordinary\n";
    expect_matches_far(mesh, 3000);
}

TEST(Osd, MatchesFarOnOpenGridWithBoundaries) {
    // Boundary edges and corners: the phantom-point extrapolation of every boundary mask.
    const ControlMesh mesh = open_grid(5);
    expect_matches_far(mesh);
    const SubdivisionModel model = build_osd_model(mesh);
    EXPECT_EQ(model.patch_count(), 25u);  // all-regular grid: one patch per quad, no isolation
    EXPECT_EQ(model.extraordinary_count(), 0u);
}

TEST(Osd, MatchesFarOnCreasesAndCorners) {
    ControlMesh mesh = creased_cube();
    expect_matches_far(mesh);
    add_corner_texcoords(mesh);
    expect_matches_far(mesh, 1000);
    // Creases on an open grid: regular vertices, so the crease patches come from isolation.
    ControlMesh grid = open_grid(6);
    grid.creases = {{8, 9, 10.0f}, {9, 10, 10.0f}, {10, 11, 10.0f}, {22, 23, 1.0f}, {23, 24, 2.0f}, {29, 30, 0.7f}};
    grid.corners = {{16, 0, 10.0f}};
    expect_matches_far(grid);
}

TEST(Osd, MatchesFarOnTrianglesAndNgons) {
    ControlMesh house = pentagon_house();
    expect_matches_far(house);
    add_corner_texcoords(house);
    expect_matches_far(house, 2000);
    ControlMesh tet = tetrahedron();
    expect_matches_far(tet);
    add_corner_texcoords(tet);
    expect_matches_far(tet, 1000);
    ControlMesh fan = open_ngon_fan();
    expect_matches_far(fan);
    add_corner_texcoords(fan);
    expect_matches_far(fan, 1000);
}

TEST(Osd, CreasesChangeTheSurface) {
    // Guards against creases being silently dropped: a sharp cube edge stays on the control edge.
    const SubdivisionModel smooth = build_osd_model(cube());
    const SubdivisionModel sharp = build_osd_model(creased_cube());
    PatchFrame a, b;
    evaluate_patches(smooth, smooth.mesh.positions, 0, a);
    evaluate_patches(sharp, sharp.mesh.positions, 0, b);
    double max_diff = 0;
    for (std::size_t p = 0; p < a.patches.size() && p < b.patches.size(); ++p)
        max_diff = std::max(max_diff, static_cast<double>(length(evaluate_position(a.patches[p], 0.5f, 0.5f) -
                                                                 evaluate_position(b.patches[p], 0.5f, 0.5f))));
    EXPECT_TRUE(a.patches.size() != b.patches.size() || max_diff > 1e-2);
}

TEST(Osd, NormalsPointOutwardOnConvexMeshes) {
    for (const ControlMesh& mesh : {cube(), pentagon_house(), tetrahedron(), creased_cube()}) {
        const SubdivisionModel model = build_osd_model(mesh);
        PatchFrame frame;
        evaluate_patches(model, mesh.positions, 0, frame);
        const Vec3 centre = compute_bounds(mesh.positions).center();
        int inward = 0, total = 0;
        for (const BezierPatch& patch : frame.patches)
            for (int j = 0; j <= 4; ++j)
                for (int i = 0; i <= 4; ++i) {
                    // Stay off the patch corners: at an extraordinary vertex du x dv may vanish.
                    const float u = 0.05f + 0.9f * static_cast<float>(i) / 4,
                                v = 0.05f + 0.9f * static_cast<float>(j) / 4;
                    const SurfacePoint s = evaluate_surface(patch, u, v);
                    ++total;
                    if (dot(s.normal, s.position - centre) <= 0) ++inward;
                }
        EXPECT_EQ(inward, 0) << mesh.name << ": " << inward << " of " << total << " normals point inward";
    }
}

// Closed meshes give crack-free patches (watertight joins matter for a Hi-Z map, Niessner & Loop §4.1),
// including end caps against regular patches and patches of different depths: every patch-edge
// sample at parameter k/4 has a sample of another patch's edge (sampled at k/16) within float
// precision. Depths of neighbours differ by at most 2 at isolation level 2, so k/4 on the deeper
// patch is a multiple of 1/16 on the shallower one.
TEST(Osd, PatchesAreWatertightOnClosedMeshes) {
    for (const ControlMesh& mesh : {load_model("bigguy.obj"), pentagon_house(), creased_cube(), tetrahedron()}) {
        const SubdivisionModel model = build_osd_model(mesh);
        PatchFrame frame;
        evaluate_patches(model, mesh.positions, 0, frame);
        const double radius = compute_bounds(mesh.positions).radius();
        const double tol = 1e-5 * radius, cell = 1e-3 * radius;
        struct Sample {
            Vec3 p;
            std::size_t patch;
            bool probe;
        };
        std::vector<Sample> samples;
        for (std::size_t p = 0; p < frame.patches.size(); ++p)
            for (int e = 0; e < 4; ++e)
                for (int k = 0; k <= 16; ++k) {
                    const float t = static_cast<float>(k) / 16;
                    const float u = e == 0 ? t : e == 1 ? 1.0f : e == 2 ? t : 0.0f;
                    const float v = e == 0 ? 0.0f : e == 1 ? t : e == 2 ? 1.0f : t;
                    samples.push_back({evaluate_position(frame.patches[p], u, v), p, k % 4 == 0});
                }
        const auto cell_of = [cell](Vec3 p) {
            return std::make_tuple(static_cast<long>(std::floor(p.x / cell)), static_cast<long>(std::floor(p.y / cell)),
                                   static_cast<long>(std::floor(p.z / cell)));
        };
        const auto hash = [](const std::tuple<long, long, long>& c) {
            return static_cast<std::size_t>(std::get<0>(c) * 73856093L ^ std::get<1>(c) * 19349663L ^
                                            std::get<2>(c) * 83492791L);
        };
        std::unordered_multimap<std::tuple<long, long, long>, std::size_t, decltype(hash)> grid(samples.size(), hash);
        for (std::size_t i = 0; i < samples.size(); ++i) grid.emplace(cell_of(samples[i].p), i);
        double worst = 0;
        for (const Sample& s : samples) {
            if (!s.probe) continue;
            double best = 1e30;
            const auto [cx, cy, cz] = cell_of(s.p);
            for (long dx = -1; dx <= 1; ++dx)
                for (long dy = -1; dy <= 1; ++dy)
                    for (long dz = -1; dz <= 1; ++dz) {
                        const auto range = grid.equal_range(std::make_tuple(cx + dx, cy + dy, cz + dz));
                        for (auto it = range.first; it != range.second; ++it)
                            if (samples[it->second].patch != s.patch)
                                best = std::min(best, static_cast<double>(length(samples[it->second].p - s.p)));
                    }
            worst = std::max(worst, best);
        }
        EXPECT_LT(worst, tol) << mesh.name << ": largest gap between neighbouring patches";
    }
}

TEST(Osd, PatchInfo) {
    const ControlMesh mesh = pentagon_house();
    const SubdivisionModel model = build_osd_model(mesh);
    ASSERT_GT(model.patch_count(), 0u);
    EXPECT_EQ(model.scheme, Scheme::osd);
    EXPECT_EQ(model.tangent_points.rows(), 0u);
    std::vector<int> per_face(mesh.face_count(), 0);
    for (const PatchInfo& info : model.patches) {
        EXPECT_EQ(info.tangent_index, -1);
        ASSERT_LT(info.base_face, mesh.face_count());
        ++per_face[info.base_face];
        // Non-quad faces are always isolated, so their patches are all extraordinary.
        if (mesh.face_size(info.base_face) != 4) {
            EXPECT_TRUE(info.extraordinary);
        }
        // No texcoords: corners lie in the ptex unit square, in patch corner order.
        for (const Vec2& c : info.uv) {
            EXPECT_GE(c.x, 0.0f);
            EXPECT_LE(c.x, 1.0f);
            EXPECT_GE(c.y, 0.0f);
            EXPECT_LE(c.y, 1.0f);
        }
        EXPECT_LT(info.uv[0].x, info.uv[1].x);
        EXPECT_LT(info.uv[0].y, info.uv[2].y);
    }
    for (std::size_t f = 0; f < mesh.face_count(); ++f) EXPECT_GT(per_face[f], 0) << "face " << f;
    // Stencils are over the original control vertices only.
    for (std::uint32_t index : model.patch_points.indices) EXPECT_LT(index, mesh.positions.size());
}

TEST(Osd, StencilsFollowAnimatedControlPoints) {
    // Linear in the control mesh: a moved control mesh gives the moved limit surface.
    ControlMesh mesh = open_ngon_fan();
    const SubdivisionModel model = build_osd_model(mesh);
    for (Vec3& p : mesh.positions) p = Vec3{p.x * 1.5f + 0.2f * p.y, p.y - 0.3f, p.z + 0.4f * p.x};
    PatchFrame frame;
    evaluate_patches(model, mesh.positions, 0, frame);
    const Reference ref(mesh);
    for (int f = 0; f < ref.ptex_faces; ++f) {
        const Reference::Sample s = ref.eval(f, 0.3, 0.6);
        ASSERT_GE(s.patch, 0);
        double u = 0.3, v = 0.6;
        ref.table->GetPatchParamTable()[static_cast<std::size_t>(s.patch)].Normalize(u, v);
        EXPECT_LT(dist(evaluate_position(frame.patches[static_cast<std::size_t>(s.patch)], static_cast<float>(u),
                                         static_cast<float>(v)),
                       s.p),
                  1e-5);
    }
}

// ---- errors ------------------------------------------------------------------------------------

TEST(Osd, NonManifoldAndInvalidMeshesThrowNamingTheMesh) {
    ControlMesh fin = open_grid(2);  // a third face on the interior edge (1, 4)
    fin.name = "fin.obj";
    fin.positions.push_back({0.5f, 0.5f, 1});
    fin.positions.push_back({0.5f, 0.0f, 1});
    add_face(fin, {1, 4, static_cast<std::uint32_t>(fin.positions.size() - 2),
                   static_cast<std::uint32_t>(fin.positions.size() - 1)});
    fin.face_texcoords.clear();
    fin.texcoords.clear();

    ControlMesh flipped = cube();  // one face wound the other way: inconsistent orientation
    flipped.name = "flipped.obj";
    std::reverse(flipped.face_vertices.begin(), flipped.face_vertices.begin() + 4);

    ControlMesh out_of_range = tetrahedron();
    out_of_range.name = "range.obj";
    out_of_range.face_vertices[5] = 17;

    ControlMesh repeated = tetrahedron();
    repeated.name = "repeat.obj";
    repeated.face_vertices[1] = repeated.face_vertices[0];

    ControlMesh bad_crease = cube();
    bad_crease.name = "crease.obj";
    bad_crease.creases = {{0, 99, 2.0f}};

    ControlMesh bowtie;  // two fans sharing only a vertex: non-manifold vertex
    bowtie.name = "bowtie.obj";
    bowtie.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
    add_face(bowtie, {0, 1, 2});
    add_face(bowtie, {0, 3, 4});

    for (const ControlMesh* m : {&fin, &flipped, &out_of_range, &repeated, &bad_crease, &bowtie})
        for (bool refine : {false, true}) {
            const std::string e = error_of(*m, refine);
            EXPECT_EQ(e.rfind(m->name + ": ", 0), 0u) << (refine ? "refine: " : "osd: ") << e;
            EXPECT_EQ(e.find('\n'), std::string::npos) << e;
            EXPECT_NE(e, "(no error)");
        }
    EXPECT_NE(error_of(fin, false).find("3 faces share it"), std::string::npos);
    EXPECT_NE(error_of(flipped, false).find("oriented inconsistently"), std::string::npos);
    // build_model routes to the same checks.
    EXPECT_THROW(build_model(fin, Scheme::osd), Error);
}

TEST(Osd, FarWarningsBecomeMeshWarnings) {
    // A crease on an edge that does not exist is not fatal for Far: it warns, and the warning
    // reaches ControlMesh::warnings (named) instead of stdout.
    ControlMesh m = cube();
    m.creases = {{0, 6, 2.0f}};
    const SubdivisionModel model = build_osd_model(m);
    ASSERT_FALSE(model.mesh.warnings.empty());
    EXPECT_EQ(model.mesh.warnings.back().rfind("cube: OpenSubdiv: ", 0), 0u) << model.mesh.warnings.back();
    EXPECT_FALSE(refine_uniform_once(m).mesh.warnings.empty());
}

// ---- refine_uniform_once -----------------------------------------------------------------------

TEST(Refine, PositionsEqualFarRefinement) {
    for (ControlMesh mesh : {pentagon_house(), tetrahedron(), creased_cube(), open_ngon_fan(), open_grid(3)}) {
        const RefinedMesh r = refine_uniform_once(mesh);
        std::unique_ptr<Far::TopologyRefiner> refiner;
        const std::vector<DPoint> expect = far_uniform_level1(mesh, refiner);
        ASSERT_EQ(r.mesh.positions.size(), expect.size()) << mesh.name;
        ASSERT_EQ(r.stencils.rows(), expect.size()) << mesh.name;
        const double radius = compute_bounds(mesh.positions).radius();
        for (std::size_t v = 0; v < expect.size(); ++v)
            EXPECT_LT(dist(r.mesh.positions[v], expect[v]), 1e-6 * radius) << mesh.name << " vertex " << v;
        for (std::uint32_t index : r.stencils.indices) EXPECT_LT(index, mesh.positions.size());
        // The stencils follow a moved control mesh.
        std::vector<Vec3> moved = mesh.positions;
        for (Vec3& p : moved) p = Vec3{p.y, -p.x + 0.5f * p.z, 2 * p.z};
        std::vector<Vec3> out(r.stencils.rows());
        r.stencils.apply(moved.data(), out.data());
        mesh.positions = moved;
        const std::vector<DPoint> expect_moved = far_uniform_level1(mesh, refiner);
        for (std::size_t v = 0; v < expect.size(); ++v) EXPECT_LT(dist(out[v], expect_moved[v]), 1e-5) << mesh.name;
    }
}

TEST(Refine, AllQuadsCountsAndOrientation) {
    for (const ControlMesh& mesh : {pentagon_house(), tetrahedron(), cube(), open_ngon_fan()}) {
        const RefinedMesh r = refine_uniform_once(mesh);
        EXPECT_EQ(r.mesh.face_count(), mesh.face_vertices.size()) << mesh.name;  // sum of face sizes
        EXPECT_TRUE(r.mesh.all_quads()) << mesh.name;
        EXPECT_EQ(r.mesh.name, mesh.name);
        // Child faces of parent face f are consecutive (Far's order), and keep f's orientation:
        // child normal (Newell) agrees with the parent's.
        std::size_t child = 0;
        for (std::size_t f = 0; f < mesh.face_count(); ++f) {
            const auto newell = [](const ControlMesh& m, std::size_t face) {
                Vec3 n{};
                const std::uint32_t b = m.face_offsets[face], sz = m.face_size(face);
                for (std::uint32_t k = 0; k < sz; ++k) {
                    const Vec3 p = m.positions[m.face_vertices[b + k]],
                               q = m.positions[m.face_vertices[b + (k + 1) % sz]];
                    n += Vec3{(p.y - q.y) * (p.z + q.z), (p.z - q.z) * (p.x + q.x), (p.x - q.x) * (p.y + q.y)};
                }
                return n;
            };
            const Vec3 np = newell(mesh, f);
            for (std::uint32_t k = 0; k < mesh.face_size(f); ++k, ++child)
                EXPECT_GT(dot(np, newell(r.mesh, child)), 0) << mesh.name << " face " << f;
        }
    }
}

TEST(Refine, TexcoordsAreLinear) {
    for (ControlMesh mesh : {pentagon_house(), tetrahedron(), open_ngon_fan(), open_grid(2)}) {
        if (!mesh.has_texcoords()) add_corner_texcoords(mesh);
        const RefinedMesh r = refine_uniform_once(mesh);
        ASSERT_TRUE(r.mesh.has_texcoords()) << mesh.name;
        ASSERT_EQ(r.mesh.face_texcoords.size(), r.mesh.face_vertices.size());
        // Child k of face f is the cycle (corner k, midpoint of edge k, centroid, midpoint of
        // edge k-1), in this (counter-clockwise) order; Far starts the cycle of a quad's child
        // elsewhere (it keeps the parent's u and v directions), so any rotation is accepted.
        std::size_t child = 0;
        for (std::size_t f = 0; f < mesh.face_count(); ++f) {
            const std::uint32_t b = mesh.face_offsets[f], n = mesh.face_size(f);
            auto tc = [&](std::uint32_t k) { return mesh.texcoords[mesh.face_texcoords[b + k % n]]; };
            Vec2 centroid{};
            for (std::uint32_t k = 0; k < n; ++k) centroid = centroid + tc(k);
            centroid = centroid * (1.0f / static_cast<float>(n));
            for (std::uint32_t k = 0; k < n; ++k, ++child) {
                const Vec2 expect[4] = {tc(k), (tc(k) + tc(k + 1)) * 0.5f, centroid, (tc(k + n - 1) + tc(k)) * 0.5f};
                int matching_rotations = 0;
                for (int rot = 0; rot < 4; ++rot) {
                    bool all = true;
                    for (int c = 0; c < 4; ++c) {
                        const Vec2 got =
                            r.mesh
                                .texcoords[r.mesh.face_texcoords[4 * child + static_cast<std::size_t>((c + rot) % 4)]];
                        all = all && std::abs(got.x - expect[c].x) < 1e-6f && std::abs(got.y - expect[c].y) < 1e-6f;
                    }
                    matching_rotations += all;
                }
                EXPECT_EQ(matching_rotations, 1) << mesh.name << " face " << f << " child " << k;
            }
        }
    }
}

TEST(Refine, CarriesCreasesAsFarDecrementsThem) {
    const ControlMesh mesh = creased_cube();
    const RefinedMesh r = refine_uniform_once(mesh);
    // Each control crease edge becomes two child edges with sharpness decremented by one
    // (1.5 -> 0.5, 2.7 -> 1.7, 10 stays infinite; 0.5 -> 0 disappears).
    int infinite = 0, half = 0, one_seven = 0;
    for (const Crease& c : r.mesh.creases) {
        if (c.sharpness >= 10)
            ++infinite;
        else if (std::abs(c.sharpness - 0.5f) < 1e-5f)
            ++half;
        else if (std::abs(c.sharpness - 1.7f) < 1e-5f)
            ++one_seven;
    }
    EXPECT_EQ(infinite, 4);
    EXPECT_EQ(half, 2);
    EXPECT_EQ(one_seven, 2);
    // With the carried creases the refined mesh describes the same limit surface: control
    // face 1 (top, z = 1) at ptex (0.5, 0.5) is ptex corner (1,1) of its child 0 (refined face
    // 4). Without the creases the two would differ by ~1e-2.
    const Reference ra(mesh), rb(r.mesh);
    const Reference::Sample sa = ra.eval(1, 0.5, 0.5);
    const Reference::Sample sb = rb.eval(4, 1.0, 1.0);
    ASSERT_GE(sa.patch, 0);
    ASSERT_GE(sb.patch, 0);
    EXPECT_LT(norm(DPoint{sa.p.x - sb.p.x, sa.p.y - sb.p.y, sa.p.z - sb.p.z}), 1e-5);
}
