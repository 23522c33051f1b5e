// Preprocessing is bit-identical across its speed and memory work (the work that made
// preprocessing scale): every stencil table, patch record and evaluated patch of a fixed set of meshes hashes
// to the value the code produced before that work (captured at 18c0849, before any change to
// src/import/acc.cpp, quad_topology.cpp, subdivision.cpp, refine.cpp or osd_topology.cpp).
//
// Why hashes and not properties: the optimisations (flat per-vertex rule tables, rows written
// straight into the stencil arrays, evaluation without temporary point arrays) must not move one
// bit of any weight or control point; the other import tests check the geometry itself. A hash
// changes with any such bit, and the failure message names the part (stencil table, patch
// records, evaluated patches) that moved.
//
// The hashes are of this toolchain's results: Release and Debug agree (-ffp-contract=off, no
// -march), but another libm (the tangent masks' cos/sin) or OpenSubdiv release may move bits; then
// re-capture them (the failure prints the new lines) from a tree whose preprocessing is trusted.
//
// Meshes: the shipped BigGuy and MonsterFrog (all quads, extraordinary vertices), and generated
// ones for the paths the shipped ones miss: a closed cube grid (valence-3 vertices, tangent
// patches), an L-shaped open grid with creases, a corner and texture coordinates (boundary
// vertices with 1, 2 and 3 faces; osd uses the creases, acc warns and ignores them), and a
// closed mesh with triangles and pentagons and face-varying texture coordinates (acc's uniform
// refinement through OpenSubdiv and the composition of stencils). Each under both schemes, the
// evaluation also with one 1-to-4 split.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "patchcull/import/model_loader.h"
#include "patchcull/import/obj.h"
#include "patchcull/import/subdivision.h"

using namespace patchcull;

namespace {

// FNV-1a, 64 bit, over explicit fields (no struct padding).
class Hash {
public:
    void bytes(const void* data, std::size_t n) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < n; ++i) {
            h_ ^= p[i];
            h_ *= 0x100000001b3ull;
        }
    }
    template <class T>
    void value(const T& v) {
        bytes(&v, sizeof v);
    }
    void floats(const float* f, std::size_t n) { bytes(f, n * sizeof(float)); }
    std::uint64_t get() const { return h_; }

private:
    std::uint64_t h_ = 0xcbf29ce484222325ull;
};

std::uint64_t hash_stencils(const PointStencils& s) {
    Hash h;
    h.value(s.offsets.size());
    h.bytes(s.offsets.data(), s.offsets.size() * sizeof(std::uint32_t));
    h.bytes(s.indices.data(), s.indices.size() * sizeof(std::uint32_t));
    h.floats(s.weights.data(), s.weights.size());
    return h.get();
}

std::uint64_t hash_infos(const std::vector<PatchInfo>& infos) {
    Hash h;
    h.value(infos.size());
    for (const PatchInfo& p : infos) {
        for (const Vec2& uv : p.uv) {
            h.value(uv.x);
            h.value(uv.y);
        }
        h.value(p.base_face);
        h.value(static_cast<std::uint8_t>(p.extraordinary));
        h.value(p.tangent_index);
        h.value(p.depth);
    }
    return h.get();
}

std::uint64_t hash_frame(const PatchFrame& frame) {
    Hash h;
    h.value(frame.patches.size());
    for (const BezierPatch& p : frame.patches)
        for (const Vec4& c : p.cp) {
            h.value(c.x);
            h.value(c.y);
            h.value(c.z);
            h.value(c.w);
        }
    h.value(frame.tangents.size());
    for (const TangentPatches& t : frame.tangents) {
        for (const Vec3& d : t.du) {
            h.value(d.x);
            h.value(d.y);
            h.value(d.z);
        }
        for (const Vec3& d : t.dv) {
            h.value(d.x);
            h.value(d.y);
            h.value(d.z);
        }
    }
    h.value(hash_infos(frame.info));
    return h.get();
}

std::uint64_t hash_warnings(const std::vector<std::string>& warnings) {
    Hash h;
    h.value(warnings.size());
    for (const std::string& w : warnings) {
        h.value(w.size());
        h.bytes(w.data(), w.size());
    }
    return h.get();
}

void add_face(ControlMesh& m, std::initializer_list<std::uint32_t> v) {
    m.face_vertices.insert(m.face_vertices.end(), v);
    m.face_offsets.push_back(static_cast<std::uint32_t>(m.face_vertices.size()));
}

// Closed cube, n x n quads per side, outward (valence-3 corners: extraordinary patches).
ControlMesh cube_grid(int n) {
    ControlMesh m;
    m.name = "cube_grid";
    std::vector<std::int64_t> key_to_vertex;
    const std::size_t s = static_cast<std::size_t>(n) + 1;  // points along an edge
    key_to_vertex.assign(s * s * s, -1);
    const auto vertex = [&](int x, int y, int z) {
        const auto u = [](int i) { return static_cast<std::size_t>(i); };
        std::int64_t& v = key_to_vertex[(u(x) * s + u(y)) * s + u(z)];
        if (v < 0) {
            v = static_cast<std::int64_t>(m.positions.size());
            // Slightly uneven spacing so that no weight meets a lucky cancellation.
            const auto c = [n](int i) {
                return static_cast<float>(i) / static_cast<float>(n) - 0.5f + 0.01f * static_cast<float>(i % 3);
            };
            m.positions.push_back({c(x), c(y), c(z)});
        }
        return static_cast<std::uint32_t>(v);
    };
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side)
            for (int a = 0; a < n; ++a)
                for (int b = 0; b < n; ++b) {
                    std::uint32_t q[4];
                    const int da[4] = {0, 1, 1, 0}, db[4] = {0, 0, 1, 1};
                    for (int k = 0; k < 4; ++k) {
                        int c[3];
                        c[axis] = side * n;
                        c[(axis + 1) % 3] = a + da[k];
                        c[(axis + 2) % 3] = b + db[k];
                        q[k] = vertex(c[0], c[1], c[2]);
                    }
                    if (side == 0)
                        add_face(m, {q[3], q[2], q[1], q[0]});
                    else
                        add_face(m, {q[0], q[1], q[2], q[3]});
                }
    return m;
}

// An L-shaped open grid (the notch's corner has 3 faces), wavy heights, per-corner texcoords,
// a crease row (sharpness 2 and infinite) and a corner.
ControlMesh l_grid_with_creases() {
    ControlMesh m;
    m.name = "l_grid";
    const int n = 10;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const float x = static_cast<float>(i) * 0.1f, y = static_cast<float>(j) * 0.1f;
            m.positions.push_back({x, y, 0.05f * std::sin(7 * x) * std::cos(5 * y)});
            m.texcoords.push_back({x, y});
        }
    const auto v = [n](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            if (i >= n / 2 && j >= n / 2) continue;  // the notch
            add_face(m, {v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)});
            const std::uint32_t* f = &m.face_vertices[m.face_vertices.size() - 4];
            m.face_texcoords.insert(m.face_texcoords.end(), f, f + 4);
        }
    for (int i = 1; i < n - 1; ++i) m.creases.push_back({v(i, 3), v(i + 1, 3), i < 4 ? 2.0f : 10.0f});
    m.corners.push_back({v(n / 2, n / 2), 0, 3.0f});
    return m;
}

// Closed, with triangles and pentagons: a pentagonal prism with a pyramid (5 triangles) on top,
// texcoords with a seam (each face its own texcoords).
ControlMesh prism_house() {
    ControlMesh m;
    m.name = "prism_house";
    const int n = 5;
    for (int ring = 0; ring < 2; ++ring)
        for (int k = 0; k < n; ++k) {
            const float a = 6.2831853f * static_cast<float>(k) / n;
            m.positions.push_back({std::cos(a), std::sin(a), ring ? 1.0f : 0.0f});
        }
    m.positions.push_back({0.1f, -0.05f, 1.7f});  // apex
    const std::uint32_t apex = 2 * n;
    const auto lo = [](int k) { return static_cast<std::uint32_t>(k % n); };
    const auto hi = [](int k) { return static_cast<std::uint32_t>(n + k % n); };
    add_face(m, {lo(4), lo(3), lo(2), lo(1), lo(0)});  // bottom pentagon, facing down
    for (int k = 0; k < n; ++k) add_face(m, {lo(k), lo(k + 1), hi(k + 1), hi(k)});
    for (int k = 0; k < n; ++k) add_face(m, {hi(k), hi(k + 1), apex});
    for (std::size_t c = 0; c < m.face_vertices.size(); ++c) {
        const Vec3 p = m.positions[m.face_vertices[c]];
        m.texcoords.push_back({0.5f + 0.4f * p.x + 0.01f * static_cast<float>(c % 7), 0.5f + 0.4f * p.y + 0.3f * p.z});
        m.face_texcoords.push_back(static_cast<std::uint32_t>(c));
    }
    return m;
}

struct Expected {
    std::uint64_t points, tangents, infos, frame, split, warnings;
};

void print_actual(const std::string& what, const Expected& e) {
    std::printf("{\"%s\", {0x%016llxull, 0x%016llxull, 0x%016llxull, 0x%016llxull, 0x%016llxull, 0x%016llxull}},\n",
                what.c_str(), static_cast<unsigned long long>(e.points), static_cast<unsigned long long>(e.tangents),
                static_cast<unsigned long long>(e.infos), static_cast<unsigned long long>(e.frame),
                static_cast<unsigned long long>(e.split), static_cast<unsigned long long>(e.warnings));
}

Expected hashes_of(const SubdivisionModel& model) {
    Expected e{};
    e.points = hash_stencils(model.patch_points);
    e.tangents = hash_stencils(model.tangent_points);
    e.infos = hash_infos(model.patches);
    PatchFrame frame;
    evaluate_patches(model, model.mesh.positions, 0, frame);
    e.frame = hash_frame(frame);
    evaluate_patches(model, model.mesh.positions, 1, frame);
    e.split = hash_frame(frame);
    e.warnings = hash_warnings(model.mesh.warnings);
    return e;
}

void expect_identical(const std::string& what, const SubdivisionModel& model, const Expected& want) {
    const Expected got = hashes_of(model);
    EXPECT_EQ(got.points, want.points) << what << ": patch point stencils changed";
    EXPECT_EQ(got.tangents, want.tangents) << what << ": tangent stencils changed";
    EXPECT_EQ(got.infos, want.infos) << what << ": patch records changed";
    EXPECT_EQ(got.frame, want.frame) << what << ": evaluated patches changed";
    EXPECT_EQ(got.split, want.split) << what << ": evaluated patches after one split changed";
    EXPECT_EQ(got.warnings, want.warnings) << what << ": warnings changed";
    if (got.points != want.points || got.tangents != want.tangents || got.infos != want.infos ||
        got.frame != want.frame || got.split != want.split || got.warnings != want.warnings)
        print_actual(what, got);
}

struct Case {
    const char* name;
    Expected acc, osd;
};

ControlMesh mesh_of(const std::string& name) {
    if (name == "bigguy" || name == "monsterfrog") {
        ControlMesh m = load_obj(shipped_model_path(name + ".obj"));
        orient_outward(m);  // as load_model does
        return m;
    }
    if (name == "cube_grid") return cube_grid(6);
    if (name == "l_grid") return l_grid_with_creases();
    return prism_house();
}

// Captured at 18c0849 (before the preprocessing speed and memory work).
const Case kCases[] = {
    {"bigguy",
     {0xd266c3255b0f0a21ull, 0xe538f67cd2b85797ull, 0xd6a2dd91032be23dull, 0xb662ca8e0b71c1e6ull, 0xd3ec6372b7c82122ull,
      0xa8c7f832281a39c5ull},
     {0xed8bf33812725076ull, 0x5f242d39c2422be4ull, 0x22a214bbb466c521ull, 0x3ee69bd2193b77f7ull, 0x8f19ed5eecd660f9ull,
      0xa8c7f832281a39c5ull}},
    {"monsterfrog",
     {0x4f3f4ab105799148ull, 0xd29ba2ec0bce953full, 0xee58b1279e4e091cull, 0x0b545b0852b079ffull, 0x0093540531d39d3full,
      0xa8c7f832281a39c5ull},
     {0x01c747cfe225dca3ull, 0x5f242d39c2422be4ull, 0x3fd49bcbcc58b679ull, 0xb4520acbf1d5404eull, 0x2941ee7f1aaedc81ull,
      0xa8c7f832281a39c5ull}},
    {"cube_grid",
     {0x33a6f0c1c66c47c2ull, 0x6aa1b8584e41b991ull, 0xc5cf28d505bf87f5ull, 0x34689bc622a9e7e8ull, 0xe5b5ec48bc9c026full,
      0xa8c7f832281a39c5ull},
     {0x633bdbdac3369ff2ull, 0x5f242d39c2422be4ull, 0x85f82a5686f703caull, 0x92d6fa442db6c357ull, 0x58ba0b6e77de5132ull,
      0xa8c7f832281a39c5ull}},
    {"l_grid",
     {0x0711db01da61e8f3ull, 0xec49e6ebe0ecf4cdull, 0x2cdc8c640560a1cdull, 0x9d108551b0c17d59ull, 0xe78988a1120a088eull,
      0xf100f175872cd754ull},
     {0xb082a40f888edb4aull, 0x5f242d39c2422be4ull, 0x534f903c2ce2ccceull, 0xb8fc21229b07c19aull, 0x4cc9a70cd520662cull,
      0xa8c7f832281a39c5ull}},
    {"prism_house",
     {0x918930dee7684aaaull, 0xe59ef72159fb3418ull, 0x0ce3a5dfe51ed22cull, 0xd873569cfecef5f6ull, 0x1c2de2d0eb003c05ull,
      0xa8c7f832281a39c5ull},
     {0xdd917886284af23aull, 0x5f242d39c2422be4ull, 0x81ba40b6a100a55bull, 0x1bbc7b7b92b6972dull, 0x21bad3137af31471ull,
      0xa8c7f832281a39c5ull}},
};

TEST(PreprocessingIdentity, PatchesAreBitIdenticalToTheReference) {
    for (const Case& c : kCases) {
        const ControlMesh mesh = mesh_of(c.name);
        expect_identical(std::string(c.name) + " acc", build_model(mesh, Scheme::acc), c.acc);
        expect_identical(std::string(c.name) + " osd", build_model(mesh, Scheme::osd), c.osd);
    }
}

// The hashes see every bit: one float weight nudged by one ulp changes the table's hash.
TEST(PreprocessingIdentity, HashSeesOneUlp) {
    SubdivisionModel model = build_model(cube_grid(3), Scheme::acc);
    const std::uint64_t before = hash_stencils(model.patch_points);
    model.patch_points.weights[model.patch_points.weights.size() / 2] =
        std::nextafter(model.patch_points.weights[model.patch_points.weights.size() / 2], 2.0f);
    EXPECT_NE(hash_stencils(model.patch_points), before);
}

}  // namespace
