// ACC patches (src/import/acc.cpp) against OpenSubdiv's exact Catmull-Clark limit surface.
//
// The reference is OpenSubdiv Far, set up independently here (Catmull-Clark, EDGE_AND_CORNER
// boundaries): LimitStencilTableFactory for the limit surface at (face, u, v) and
// PrimvarRefiner::Limit for limit positions and tangents at vertices.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/stencilTableFactory.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include "patchcull/core/error.h"
#include "patchcull/core/patch.h"
#include "patchcull/import/obj.h"
#include "patchcull/import/subdivision.h"

using namespace patchcull;
namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

namespace {

ControlMesh load_model(const std::string& file) {
    return load_obj(std::string(PATCHCULL_SOURCE_DIR) + "/data/models/" + file);
}

ControlMesh make_mesh(const std::string& name, std::vector<Vec3> positions,
                      const std::vector<std::vector<std::uint32_t>>& faces) {
    ControlMesh m;
    m.name = name;
    m.positions = std::move(positions);
    for (const auto& f : faces) {
        m.face_vertices.insert(m.face_vertices.end(), f.begin(), f.end());
        m.face_offsets.push_back(static_cast<std::uint32_t>(m.face_vertices.size()));
    }
    return m;
}

// An open nx x ny grid of quads over a bumpy height field (all vertices regular).
ControlMesh make_grid(int nx, int ny) {
    std::vector<Vec3> p;
    for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i) {
            const float x = static_cast<float>(i), y = static_cast<float>(j);
            p.push_back({x, y, 0.3f * std::sin(1.3f * x) * std::cos(0.9f * y) + 0.05f * x * y});
        }
    std::vector<std::vector<std::uint32_t>> faces;
    const auto id = [&](int i, int j) { return static_cast<std::uint32_t>(j * (nx + 1) + i); };
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
    return make_mesh("grid", p, faces);
}

// Three quads around a boundary vertex with three faces (an irregular boundary vertex), on a
// curved surface so normals matter.
ControlMesh make_boundary_fan() {
    std::vector<Vec3> p{{0, 0, 0}};
    const auto at = [](double deg, double r) {
        const double a = deg * 3.14159265358979 / 180;
        const double x = r * std::cos(a), y = r * std::sin(a);
        return Vec3{static_cast<float>(x), static_cast<float>(y),
                    static_cast<float>(0.4 * x * x - 0.3 * y * y + 0.2 * x * y)};
    };
    for (int i = 0; i < 4; ++i) p.push_back(at(60.0 * i, 1.0));       // m0..m3: 1..4
    for (int i = 0; i < 3; ++i) p.push_back(at(60.0 * i + 30, 1.5));  // c0..c2: 5..7
    return make_mesh("fan", p, {{0, 1, 5, 2}, {0, 2, 6, 3}, {0, 3, 7, 4}});
}

// ---- OpenSubdiv reference ------------------------------------------------------------------

struct DPoint {
    double x = 0, y = 0, z = 0;
    void Clear(void* = nullptr) { x = y = z = 0; }
    void AddWithWeight(const DPoint& s, double w) {
        x += w * s.x;
        y += w * s.y;
        z += w * s.z;
    }
};

Vec3 to_vec(const DPoint& p) { return {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)}; }

std::unique_ptr<Far::TopologyRefiner> make_refiner(const ControlMesh& m) {
    std::vector<int> sizes(m.face_count());
    for (std::size_t f = 0; f < m.face_count(); ++f) sizes[f] = static_cast<int>(m.face_size(f));
    std::vector<int> indices(m.face_vertices.begin(), m.face_vertices.end());
    Far::TopologyDescriptor desc;
    desc.numVertices = static_cast<int>(m.positions.size());
    desc.numFaces = static_cast<int>(m.face_count());
    desc.numVertsPerFace = sizes.data();
    desc.vertIndicesPerFace = indices.data();
    Sdc::Options sdc;
    sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
    using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
    return std::unique_ptr<Far::TopologyRefiner>(Factory::Create(desc, Factory::Options(Sdc::SCHEME_CATMARK, sdc)));
}

struct Location {
    int face;
    float u, v;
};

struct LimitSample {
    Vec3 position, du, dv;
};

// Exact limit surface of an all-quad mesh at (face, u, v) (ptex face = face for quads).
std::vector<LimitSample> osd_limit_surface(const ControlMesh& m, const std::vector<Location>& locations) {
    auto refiner = make_refiner(m);
    refiner->RefineAdaptive(Far::TopologyRefiner::AdaptiveOptions(3));
    std::map<int, std::pair<std::vector<double>, std::vector<double>>> per_face;
    std::vector<std::pair<int, std::size_t>> order;  // (face, index within face)
    for (const Location& l : locations) {
        auto& st = per_face[l.face];
        order.emplace_back(l.face, st.first.size());
        st.first.push_back(l.u);
        st.second.push_back(l.v);
    }
    using LimitFactory = Far::LimitStencilTableFactoryReal<double>;
    LimitFactory::LocationArrayVec arrays;
    std::map<int, std::size_t> first_stencil;
    std::size_t count = 0;
    for (auto& [face, st] : per_face) {
        LimitFactory::LocationArray a;
        a.ptexIdx = face;
        a.numLocations = static_cast<int>(st.first.size());
        a.s = st.first.data();
        a.t = st.second.data();
        arrays.push_back(a);
        first_stencil[face] = count;
        count += st.first.size();
    }
    std::unique_ptr<const Far::LimitStencilTableReal<double>> table(LimitFactory::Create(*refiner, arrays));
    EXPECT_TRUE(table);
    if (!table) return {};
    EXPECT_EQ(static_cast<std::size_t>(table->GetNumStencils()), count);
    const auto eval = [&](std::size_t s, const std::vector<double>& w) {
        double x = 0, y = 0, z = 0;
        const int off = table->GetOffsets()[s];
        for (int k = 0; k < table->GetSizes()[s]; ++k) {
            const Vec3& p = m.positions[static_cast<std::size_t>(table->GetControlIndices()[off + k])];
            x += w[off + k] * p.x;
            y += w[off + k] * p.y;
            z += w[off + k] * p.z;
        }
        return Vec3{static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)};
    };
    std::vector<LimitSample> out;
    for (const auto& [face, i] : order) {
        const std::size_t s = first_stencil[face] + i;
        out.push_back({eval(s, table->GetWeights()), eval(s, table->GetDuWeights()), eval(s, table->GetDvWeights())});
    }
    return out;
}

struct VertexLimit {
    std::vector<Vec3> position, normal;
};

// Limit positions and normals (tan1 x tan2) at the vertices of level 0.
VertexLimit osd_vertex_limits(const ControlMesh& m) {
    auto refiner = make_refiner(m);
    std::vector<DPoint> src(m.positions.size()), pos(src.size()), t1(src.size()), t2(src.size());
    for (std::size_t i = 0; i < src.size(); ++i) src[i] = {m.positions[i].x, m.positions[i].y, m.positions[i].z};
    Far::PrimvarRefinerReal<double>(*refiner).Limit(src, pos, t1, t2);
    VertexLimit out;
    for (std::size_t i = 0; i < src.size(); ++i) {
        out.position.push_back(to_vec(pos[i]));
        const DPoint& a = t1[i];
        const DPoint& b = t2[i];
        out.normal.push_back(to_vec({a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}));
    }
    return out;
}

// ---- patch helpers ---------------------------------------------------------------------------

PatchFrame evaluate(const SubdivisionModel& model) {
    PatchFrame frame;
    evaluate_patches(model, model.mesh.positions, 0, frame);
    return frame;
}

// Normal of patch p at (u, v): tangent patches where present, else the geometry derivatives.
Vec3 patch_normal(const PatchFrame& frame, std::size_t p, float u, float v) {
    const std::int32_t t = frame.info[p].tangent_index;
    if (t >= 0) return evaluate_tangent_normal(frame.tangents[static_cast<std::size_t>(t)], u, v);
    return evaluate_surface(frame.patches[p], u, v).normal;
}

// Angle between two vectors; atan2 of |a x b| and a.b in double stays accurate near 0 (acos of a
// float dot product cannot resolve angles below ~3e-4).
float angle_between(Vec3 a, Vec3 b) {
    const double ax = a.x, ay = a.y, az = a.z, bx = b.x, by = b.y, bz = b.z;
    const double cx = ay * bz - az * by, cy = az * bx - ax * bz, cz = ax * by - ay * bx;
    return static_cast<float>(std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), ax * bx + ay * by + az * bz));
}

// (u, v) of face corner q: corners (v0 v1 v2 v3) sit at (0,0), (1,0), (1,1), (0,1).
constexpr float kCornerU[4] = {0, 1, 1, 0};
constexpr float kCornerV[4] = {0, 0, 1, 1};
// Bezier control point index of face corner q.
constexpr int kCornerCp[4] = {0, 3, 15, 12};

// (u, v) at parameter t along quad edge q (corner q -> corner q+1).
void edge_uv(int q, float t, float& u, float& v) {
    u = kCornerU[q] + (kCornerU[(q + 1) % 4] - kCornerU[q]) * t;
    v = kCornerV[q] + (kCornerV[(q + 1) % 4] - kCornerV[q]) * t;
}

struct SeamReport {
    std::size_t edges = 0, checked_normals = 0;
    float max_gap = 0, max_normal_angle = 0;
};

// For every interior edge shared by two patches: position gap and angle between the two normals
// (normals compared only where at least one side is extraordinary: regular-regular is C1 by the
// exactness test).
SeamReport seams(const SubdivisionModel& model, const PatchFrame& frame) {
    const ControlMesh& m = model.mesh;
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::pair<std::size_t, int>> half;
    // Patches of an all-quad mesh are its faces, in order.
    for (std::size_t f = 0; f < m.face_count(); ++f)
        for (int q = 0; q < 4; ++q) half[{m.face_vertices[4 * f + q], m.face_vertices[4 * f + (q + 1) % 4]}] = {f, q};
    SeamReport r;
    for (const auto& [key, fq] : half) {
        if (key.first > key.second) continue;
        const auto other = half.find({key.second, key.first});
        if (other == half.end()) continue;
        ++r.edges;
        const auto [f, q] = fq;
        const auto [g, qg] = other->second;
        const bool compare_normals = frame.info[f].extraordinary || frame.info[g].extraordinary;
        for (int s = 0; s <= 8; ++s) {
            const float t = static_cast<float>(s) / 8;
            float u0, v0, u1, v1;
            edge_uv(q, t, u0, v0);
            edge_uv(qg, 1 - t, u1, v1);
            const Vec3 a = evaluate_position(frame.patches[f], u0, v0);
            const Vec3 b = evaluate_position(frame.patches[g], u1, v1);
            r.max_gap = std::max(r.max_gap, length(a - b));
            if (compare_normals) {
                ++r.checked_normals;
                r.max_normal_angle = std::max(
                    r.max_normal_angle, angle_between(patch_normal(frame, f, u0, v0), patch_normal(frame, g, u1, v1)));
            }
        }
    }
    return r;
}

// Faces touching a vertex of valence != 4 (closed meshes: valence = number of faces).
std::size_t count_faces_at_irregular_vertices(const ControlMesh& m) {
    std::vector<int> faces_at(m.positions.size(), 0);
    for (std::uint32_t v : m.face_vertices) ++faces_at[v];
    std::size_t n = 0;
    for (std::size_t f = 0; f < m.face_count(); ++f) {
        bool irregular = false;
        for (std::uint32_t c = m.face_offsets[f]; c < m.face_offsets[f + 1]; ++c)
            irregular |= faces_at[m.face_vertices[c]] != 4;
        n += irregular;
    }
    return n;
}

std::string sci(double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3e", x);
    return buf;
}

std::string error_of(const ControlMesh& m) {
    try {
        build_acc_model(m);
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

class AccModels : public ::testing::TestWithParam<const char*> {};

}  // namespace

// ---- 1. regular patches are the exact limit surface -----------------------------------------

TEST_P(AccModels, RegularPatchesMatchOpenSubdivLimitSurface) {
    const ControlMesh mesh = load_model(GetParam());
    const SubdivisionModel model = build_acc_model(mesh);
    const PatchFrame frame = evaluate(model);
    const float radius = compute_bounds(mesh.positions).radius();

    std::mt19937 rng(7);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    std::vector<Location> locations;
    std::vector<std::size_t> patch_of;
    for (std::size_t p = 0; p < model.patch_count(); ++p) {
        if (model.patches[p].extraordinary) continue;
        for (int s = 0; s < 6; ++s) {
            locations.push_back({static_cast<int>(model.patches[p].base_face), uniform(rng), uniform(rng)});
            patch_of.push_back(p);
        }
    }
    ASSERT_GT(locations.size(), 0u);
    const std::vector<LimitSample> ref = osd_limit_surface(mesh, locations);
    ASSERT_EQ(ref.size(), locations.size());
    float max_err = 0, max_du_err = 0;
    for (std::size_t i = 0; i < locations.size(); ++i) {
        const SurfacePoint sp = evaluate_surface(frame.patches[patch_of[i]], locations[i].u, locations[i].v);
        max_err = std::max(max_err, length(sp.position - ref[i].position));
        max_du_err = std::max({max_du_err, length(sp.du - ref[i].du), length(sp.dv - ref[i].dv)});
    }
    RecordProperty("max_position_error_over_radius", sci(max_err / radius));
    EXPECT_LT(max_err, 1e-6f * radius) << "regular ACC patches must be the exact limit surface";
    EXPECT_LT(max_du_err, 1e-5f * radius);
}

// ---- 2. corners = limit positions; tangent-patch normals = limit normals --------------------

TEST_P(AccModels, CornersAreLimitPositionsAndTangentNormalsAreLimitNormals) {
    const ControlMesh mesh = load_model(GetParam());
    const SubdivisionModel model = build_acc_model(mesh);
    const PatchFrame frame = evaluate(model);
    const VertexLimit limit = osd_vertex_limits(mesh);
    const float radius = compute_bounds(mesh.positions).radius();

    float max_pos = 0, max_angle = 0;
    std::size_t normals = 0, same_sense = 0;
    for (std::size_t p = 0; p < model.patch_count(); ++p) {
        const std::uint32_t f = model.patches[p].base_face;
        for (int q = 0; q < 4; ++q) {
            const std::uint32_t v = mesh.face_vertices[4 * f + q];
            max_pos = std::max(max_pos, length(xyz(frame.patches[p].cp[kCornerCp[q]]) - limit.position[v]));
            if (!model.patches[p].extraordinary) continue;
            const Vec3 n = patch_normal(frame, p, kCornerU[q], kCornerV[q]);
            ASSERT_GT(length(n), 0.0f);
            // OpenSubdiv's tangent pair may be ordered either way: compare lines, then check that
            // ours faces outwards below.
            const float a = angle_between(n, limit.normal[v]);
            max_angle = std::max(max_angle, std::min(a, 3.14159265f - a));
            same_sense += dot(n, limit.normal[v]) > 0;
            ++normals;
        }
    }
    RecordProperty("max_corner_error_over_radius", sci(max_pos / radius));
    RecordProperty("max_corner_normal_angle_rad", sci(max_angle));
    EXPECT_LT(max_pos, 1e-6f * radius);
    EXPECT_GT(normals, 0u);
    EXPECT_LT(max_angle, 1e-4f) << "tangent-patch normal at a corner must be the limit normal";
    EXPECT_TRUE(same_sense == 0 || same_sense == normals) << "normals must agree with OpenSubdiv's in sense everywhere";
}

TEST_P(AccModels, NormalsFaceOutwardsAndTexcoordsFollowCorners) {
    const ControlMesh mesh = load_model(GetParam());
    const SubdivisionModel model = build_acc_model(mesh);
    const PatchFrame frame = evaluate(model);
    ASSERT_TRUE(mesh.has_texcoords());
    for (std::size_t p = 0; p < model.patch_count(); ++p) {
        const std::uint32_t f = model.patches[p].base_face;
        ASSERT_EQ(f, p);
        const Vec3* c[4];
        for (int q = 0; q < 4; ++q) c[q] = &mesh.positions[mesh.face_vertices[4 * f + q]];
        const Vec3 face_normal = cross(*c[2] - *c[0], *c[3] - *c[1]);
        EXPECT_GT(dot(patch_normal(frame, p, 0.5f, 0.5f), face_normal), 0.0f) << "patch " << p;
        const Vec2 t0 = mesh.texcoords[mesh.face_texcoords[4 * f + 0]];
        const Vec2 t2 = mesh.texcoords[mesh.face_texcoords[4 * f + 2]];
        const Vec2 t3 = mesh.texcoords[mesh.face_texcoords[4 * f + 3]];
        EXPECT_EQ(model.patches[p].uv[0].x, t0.x);
        EXPECT_EQ(model.patches[p].uv[2].y, t3.y);
        EXPECT_EQ(model.patches[p].uv[3].x, t2.x);
    }
}

// Extraordinary patches are an approximation: bounded distance to the limit surface and normals
// close to the limit normals (a loose sanity bound; the exact checks are above).
TEST_P(AccModels, ExtraordinaryPatchesStayCloseToLimitSurface) {
    const ControlMesh mesh = load_model(GetParam());
    const SubdivisionModel model = build_acc_model(mesh);
    const PatchFrame frame = evaluate(model);
    const float radius = compute_bounds(mesh.positions).radius();
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    std::vector<Location> locations;
    std::vector<std::size_t> patch_of;
    for (std::size_t p = 0; p < model.patch_count(); ++p) {
        if (!model.patches[p].extraordinary) continue;
        for (int s = 0; s < 4; ++s) {
            locations.push_back({static_cast<int>(p), uniform(rng), uniform(rng)});
            patch_of.push_back(p);
        }
    }
    const std::vector<LimitSample> ref = osd_limit_surface(mesh, locations);
    ASSERT_EQ(ref.size(), locations.size());
    float max_err = 0, max_angle = 0;
    for (std::size_t i = 0; i < locations.size(); ++i) {
        const float u = locations[i].u, v = locations[i].v;
        max_err = std::max(max_err, length(evaluate_position(frame.patches[patch_of[i]], u, v) - ref[i].position));
        max_angle =
            std::max(max_angle, angle_between(patch_normal(frame, patch_of[i], u, v), cross(ref[i].du, ref[i].dv)));
    }
    RecordProperty("max_distance_over_radius", sci(max_err / radius));
    RecordProperty("max_normal_angle_rad", sci(max_angle));
    EXPECT_LT(max_err, 0.01f * radius);
    EXPECT_LT(max_angle, 0.35f);
}

// ---- 3. watertight geometry, continuous normal field ----------------------------------------

TEST_P(AccModels, PatchesAreWatertightAndNormalFieldIsContinuous) {
    const ControlMesh mesh = load_model(GetParam());
    const SubdivisionModel model = build_acc_model(mesh);
    const PatchFrame frame = evaluate(model);
    const float radius = compute_bounds(mesh.positions).radius();
    const SeamReport r = seams(model, frame);
    RecordProperty("max_gap_over_radius", sci(r.max_gap / radius));
    RecordProperty("max_seam_normal_angle_rad", sci(r.max_normal_angle));
    EXPECT_EQ(r.edges, 2 * mesh.face_count());  // closed quad mesh: E = 2F
    EXPECT_GT(r.checked_normals, 0u);
    EXPECT_LT(r.max_gap, 1e-6f * radius);
    EXPECT_LT(r.max_normal_angle, 2e-4f);
}

// ---- 4. counts --------------------------------------------------------------------------------

TEST(Acc, PatchAndExtraordinaryCountsOfTestModels) {
    struct Expected {
        const char* file;
        std::size_t patches, extraordinary;
    };
    for (const Expected& e : {Expected{"bigguy.obj", 1450, 592}, Expected{"monsterfrog.obj", 1292, 764}}) {
        const ControlMesh mesh = load_model(e.file);
        const SubdivisionModel model = build_acc_model(mesh);
        EXPECT_EQ(model.patch_count(), e.patches) << e.file;
        EXPECT_EQ(model.extraordinary_count(), e.extraordinary) << e.file;
        EXPECT_EQ(model.extraordinary_count(), count_faces_at_irregular_vertices(mesh)) << e.file;
        EXPECT_EQ(model.patch_points.rows(), 16 * model.patch_count());
        EXPECT_EQ(model.tangent_points.rows(), 24 * model.extraordinary_count());
        std::int32_t next_tangent = 0;
        for (const PatchInfo& p : model.patches) {
            if (p.extraordinary)
                EXPECT_EQ(p.tangent_index, next_tangent++);
            else
                EXPECT_EQ(p.tangent_index, -1);
        }
        EXPECT_TRUE(model.mesh.warnings.empty());
        EXPECT_EQ(model.scheme, Scheme::acc);
    }
}

INSTANTIATE_TEST_SUITE_P(TestModels, AccModels, ::testing::Values("bigguy.obj", "monsterfrog.obj"),
                         [](const auto& info) {
                             return std::string(info.param).substr(0, std::string(info.param).find('.'));
                         });

// ---- 5. boundaries, non-quads, invalid input -------------------------------------------------

TEST(Acc, OpenRegularGridIsTheExactBoundaryLimitSurface) {
    const ControlMesh mesh = make_grid(5, 4);
    const SubdivisionModel model = build_acc_model(mesh);
    ASSERT_EQ(model.patch_count(), 20u);
    EXPECT_EQ(model.extraordinary_count(), 0u);  // interior valence 4, boundary 2 faces, corners 1 face
    const PatchFrame frame = evaluate(model);
    std::vector<Location> locations;
    for (int f = 0; f < 20; ++f)
        for (float u : {0.0f, 0.3f, 1.0f})
            for (float v : {0.0f, 0.6f, 1.0f}) locations.push_back({f, u, v});
    const std::vector<LimitSample> ref = osd_limit_surface(mesh, locations);
    ASSERT_EQ(ref.size(), locations.size());
    for (std::size_t i = 0; i < locations.size(); ++i) {
        const SurfacePoint sp = evaluate_surface(frame.patches[static_cast<std::size_t>(locations[i].face)],
                                                 locations[i].u, locations[i].v);
        EXPECT_LT(length(sp.position - ref[i].position), 1e-5f) << "face " << locations[i].face;
        EXPECT_LT(length(sp.du - ref[i].du) + length(sp.dv - ref[i].dv), 1e-4f) << "face " << locations[i].face;
    }
    const SeamReport r = seams(model, frame);
    EXPECT_LT(r.max_gap, 1e-5f);
}

TEST(Acc, IrregularBoundaryVertexGivesSaneExtraordinaryPatches) {
    const ControlMesh mesh = make_boundary_fan();
    const SubdivisionModel model = build_acc_model(mesh);
    ASSERT_EQ(model.patch_count(), 3u);
    EXPECT_EQ(model.extraordinary_count(), 3u);
    const PatchFrame frame = evaluate(model);
    for (const BezierPatch& p : frame.patches)
        for (const Vec4& c : p.cp) ASSERT_TRUE(is_finite(xyz(c)));

    // Corners: limit positions and limit normals, including the 3-face boundary vertex.
    const VertexLimit limit = osd_vertex_limits(mesh);
    for (std::size_t p = 0; p < 3; ++p)
        for (int q = 0; q < 4; ++q) {
            const std::uint32_t v = mesh.face_vertices[4 * p + q];
            EXPECT_LT(length(xyz(frame.patches[p].cp[kCornerCp[q]]) - limit.position[v]), 1e-5f) << p << "/" << q;
            const Vec3 n = patch_normal(frame, p, kCornerU[q], kCornerV[q]);
            const float a = angle_between(n, limit.normal[v]);
            EXPECT_LT(std::min(a, 3.14159265f - a), 2e-4f) << "patch " << p << " corner " << q;
            EXPECT_GT(n.z, 0.0f);  // faces are counter-clockwise seen from +z
        }
    // The boundary is OpenSubdiv's boundary curve (cubic B-spline of the boundary vertices).
    std::vector<Location> locations;
    for (int f = 0; f < 3; ++f)
        for (float t : {0.0f, 0.25f, 0.5f, 0.8f, 1.0f}) {
            locations.push_back({f, t, 1.0f});  // edges v2-v3: boundary for all three faces
            locations.push_back({f, 1.0f, t});  // edge v1-v2: boundary
        }
    locations.push_back({0, 0.4f, 0.0f});  // edge v0-v1 of face 0 lies on the boundary
    locations.push_back({2, 0.0f, 0.7f});  // edge v3-v0 of face 2 lies on the boundary
    const std::vector<LimitSample> ref = osd_limit_surface(mesh, locations);
    ASSERT_EQ(ref.size(), locations.size());
    for (std::size_t i = 0; i < locations.size(); ++i)
        EXPECT_LT(length(evaluate_position(frame.patches[static_cast<std::size_t>(locations[i].face)], locations[i].u,
                                           locations[i].v) -
                         ref[i].position),
                  1e-5f)
            << "face " << locations[i].face << " (" << locations[i].u << ", " << locations[i].v << ")";
    const SeamReport r = seams(model, frame);
    EXPECT_EQ(r.edges, 2u);
    EXPECT_LT(r.max_gap, 1e-5f);
    EXPECT_LT(r.max_normal_angle, 2e-4f);
}

TEST(Acc, NonQuadMeshIsRefinedOnceAndStaysOverOriginalVertices) {
    // A closed pentagonal prism with one end split into triangles: pentagon + 5 quads + 5 triangles.
    std::vector<Vec3> p;
    for (int k = 0; k < 5; ++k) {
        const float a = 2 * 3.14159265f * static_cast<float>(k) / 5;
        p.push_back({std::cos(a), std::sin(a), 0});
        p.push_back({std::cos(a), std::sin(a), 1.5f});
    }
    p.push_back({0, 0, 2.0f});                                       // apex: 10
    std::vector<std::vector<std::uint32_t>> faces{{8, 6, 4, 2, 0}};  // bottom, seen from below
    for (std::uint32_t k = 0; k < 5; ++k) {
        const std::uint32_t a = 2 * k, b = 2 * ((k + 1) % 5);
        faces.push_back({a, b, b + 1, a + 1});
        faces.push_back({a + 1, b + 1, 10});
    }
    ControlMesh mesh = make_mesh("prism", p, faces);
    const SubdivisionModel model = build_acc_model(mesh);
    EXPECT_EQ(model.patch_count(), 5u + 5 * 4 + 5 * 3);
    EXPECT_EQ(model.mesh.positions.size(), mesh.positions.size());  // original control mesh
    for (std::uint32_t i : model.patch_points.indices) ASSERT_LT(i, mesh.positions.size());
    for (std::uint32_t i : model.tangent_points.indices) ASSERT_LT(i, mesh.positions.size());
    // Children of each face come in order, one per corner.
    std::size_t p_index = 0;
    for (std::size_t f = 0; f < mesh.face_count(); ++f)
        for (std::uint32_t k = 0; k < mesh.face_size(f); ++k) EXPECT_EQ(model.patches[p_index++].base_face, f);

    // Corners equal the limit positions of the refined mesh and the surface is closed and smooth.
    const RefinedMesh refined = refine_uniform_once(mesh);
    const VertexLimit limit = osd_vertex_limits(refined.mesh);
    const PatchFrame frame = evaluate(model);
    for (std::size_t q = 0; q < model.patch_count(); ++q)
        for (int c = 0; c < 4; ++c) {
            const std::uint32_t v = refined.mesh.face_vertices[4 * q + c];
            EXPECT_LT(length(xyz(frame.patches[q].cp[kCornerCp[c]]) - limit.position[v]), 1e-5f);
            const Vec3 n = patch_normal(frame, q, kCornerU[c], kCornerV[c]);
            const float a = angle_between(n, limit.normal[v]);
            EXPECT_LT(std::min(a, 3.14159265f - a), 2e-4f);
        }
    SubdivisionModel on_refined = model;
    on_refined.mesh = refined.mesh;  // seams() walks the faces of the mesh the patches come from
    const SeamReport r = seams(on_refined, frame);
    EXPECT_EQ(r.edges, 2 * model.patch_count());
    EXPECT_LT(r.max_gap, 1e-5f);
    EXPECT_LT(r.max_normal_angle, 2e-4f);
}

TEST(Acc, RejectsNonManifoldAndInconsistentMeshes) {
    // Three quads on one edge (0,1).
    const std::vector<Vec3> p{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {1, -1, 0}, {0, -1, 0}, {1, 0, 1}, {0, 0, 1}};
    const ControlMesh fin = make_mesh("fin.obj", p, {{0, 1, 2, 3}, {1, 0, 5, 4}, {0, 1, 6, 7}});
    const std::string fin_error = error_of(fin);
    EXPECT_EQ(fin_error.rfind("fin.obj: ", 0), 0u) << fin_error;
    EXPECT_NE(fin_error.find("non-manifold edge"), std::string::npos) << fin_error;
    EXPECT_EQ(fin_error.find('\n'), std::string::npos);

    // Two quads on edge (0,1) walking it the same way: one is flipped.
    const ControlMesh flipped = make_mesh("flip.obj", p, {{0, 1, 2, 3}, {0, 1, 4, 5}});
    const std::string flip_error = error_of(flipped);
    EXPECT_EQ(flip_error.rfind("flip.obj: ", 0), 0u) << flip_error;
    EXPECT_NE(flip_error.find("oriented inconsistently"), std::string::npos) << flip_error;

    // Two quads touching at one vertex only (bowtie).
    const std::vector<Vec3> q{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {-1, 0, 0}, {-1, -1, 0}, {0, -1, 0}};
    const ControlMesh bowtie = make_mesh("bowtie.obj", q, {{0, 1, 2, 3}, {0, 4, 5, 6}});
    const std::string bowtie_error = error_of(bowtie);
    EXPECT_EQ(bowtie_error.rfind("bowtie.obj: ", 0), 0u) << bowtie_error;
    EXPECT_NE(bowtie_error.find("non-manifold vertex"), std::string::npos) << bowtie_error;

    // Non-quad input goes through OpenSubdiv's refinement, which must reject it as well.
    const ControlMesh tri_fin = make_mesh("trifin.obj", p, {{0, 1, 2}, {1, 0, 5}, {0, 1, 6}});
    EXPECT_EQ(error_of(tri_fin).rfind("trifin.obj: ", 0), 0u) << error_of(tri_fin);
}

TEST(Acc, CreasesAreIgnoredWithOneWarning) {
    ControlMesh mesh = make_grid(3, 3);
    mesh.creases.push_back({5, 6, 2.0f});
    const SubdivisionModel model = build_acc_model(mesh);
    ASSERT_EQ(model.mesh.warnings.size(), 1u);
    EXPECT_NE(model.mesh.warnings[0].find("acc"), std::string::npos);
    EXPECT_EQ(model.mesh.warnings[0].find('\n'), std::string::npos);
    // Same patches as without the crease.
    ControlMesh plain = make_grid(3, 3);
    EXPECT_EQ(build_acc_model(plain).patch_points.weights, model.patch_points.weights);
}

TEST(Acc, AnimatedPositionsMoveThePatchesLinearly) {
    const ControlMesh mesh = make_boundary_fan();
    const SubdivisionModel model = build_acc_model(mesh);
    std::vector<Vec3> moved = mesh.positions;
    for (Vec3& v : moved) v = v + Vec3{1, 2, 3};
    PatchFrame a, b;
    evaluate_patches(model, mesh.positions, 0, a);
    evaluate_patches(model, moved, 0, b);
    // Every row's weights sum to 1 (positions) or 0 (tangents): a translation moves points only.
    for (std::size_t p = 0; p < a.patches.size(); ++p)
        for (int k = 0; k < 16; ++k)
            EXPECT_LT(length(xyz(b.patches[p].cp[k]) - xyz(a.patches[p].cp[k]) - Vec3{1, 2, 3}), 1e-5f);
    for (std::size_t t = 0; t < a.tangents.size(); ++t)
        for (int k = 0; k < 12; ++k) {
            EXPECT_LT(length(b.tangents[t].du[k] - a.tangents[t].du[k]), 1e-5f);
            EXPECT_LT(length(b.tangents[t].dv[k] - a.tangents[t].dv[k]), 1e-5f);
        }
}

TEST(Acc, SmallClosedMeshes) {
    // Cube: every vertex has valence 3, so every patch is extraordinary at all four corners.
    const ControlMesh cube =
        make_mesh("cube", {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}},
                  {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}});
    const SubdivisionModel model = build_acc_model(cube);
    EXPECT_EQ(model.extraordinary_count(), 6u);
    const PatchFrame frame = evaluate(model);
    const SeamReport r = seams(model, frame);
    EXPECT_EQ(r.edges, 12u);
    EXPECT_LT(r.max_gap, 1e-6f);
    EXPECT_LT(r.max_normal_angle, 2e-4f);
    const VertexLimit limit = osd_vertex_limits(cube);
    for (std::size_t p = 0; p < 6; ++p)
        for (int q = 0; q < 4; ++q) {
            const std::uint32_t v = cube.face_vertices[4 * p + q];
            EXPECT_LT(length(xyz(frame.patches[p].cp[kCornerCp[q]]) - limit.position[v]), 1e-6f);
            const Vec3 n = patch_normal(frame, p, kCornerU[q], kCornerV[q]);
            EXPECT_GT(dot(n, limit.position[v] - Vec3{0.5f, 0.5f, 0.5f}), 0.0f);             // outwards
            EXPECT_LT(angle_between(n, limit.position[v] - Vec3{0.5f, 0.5f, 0.5f}), 1e-4f);  // symmetric cube
        }

    // Pillow: two quads on the same four edges, valence-2 vertices. Degenerate, but builds finite
    // points (the tangent-patch normal may vanish at the valence-2 corners, which patch.h allows).
    const ControlMesh pillow =
        make_mesh("pillow", {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 1, 2, 3}, {3, 2, 1, 0}});
    const PatchFrame pf = evaluate(build_acc_model(pillow));
    for (const BezierPatch& p : pf.patches)
        for (const Vec4& c : p.cp) EXPECT_TRUE(is_finite(xyz(c)));
    for (const TangentPatches& t : pf.tangents)
        for (int k = 0; k < 12; ++k) EXPECT_TRUE(is_finite(t.du[k]) && is_finite(t.dv[k]));
}
