// An OpenSubdiv Far::PatchTable culled in place (patchcull/import/osd_patch_table.h), against
// OpenSubdiv's own evaluation of the same table over the same vertex buffer.
//
// Shapes: OpenSubdiv's regression shapes in tests/data/opensubdiv (semi-sharp and infinitely
// sharp creases, corners, holes, boundaries under each interpolation rule, triangles) and the
// shipped bigguy, adaptively refined to levels 1-4 with Gregory-basis (Far's default) and
// B-spline-basis end caps. The vertex buffer holds every refined level and the local points,
// float3 or float4 at odd strides and offsets.
// (a) Each array's source describes the surface PatchTable::EvaluateBasis gives: the B-spline
//     arrays' Bezier conversion and the Gregory arrays' 20 points (evaluated by the definition in
//     core/patch_source.h) agree with Far at a grid of (s, t) on every patch, with the buffer at
//     the origin and translated by thousands of units.
// (b) No patch is culled that has a dense sample (Far's positions, normals from Far's
//     derivatives) inside the frustum, in front of a synthetic depth layer or facing the eye, in
//     every ClipDepth convention, the object at the origin and placed thousands of units out
//     with the camera (camera-relative, as docs/ENGINE.md asks; see check_cases); and every kind
//     of cull happens, Gregory end caps included (the checks can fail). Sathe's box
//     (cull_frustum_disp) is checked as the frustum is; the fused kernel's decision is the first
//     separate entry's that culls (frustum, ncone, Hi-Z), so their checks cover it.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyRefiner.h>

#include "import/osd_topology.h"
#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/clip_space.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/error.h"
#include "patchcull/core/fused_cull.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/patch_source.h"
#include "patchcull/import/obj.h"
#include "patchcull/import/osd_patch_table.h"

using namespace patchcull;
namespace Far = OpenSubdiv::Far;

namespace {

using EndCap = Far::PatchTableFactory::Options::EndCapType;
constexpr EndCap kGregoryEnds = Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS;
constexpr EndCap kBsplineEnds = Far::PatchTableFactory::Options::ENDCAP_BSPLINE_BASIS;

struct D3 {
    double x = 0, y = 0, z = 0;
    void Clear(void* = nullptr) { x = y = z = 0; }
    void AddWithWeight(const D3& p, double w) {
        x += w * p.x;
        y += w * p.y;
        z += w * p.z;
    }
};
D3 operator+(D3 a, D3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
D3 operator-(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
D3 operator*(D3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
D3 cross(D3 a, D3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double norm(D3 a) { return std::sqrt(dot(a, a)); }

const char* const kShapes[] = {"catmark_chaikin1",   "catmark_cubes_infsharp", "catmark_edgenone",
                               "catmark_edgeonly",   "catmark_helmet",         "catmark_hole_test1",
                               "catmark_hole_test2", "catmark_smoothtris1"};

struct Layout {
    int components;
    std::size_t stride, offset;
};

// One table over one vertex buffer.
struct Case {
    std::string name;
    osd_detail::RefinerPtr refiner;
    std::unique_ptr<const Far::PatchTable> table;
    std::vector<unsigned char> bytes;  // the vertex buffer
    std::vector<D3> points;            // its points as stored (floats, read back)
    OsdPatchTableSource source;
    D3 centre;
    double radius = 0;
};

// shape (a regression shape's name or a model under data/models), refined to level with the end
// caps given, its buffer in layout, every point moved by offset (in double, then stored as float).
std::unique_ptr<Case> make_case(const std::string& shape, int level, EndCap ends, const Layout& layout, D3 offset,
                                bool inf_sharp = false) {
    auto c = std::make_unique<Case>();
    const bool model = shape == "bigguy";
    const ControlMesh mesh = load_obj(std::string(PATCHCULL_SOURCE_DIR) +
                                      (model ? "/data/models/" : "/tests/data/opensubdiv/") + shape + ".obj");
    c->name = shape + " level " + std::to_string(level) + (ends == kGregoryEnds ? " gregory" : " bspline") +
              " ends, float" + std::to_string(layout.components) + (inf_sharp ? ", inf-sharp patches" : "") +
              (offset.x != 0 ? ", far from the origin" : "");
    c->refiner = osd_detail::create_refiner(mesh);
    Far::PatchTableFactory::Options options(level);
    options.SetEndCapType(ends);
    options.useInfSharpPatch = inf_sharp;
    c->refiner->RefineAdaptive(options.GetRefineAdaptiveOptions());
    c->table.reset(Far::PatchTableFactory::Create(*c->refiner, options));

    // Every level's vertices (Far's primvar refinement), then the local points.
    const int refined = c->refiner->GetNumVerticesTotal();
    std::vector<D3> all(static_cast<std::size_t>(refined + c->table->GetNumLocalPoints()));
    for (std::size_t v = 0; v < mesh.positions.size(); ++v)
        all[v] = D3{mesh.positions[v].x, mesh.positions[v].y, mesh.positions[v].z} + offset;
    Far::PrimvarRefinerReal<double> primvar(*c->refiner);
    D3* src = all.data();
    for (int l = 1; l <= c->refiner->GetMaxLevel(); ++l) {
        D3* dst = src + c->refiner->GetLevel(l - 1).GetNumVertices();
        primvar.Interpolate(l, src, dst);
        src = dst;
    }
    if (const auto* local = c->table->GetLocalPointStencilTable<float>())
        local->UpdateValues(all.data(), all.data() + refined);

    c->bytes.assign(all.size() * layout.stride + 16, 0xCD);
    c->points.resize(all.size());
    D3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
    for (std::size_t i = 0; i < all.size(); ++i) {
        const float xyzw[4] = {static_cast<float>(all[i].x), static_cast<float>(all[i].y), static_cast<float>(all[i].z),
                               1.0f};
        std::memcpy(c->bytes.data() + i * layout.stride + layout.offset, xyzw,
                    static_cast<std::size_t>(layout.components) * sizeof(float));
        c->points[i] = {xyzw[0], xyzw[1], xyzw[2]};
        lo = {std::min(lo.x, c->points[i].x), std::min(lo.y, c->points[i].y), std::min(lo.z, c->points[i].z)};
        hi = {std::max(hi.x, c->points[i].x), std::max(hi.y, c->points[i].y), std::max(hi.z, c->points[i].z)};
    }
    c->centre = (lo + hi) * 0.5;
    c->radius = 0.5 * norm(hi - lo);
    c->source = OsdPatchTableSource(
        *c->table, PointLayout{c->bytes.data(), layout.stride, layout.offset, layout.components, all.size()});
    return c;
}

// Far's evaluation of table patch `patch` (array a, index p in it) at the patch's own (s, t):
// position and du x dv (OpenSubdiv's derivatives, scaled by 2^depth: the direction is what counts).
struct Sample {
    D3 p, n;
};
Sample far_sample(const Case& c, int a, int p, std::size_t patch, double s, double t) {
    Far::PatchTable::PatchHandle h;
    h.arrayIndex = a;
    h.patchIndex = static_cast<Far::Index>(patch);
    const int per_patch = c.table->GetPatchArrayDescriptor(a).GetNumControlVertices();
    h.vertIndex = p * per_patch;
    const Far::PatchParam param = c.table->GetPatchParam(a, p);
    double u = s, v = t;
    param.Unnormalize(u, v);
    double w[20], wu[20], wv[20];
    c.table->EvaluateBasis(h, u, v, w, wu, wv);
    const Far::ConstIndexArray cv = c.table->GetPatchVertices(h);
    D3 pos, du, dv;
    for (int k = 0; k < cv.size(); ++k) {
        const D3 q = c.points[static_cast<std::size_t>(cv[k])];
        pos.AddWithWeight(q, w[k]);
        du.AddWithWeight(q, wu[k]);
        dv.AddWithWeight(q, wv[k]);
    }
    return {pos, cross(du, dv)};
}

// Point i of a source, as its layout stores it (Cartesian).
D3 source_point(const PatchSourceView& s, std::size_t i) {
    float q[4] = {0, 0, 0, 1};
    std::memcpy(q, static_cast<const char*>(s.points.data) + s.points.offset_bytes + i * s.points.stride_bytes,
                static_cast<std::size_t>(s.points.components) * sizeof(float));
    return {q[0] / q[3], q[1] / q[3], q[2] / q[3]};
}

void bernstein(double x, double b[4]) {
    const double y = 1 - x;
    b[0] = y * y * y;
    b[1] = 3 * x * y * y;
    b[2] = 3 * x * x * y;
    b[3] = x * x * x;
}

// The surface of patch p of source at (s, t), from the source alone: a B-spline patch through
// its Bezier conversion (source_bezier_patch), a Gregory patch by patch_source.h's definition (a
// bicubic Bezier patch whose interior points blend the corners' face points F+ and F-).
D3 source_surface(const PatchSourceView& src, std::size_t p, double s, double t) {
    double bs[4], bt[4];
    bernstein(s, bs);
    bernstein(t, bt);
    std::array<std::array<double, 4>, 16> bez{};
    if (src.basis == PatchBasis::gregory) {
        D3 g[20];
        for (int k = 0; k < 20; ++k) g[k] = source_point(src, src.indices[20 * p + static_cast<std::size_t>(k)]);
        const auto put = [&](int i, int j, D3 q) {
            bez[4 * static_cast<std::size_t>(j) + static_cast<std::size_t>(i)] = {q.x, q.y, q.z, 1};
        };
        // Boundary: corner c's P at (0,0), (3,0), (3,3), (0,3); E+ along the edge leaving c
        // counter-clockwise, E- along the edge arriving.
        const int at[12][3] = {{0, 0, 0},  {1, 0, 1},  {0, 1, 2},  {3, 0, 5},  {3, 1, 6},  {2, 0, 7},
                               {3, 3, 10}, {2, 3, 11}, {3, 2, 12}, {0, 3, 15}, {0, 2, 16}, {1, 3, 17}};
        for (const auto& e : at) put(e[0], e[1], g[e[2]]);
        const auto blend = [&](int i, int j, D3 fp, double a, D3 fm, double b) {
            put(i, j, a + b > 0 ? (fp * a + fm * b) * (1 / (a + b)) : fp);
        };
        blend(1, 1, g[3], s, g[4], t);
        blend(2, 1, g[8], t, g[9], 1 - s);
        blend(2, 2, g[13], 1 - s, g[14], 1 - t);
        blend(1, 2, g[18], 1 - t, g[19], s);
    } else {
        const BezierPatch b = source_bezier_patch(src, p);
        for (int k = 0; k < 16; ++k) bez[static_cast<std::size_t>(k)] = {b.cp[k].x, b.cp[k].y, b.cp[k].z, b.cp[k].w};
    }
    double h[4] = {0, 0, 0, 0};
    for (std::size_t j = 0; j < 4; ++j)
        for (std::size_t i = 0; i < 4; ++i)
            for (int k = 0; k < 4; ++k) h[k] += bs[i] * bt[j] * bez[4 * j + i][k];
    return {h[0] / h[3], h[1] / h[3], h[2] / h[3]};
}

// ---- (a) the sources describe Far's surface ------------------------------------------------------

// Largest distance between each source's surface and Far's over a 5 x 5 grid of every patch;
// fails beyond tol. Also checks the views' bookkeeping: first_patch, the index arrays as views
// into the table, the boundary masks.
void expect_same_surface(const Case& c, double tol, std::size_t& gregory_patches, std::size_t& boundary_patches) {
    ASSERT_EQ(c.source.arrays().size(), static_cast<std::size_t>(c.table->GetNumPatchArrays())) << c.name;
    ASSERT_EQ(c.source.patch_count(), static_cast<std::size_t>(c.table->GetNumPatchesTotal())) << c.name;
    EXPECT_TRUE(c.source.indices_are_views());
    std::size_t first = 0;
    int failures = 0;
    for (const OsdPatchArraySource& a : c.source.arrays()) {
        EXPECT_EQ(a.first_patch, first) << c.name;
        const int n = c.table->GetNumPatches(a.array);
        ASSERT_EQ(a.source.count, static_cast<std::size_t>(n)) << c.name;
        EXPECT_EQ(static_cast<const void*>(a.source.indices),
                  static_cast<const void*>(&c.table->GetPatchArrayVertices(a.array)[0]))
            << c.name << ": the indices must be the table's own";
        for (int p = 0; p < n; ++p) {
            const unsigned mask = a.source.boundary_mask ? a.source.boundary_mask[p] : 0u;
            EXPECT_EQ(mask,
                      a.source.basis == PatchBasis::bspline ? c.table->GetPatchParam(a.array, p).GetBoundary() : 0)
                << c.name;
            (a.source.basis == PatchBasis::gregory ? gregory_patches : boundary_patches) +=
                a.source.basis == PatchBasis::gregory || mask != 0;
            for (int i = 0; i < 5; ++i)
                for (int j = 0; j < 5; ++j) {
                    const double s = i / 4.0, t = j / 4.0;
                    const D3 want = far_sample(c, a.array, p, first + static_cast<std::size_t>(p), s, t).p;
                    const D3 got = source_surface(a.source, static_cast<std::size_t>(p), s, t);
                    const double e = norm(got - want);
                    if (!(e <= tol) && ++failures <= 5)
                        ADD_FAILURE() << c.name << ": patch " << first + static_cast<std::size_t>(p) << " ("
                                      << (a.source.basis == PatchBasis::gregory ? "gregory" : "bspline")
                                      << ", boundary " << mask << ") at (" << s << ", " << t << "): off by " << e
                                      << " (tolerance " << tol << ")";
                }
        }
        first += static_cast<std::size_t>(n);
    }
    EXPECT_EQ(failures, 0) << c.name;
}

TEST(OsdPatchTable, SourcesEvaluateToFarsSurface) {
    const Layout layouts[] = {{3, 28, 8}, {4, 36, 12}};
    std::size_t gregory = 0, boundary = 0, cases = 0;
    for (const char* shape : kShapes)
        for (int level = 1; level <= 4; ++level)
            for (EndCap ends : {kGregoryEnds, kBsplineEnds}) {
                const Layout& layout = layouts[(level + (ends == kBsplineEnds)) % 2];
                const bool far = level % 2 == 0;
                const D3 offset = far ? D3{3000, -2000, 1500} : D3{};
                const auto c = make_case(shape, level, ends, layout, offset, level == 3);
                // Float points: a few ulps of the largest coordinate, plus 1e-5 of the size.
                const double tol = 1e-5 * c->radius + (far ? 8 * 2.5e-4 : 8 * 1.2e-7 * c->radius);
                expect_same_surface(*c, tol, gregory, boundary);
                ++cases;
            }
    const auto big = make_case("bigguy", 2, kGregoryEnds, layouts[0], {});
    expect_same_surface(*big, 1e-5 * big->radius, gregory, boundary);
    EXPECT_GT(gregory, 1000u);
    EXPECT_GT(boundary, 1000u);
    EXPECT_EQ(cases, 64u);
}

// ---- (b) nothing visible is culled ----------------------------------------------------------------

constexpr int kGrid = 8;  // samples per patch side, (s, t) = (i, j) / (kGrid - 1)
constexpr int W = 64, H = 48;

struct Truth {
    std::vector<Sample> samples;  // kGrid^2 per table patch
};

Truth far_truth(const Case& c) {
    Truth t;
    t.samples.resize(c.source.patch_count() * kGrid * kGrid);
    for (const OsdPatchArraySource& a : c.source.arrays())
        for (std::size_t p = 0; p < a.source.count; ++p)
            for (int j = 0; j < kGrid; ++j)
                for (int i = 0; i < kGrid; ++i)
                    t.samples[((a.first_patch + p) * kGrid + static_cast<std::size_t>(j)) * kGrid +
                              static_cast<std::size_t>(i)] =
                        far_sample(c, a.array, static_cast<int>(p), a.first_patch + p, i / (kGrid - 1.0),
                                   j / (kGrid - 1.0));
    return t;
}

struct Counts {
    std::size_t frustum = 0, occluded = 0, gregory_frustum = 0, gregory_occluded = 0, box = 0, gregory_box = 0;
    std::size_t fused_back = 0;    // patches whose fused decision is the back-patch stage
    std::size_t gregory_back = 0;  // Gregory patches culled by a back-patch cone (tcone, ncone)
    std::vector<std::size_t> backpatch = std::vector<std::size_t>(backpatch_method_ids().size(), 0);
    int failures = 0;
};

// A random view of the case in convention depth, a depth layer of random rectangles across the
// model's depth range; then every cull entry, and every culled patch's samples checked.
void check_view(const Case& c, const Truth& truth, std::mt19937& rng, ClipDepth depth, D3 placement, Counts& counts) {
    std::uniform_real_distribution<double> u(-1, 1), unit(0, 1);
    D3 dir{u(rng), u(rng), u(rng)};
    dir = dir * (1 / std::max(1e-6, norm(dir)));
    const double dist = c.radius * (0.4 + 2.6 * unit(rng));
    // The camera in world coordinates (double), the object at placement; ENGINE.md's camera-
    // relative frame: an origin F on the 16-unit grid nearest the eye, the view from eye - F and
    // the object's translation placement - F, each rounded once to float.
    const D3 eye = placement + c.centre + dir * dist;
    const D3 target = placement + c.centre + D3{u(rng), u(rng), u(rng)} * (0.6 * c.radius);
    const D3 frame{16 * std::round(eye.x / 16), 16 * std::round(eye.y / 16), 16 * std::round(eye.z / 16)};
    const auto f3 = [](D3 a) {
        return Vec3{static_cast<float>(a.x), static_cast<float>(a.y), static_cast<float>(a.z)};
    };
    Mat4 model;
    const Vec3 t = f3(placement - frame);
    model.at(0, 3) = t.x;
    model.at(1, 3) = t.y;
    model.at(2, 3) = t.z;
    const Vec3 eye_f = f3(eye - placement);  // in the buffer's (object) space
    const float fovy = static_cast<float>(0.5 + 0.8 * unit(rng));
    const float z_near = static_cast<float>(0.02 * c.radius), z_far = static_cast<float>(dist + 0.8 * c.radius);
    const Mat4 projection = perspective(fovy, float(W) / float(H), z_near, z_far, depth);
    const CullView view =
        make_cull_view(look_at(f3(eye - frame), f3(target - frame), {0, 1, 0}) * model, projection, depth, eye_f);

    // The depth layer: window depths of view distances within the model's depth range.
    const bool reversed = is_reversed(depth);
    std::vector<float> buffer(static_cast<std::size_t>(W) * H, reversed ? 0.0f : 1.0f);
    const auto window_depth = [&](double distance) {
        const Vec4 q = projection * Vec4{0, 0, static_cast<float>(-distance), 1};
        const float d = q.z / q.w;
        return depth == ClipDepth::minus_one_to_one ? 0.5f * d + 0.5f : d;
    };
    for (int r = 0; r < 6; ++r) {
        const int x0 = static_cast<int>(unit(rng) * W), y0 = static_cast<int>(unit(rng) * H);
        const int w = 1 + static_cast<int>(unit(rng) * W * 0.7), h = 1 + static_cast<int>(unit(rng) * H * 0.7);
        const float z = window_depth(std::max(2.0 * z_near, dist + c.radius * (1.2 * unit(rng) - 0.9)));
        for (int y = y0; y < std::min(H, y0 + h); ++y)
            for (int x = x0; x < std::min(W, x0 + w); ++x) {
                float& d = buffer[static_cast<std::size_t>(y) * W + static_cast<std::size_t>(x)];
                d = reversed ? std::max(d, z) : std::min(d, z);
            }
    }
    HiZPyramid hiz;
    hiz.build(buffer.data(), W, H, depth);

    const std::size_t n = c.source.patch_count();
    std::vector<std::uint8_t> frustum(n + 1, 0xAB), occlusion(n + 1, 0xAB), back(n + 1, 0xAB);
    cull_frustum(c.source, nullptr, view, frustum.data());
    cull_occlusion(c.source, view, hiz, occlusion.data());
    EXPECT_EQ(frustum[n], 0xAB);
    EXPECT_EQ(occlusion[n], 0xAB);

    // Clip coordinates of a sample under the view's own matrix, in double: the truth is exact.
    const Mat4& m = view.object_to_clip;
    const auto clip = [&](D3 p) {
        std::array<double, 4> q;
        for (int r = 0; r < 4; ++r)
            q[static_cast<std::size_t>(r)] =
                double(m.at(r, 0)) * p.x + double(m.at(r, 1)) * p.y + double(m.at(r, 2)) * p.z + double(m.at(r, 3));
        return q;
    };
    const auto inside = [&](const std::array<double, 4>& q) {
        const double x = q[0], y = q[1], z = q[2], w = q[3];
        if (!(w > 0) || x < -w || x > w || y < -w || y > w || z > w) return false;
        if (depth == ClipDepth::minus_one_to_one) return z >= -w;
        return depth == ClipDepth::reversed_infinite || z >= 0;
    };
    // Not behind the layer at the pixel the sample lands in.
    const auto in_front = [&](const std::array<double, 4>& q) {
        const double ndc_z = q[2] / q[3];
        const double d = depth == ClipDepth::minus_one_to_one ? 0.5 * ndc_z + 0.5 : ndc_z;
        const int x = std::clamp(static_cast<int>(std::floor((0.5 * q[0] / q[3] + 0.5) * W)), 0, W - 1);
        const int y = std::clamp(static_cast<int>(std::floor((0.5 * q[1] / q[3] + 0.5) * H)), 0, H - 1);
        const double b = buffer[static_cast<std::size_t>(y) * W + static_cast<std::size_t>(x)];
        return reversed ? d >= b : d <= b;
    };
    const auto is_gregory = [&](std::size_t patch) {
        for (const OsdPatchArraySource& a : c.source.arrays())
            if (patch >= a.first_patch && patch < a.first_patch + a.source.count)
                return a.source.basis == PatchBasis::gregory;
        return false;
    };
    const auto fail = [&](std::size_t patch, const char* what, const Sample& s) {
        if (++counts.failures <= 8)
            ADD_FAILURE() << c.name << (placement.x != 0 ? ", placed far out" : "") << ", " << clip_depth_name(depth)
                          << ": patch " << patch << (is_gregory(patch) ? " (gregory)" : "") << " culled by " << what
                          << " with a visible sample at (" << s.p.x << ", " << s.p.y << ", " << s.p.z << ")";
    };
    const Sample* samples = truth.samples.data();
    for (std::size_t p = 0; p < n; ++p) {
        const Sample* ps = samples + p * kGrid * kGrid;
        if (frustum[p]) {
            ++counts.frustum;
            counts.gregory_frustum += is_gregory(p);
            for (int k = 0; k < kGrid * kGrid; ++k)
                if (inside(clip(ps[k].p))) {
                    fail(p, "the frustum", ps[k]);
                    break;
                }
        }
        EXPECT_EQ(occlusion[p] == kHiZFrustumCulled, frustum[p] != 0) << c.name << " patch " << p;
        if (occlusion[p] == kHiZOccluded) {
            ++counts.occluded;
            counts.gregory_occluded += is_gregory(p);
            for (int k = 0; k < kGrid * kGrid; ++k) {
                const std::array<double, 4> q = clip(ps[k].p);
                if (inside(q) && in_front(q)) {
                    fail(p, "occlusion", ps[k]);
                    break;
                }
            }
        }
    }
    // Sathe's box: every culled patch's samples outside, as the frustum's.
    std::vector<std::uint8_t> box(n + 1, 0xAB);
    cull_frustum_disp(c.source, nullptr, view, box.data());
    EXPECT_EQ(box[n], 0xAB);
    for (std::size_t p = 0; p < n; ++p) {
        if (!box[p]) continue;
        ++counts.box;
        counts.gregory_box += is_gregory(p);
        const Sample* ps = samples + p * kGrid * kGrid;
        for (int k = 0; k < kGrid * kGrid; ++k)
            if (inside(clip(ps[k].p))) {
                fail(p, "the frustum-disp box", ps[k]);
                break;
            }
    }
    // The fused kernel (frustum, ncone, Hi-Z): each patch's decision is the first of the separate
    // entries that culls it, so the checks of those entries here hold for it too.
    std::vector<std::uint8_t> ncone(n + 1, 0xAB), fused(n + 1, 0xAB);
    cull_backpatch(BackpatchMethod::ncone, c.source, view, BackpatchOptions{}, ncone.data());
    cull_fused(c.source, make_fused_setup(view, BackPatchCone::ncone, &hiz), FusedPlan{}, fused.data());
    EXPECT_EQ(fused[n], 0xAB);
    for (std::size_t p = 0; p < n; ++p) {
        const std::uint8_t want = frustum[p]                     ? kFusedFrustumCulled
                                  : ncone[p]                     ? kFusedBackPatchCulled
                                  : occlusion[p] == kHiZOccluded ? kFusedOccluded
                                                                 : kFusedVisible;
        if (fused[p] != want && ++counts.failures <= 8)
            ADD_FAILURE() << c.name << ", " << clip_depth_name(depth) << ": patch " << p << " fused decision "
                          << int(fused[p]) << ", the separate entries say " << int(want);
        counts.fused_back += fused[p] == kFusedBackPatchCulled;
    }
    for (BackpatchMethod id : backpatch_method_ids()) {
        cull_backpatch(id, c.source, view, BackpatchOptions{}, back.data());
        EXPECT_EQ(back[n], 0xAB);
        const D3 e{eye_f.x, eye_f.y, eye_f.z};  // object space, as the samples
        for (std::size_t p = 0; p < n; ++p) {
            if (!back[p]) continue;
            ++counts.backpatch[static_cast<std::size_t>(id)];
            // Gregory patches: only the cone methods cull them (the Gregory tangent cone).
            if (is_gregory(p)) {
                EXPECT_TRUE(backpatch_method_info(id).fusable)
                    << backpatch_method_name(id) << " culled a Gregory patch";
                ++counts.gregory_back;
            }
            const Sample* ps = samples + p * kGrid * kGrid;
            for (int k = 0; k < kGrid * kGrid; ++k) {
                const D3 to_eye = e - ps[k].p;
                // Facing: the normal's cosine with the direction to the eye above rounding.
                if (dot(ps[k].n, to_eye) > 1e-6 * norm(ps[k].n) * norm(to_eye)) {
                    fail(p, backpatch_method_name(id), ps[k]);
                    break;
                }
            }
        }
    }
}

// Every shape and level with both end caps and both layouts, placed at the origin and 3000-5000
// units out. Far out the buffer stays in object space and the view is composed camera-relative
// (docs/ENGINE.md, "Worlds of game size"): with the float buffer itself at 3000 units the core
// kernels' float rounding (not the table's views) culls visible samples (frustum up to 3e-4 units
// inside a plane, Hi-Z up to 0.025 units in front of the layer, ncone at cosines up to 0.5 on level-4
// patches 0.06 units across), as that section says of float world coordinates.
void check_cases(const std::vector<const char*>& shapes, const std::vector<int>& levels, int views_per_depth,
                 Counts& counts, std::uint32_t seed) {
    std::mt19937 rng(seed);
    const Layout layouts[] = {{3, 20, 4}, {4, 24, 8}};
    for (const char* shape : shapes)
        for (int level : levels)
            for (EndCap ends : {kGregoryEnds, kBsplineEnds}) {
                const auto c = make_case(shape, level, ends, layouts[level % 2], {}, level == 2);
                const Truth truth = far_truth(*c);
                for (const D3 placement : {D3{}, D3{3000, 2500, -3000}})
                    for (ClipDepth depth : {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one, ClipDepth::reversed,
                                            ClipDepth::reversed_infinite})
                        for (int v = 0; v < views_per_depth; ++v) check_view(*c, truth, rng, depth, placement, counts);
            }
}

void expect_teeth(const Counts& counts) {
    EXPECT_EQ(counts.failures, 0);
    EXPECT_GT(counts.frustum, 0u);
    EXPECT_GT(counts.occluded, 0u);
    EXPECT_GT(counts.gregory_frustum, 0u);
    EXPECT_GT(counts.gregory_occluded, 0u);
    EXPECT_GT(counts.box, 0u);
    EXPECT_GT(counts.gregory_box, 0u);
    EXPECT_GT(counts.gregory_back, 0u);
    EXPECT_GT(counts.fused_back, 0u);
    for (BackpatchMethod id : backpatch_method_ids())
        EXPECT_GT(counts.backpatch[static_cast<std::size_t>(id)], 0u) << backpatch_method_name(id);
}

TEST(OsdPatchTable, NothingVisibleIsCulledOnRegressionShapes) {
    Counts counts;
    check_cases({std::begin(kShapes), std::end(kShapes)}, {1, 2, 3, 4}, 2, counts, 11);
    expect_teeth(counts);
}

TEST(OsdPatchTable, NothingVisibleIsCulledOnBigguy) {
    Counts counts;
    check_cases({"bigguy"}, {1}, 2, counts, 12);
    expect_teeth(counts);
}

// ---- bookkeeping and refusals ---------------------------------------------------------------------

// Every decision lands at the patch index Far's own PatchMap gives for a point of the patch.
TEST(OsdPatchTable, DecisionsAreInFarsPatchOrder) {
    const auto c = make_case("catmark_smoothtris1", 2, kGregoryEnds, {3, 12, 0}, {});
    ASSERT_GE(c->source.arrays().size(), 2u);  // regular and Gregory arrays
    const Far::PatchMap map(*c->table);
    std::mt19937 rng(3);
    std::size_t checked = 0, culled = 0;
    for (ClipDepth depth : {ClipDepth::zero_to_one, ClipDepth::reversed}) {
        for (int v = 0; v < 6; ++v) {
            std::uniform_real_distribution<double> u(-1, 1);
            const D3 eye = c->centre + D3{u(rng), u(rng), u(rng)} * (1.5 * c->radius);
            const CullView view =
                make_cull_view(look_at({float(eye.x), float(eye.y), float(eye.z)},
                                       {float(c->centre.x), float(c->centre.y), float(c->centre.z)}, {0, 1, 0}),
                               perspective(0.6f, 1.0f, 0.01f, 100.0f, depth), depth);
            std::vector<std::uint8_t> all(c->source.patch_count());
            cull_frustum(c->source, nullptr, view, all.data());
            for (std::size_t patch = 0; patch < all.size(); ++patch) {
                // The patch's centre in its ptex face, and the handle Far finds there.
                const Far::PatchParam param = c->table->GetPatchParamTable()[patch];
                double pu = 0.5, pv = 0.5;
                param.Unnormalize(pu, pv);
                const Far::PatchTable::PatchHandle* h = map.FindPatch(param.GetFaceId(), pu, pv);
                ASSERT_NE(h, nullptr);
                ASSERT_EQ(static_cast<std::size_t>(h->patchIndex), patch);
                // The one patch alone, from Far's handle.
                const Far::ConstIndexArray cvs = c->table->GetPatchVertices(*h);
                std::vector<std::uint32_t> idx(cvs.begin(), cvs.end());
                const bool gregory = c->table->GetPatchDescriptor(*h).GetType() == Far::PatchDescriptor::GREGORY_BASIS;
                const std::uint8_t mask = static_cast<std::uint8_t>(param.GetBoundary());
                PatchSourceView one = c->source.arrays()[0].source;
                one.indices = idx.data();
                one.count = 1;
                one.basis = gregory ? PatchBasis::gregory : PatchBasis::bspline;
                one.boundary_mask = gregory ? nullptr : &mask;
                std::uint8_t alone = 0xAB;
                cull_frustum(one, nullptr, view, &alone);
                EXPECT_EQ(all[patch], alone) << "patch " << patch;
                ++checked;
                culled += alone;
            }
        }
    }
    EXPECT_GT(culled, 0u);
    EXPECT_LT(culled, checked);
}

std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(OsdPatchTable, RefusesOtherPatchTypesAndShortBuffers) {
    const ControlMesh mesh = load_obj(std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/opensubdiv/catmark_helmet.obj");
    for (EndCap ends : {Far::PatchTableFactory::Options::ENDCAP_BILINEAR_BASIS,
                        Far::PatchTableFactory::Options::ENDCAP_LEGACY_GREGORY}) {
        osd_detail::RefinerPtr refiner = osd_detail::create_refiner(mesh);
        Far::PatchTableFactory::Options options(2);
        options.SetEndCapType(ends);
        refiner->RefineAdaptive(options.GetRefineAdaptiveOptions());
        const std::unique_ptr<const Far::PatchTable> table(Far::PatchTableFactory::Create(*refiner, options));
        const std::string e = error_of([&] { OsdPatchTableSource source(*table); });
        EXPECT_NE(e.find("OsdPatchTableSource: patch array"), std::string::npos) << e;
        EXPECT_NE(e.find("only REGULAR"), std::string::npos) << e;
    }
    {  // uniform refinement: QUADS
        osd_detail::RefinerPtr refiner = osd_detail::create_refiner(mesh);
        refiner->RefineUniform(Far::TopologyRefiner::UniformOptions(1));
        const std::unique_ptr<const Far::PatchTable> table(Far::PatchTableFactory::Create(*refiner));
        const std::string e = error_of([&] { OsdPatchTableSource source(*table); });
        EXPECT_NE(e.find("type QUADS"), std::string::npos) << e;
    }
    // A buffer one point short: refused before any byte is written.
    const auto c = make_case("catmark_edgeonly", 2, kGregoryEnds, {3, 12, 0}, {});
    EXPECT_EQ(c->source.points_needed(), c->points.size());
    PointLayout shorter = c->source.arrays()[0].source.points;
    shorter.point_count = c->source.points_needed() - 1;
    OsdPatchTableSource moved = std::move(c->source);
    moved.bind_points(shorter);
    const CullView view =
        make_cull_view(look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}),
                       perspective(0.8f, 1.0f, 0.1f, 100.0f, ClipDepth::zero_to_one), ClipDepth::zero_to_one);
    std::vector<std::uint8_t> out(moved.patch_count(), 0xAB);
    EXPECT_NE(error_of([&] { cull_frustum(moved, nullptr, view, out.data()); }).find("past points.point_count"),
              std::string::npos);
    EXPECT_NE(
        error_of([&] { cull_backpatch(BackpatchMethod::tcone, moved, view, {}, out.data()); }).find("cull_backpatch"),
        std::string::npos);
    EXPECT_NE(error_of([&] { cull_frustum_disp(moved, nullptr, view, out.data()); }).find("cull_frustum_disp: "),
              std::string::npos);
    // The fused entry: the view, then the plan (occlusion without a pyramid) before any array.
    const FusedCullSetup setup = make_fused_setup(view, BackPatchCone::tcone, nullptr);
    FusedPlan frustum_only;
    frustum_only.count = 1;
    EXPECT_NE(error_of([&] { cull_fused(moved, setup, frustum_only, out.data()); }).find("cull_fused: "),
              std::string::npos);
    PointLayout full = shorter;
    full.point_count = c->points.size();
    moved.bind_points(full);
    EXPECT_EQ(error_of([&] { cull_fused(moved, setup, FusedPlan{}, out.data()); }),
              "cull_fused: the plan has occlusion but setup.hiz is null");
    EXPECT_TRUE(std::all_of(out.begin(), out.end(), [](std::uint8_t b) { return b == 0xAB; }));
    EXPECT_EQ(error_of([&] { cull_fused(moved, setup, frustum_only, out.data()); }), "(no error)");
}

}  // namespace
