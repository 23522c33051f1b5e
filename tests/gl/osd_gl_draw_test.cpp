// OpenSubdiv's own patch table drawn with OpenSubdiv's own GLSL patch shaders and culled in place
// by patchcull's passes (patchcull/gl_osd/osd_gl_draw.h), checked by the id buffer:
// - OpenSubdiv regression shapes with semi-sharp and infinitely sharp creases, corners, holes and
//   boundaries, feature-adaptive tables at levels 1-4 (B-spline patches, Gregory-basis end caps,
//   which must draw pixels too);
// - every mode: frustum, back-patch tcone / ncone / ptp (closed shapes, drawn one-sided), Hi-Z
//   occlusion in Niessner & Loop's two-pass frame, and all of them at once, over a few frames of
//   an orbit (the flags carry the statuses from frame to frame);
// - each culled frame's id buffer equals the unculled draw's of the same view pixel for pixel (no
//   false cull, nothing drawn that should not be), and every mode culls something;
// - the ids name the right patches: every pixel of the unculled draw lies in the window-space box
//   of its patch's control points (Far's patch index = PrimitiveIdBase + gl_PrimitiveID, which
//   llvmpipe restarts within a draw: a wrong index shows here);
// - the compacted draw (OsdDrawMode::indirect: CompactPass's list per array, OpenSubdiv's vertex
//   shader pulling each control point through it, at an odd stride and offset) gives every frame
//   the flag path's id buffer pixel for pixel and its counters, issues only the patches drawn, and
//   a list missing one surviving patch shows in the comparison;
// - bad input is a one-line Error.
#include <gtest/gtest.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include "gl_test_util.h"
#include "import/osd_topology.h"
#include "patchcull/core/error.h"
#include "patchcull/core/mesh.h"
#include "patchcull/core/patch_source.h"
#include "patchcull/gl_osd/osd_gl_draw.h"
#include "patchcull/import/obj.h"
#include "patchcull/import/osd_patch_table.h"

using namespace patchcull;
using namespace patchcull::gl_osd;
namespace Far = OpenSubdiv::Far;

namespace {

constexpr int W = 96, H = 72;

struct Shape {
    std::string name;
    ControlMesh mesh;
    bool closed = false;
};

Shape load_shape(const std::string& name) {
    Shape s;
    s.name = name;
    s.mesh = load_obj(std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/opensubdiv/" + name + ".obj");
    s.closed = orient_outward(s.mesh) == SurfaceOrientation::outward && s.mesh.holes.empty();
    return s;
}

// One table on the GPU: its points in a vertex buffer at an odd stride and offset.
struct GpuTable {
    OsdAdaptiveTable table;
    OsdPatchTableSource cpu;  // the same points on the CPU, for the window-space boxes
    std::vector<float> bytes;
    GLuint buffer = 0;
    OsdVertexBuffer vertices;
    Vec3 centre{0, 0, 0};
    float radius = 1;

    GpuTable(const ControlMesh& mesh, int level) : table(make_osd_adaptive_table(mesh, level)) {
        constexpr std::size_t stride = 5;  // floats: (pad, x, y, z, pad)
        bytes.assign(table.points.size() * stride, 0.0f);
        Vec3 lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
        for (std::size_t i = 0; i < table.points.size(); ++i) {
            const Vec3 p = table.points[i];
            bytes[i * stride + 1] = p.x;
            bytes[i * stride + 2] = p.y;
            bytes[i * stride + 3] = p.z;
            lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
            hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
        }
        centre = 0.5f * (lo + hi);
        radius = 0.5f * length(hi - lo);
        glCreateBuffers(1, &buffer);
        glNamedBufferStorage(buffer, static_cast<GLsizeiptr>(bytes.size() * sizeof(float)), bytes.data(), 0);
        vertices = {buffer, stride * sizeof(float), sizeof(float), table.points.size()};
        cpu = OsdPatchTableSource(*table.table,
                                  {bytes.data(), stride * sizeof(float), sizeof(float), 3, table.points.size()});
    }
    ~GpuTable() { glDeleteBuffers(1, &buffer); }
    GpuTable(const GpuTable&) = delete;
    GpuTable& operator=(const GpuTable&) = delete;
};

// The control points of the table's patch p (Bezier form for B-spline patches, Gregory's 20).
std::vector<Vec4> patch_points(const OsdPatchTableSource& t, std::size_t p) {
    for (const OsdPatchArraySource& a : t.arrays()) {
        if (p < a.first_patch || p >= a.first_patch + a.source.count) continue;
        const std::size_t i = p - a.first_patch;
        std::vector<Vec4> out;
        if (a.source.basis != PatchBasis::gregory) {
            const BezierPatch b = source_bezier_patch(a.source, i);
            out.assign(std::begin(b.cp), std::end(b.cp));
            return out;
        }
        for (std::size_t k = 0; k < 20; ++k) {
            float q[3];
            std::memcpy(q,
                        static_cast<const char*>(a.source.points.data) + a.source.points.offset_bytes +
                            a.source.indices[20 * i + k] * a.source.points.stride_bytes,
                        sizeof q);
            out.push_back({q[0], q[1], q[2], 1});
        }
        return out;
    }
    return {};
}

// An orbit of views around the table: the target off centre and close enough that parts of
// the surface leave the frustum, the far half hidden behind the near one.
OsdView orbit_view(const GpuTable& t, int view, int frame, bool one_sided) {
    const float angle = 0.9f * static_cast<float>(view) + 0.05f * static_cast<float>(frame);
    const float elevation = 0.35f * static_cast<float>((view % 3) - 1);
    const Vec3 dir = normalize(
        Vec3{std::cos(angle) * std::cos(elevation), std::sin(elevation), std::sin(angle) * std::cos(elevation)});
    const Vec3 eye = t.centre + (1.7f * t.radius) * dir;
    const Vec3 side = normalize(cross(dir, Vec3{0, 1, 0}));
    const Vec3 target = t.centre + (0.45f * t.radius) * side;
    OsdView v;
    v.model_view = look_at(eye, target, {0, 1, 0});
    v.depth = view % 4 == 3 ? ClipDepth::reversed : ClipDepth::zero_to_one;
    v.projection = perspective(0.9f, float(W) / float(H), 0.05f * t.radius, 4.0f * t.radius, v.depth);
    v.eye = eye;
    v.tess_level = 4;
    v.one_sided = one_sided;
    return v;
}

struct Mode {
    const char* name;
    OsdCullSettings settings;
    bool closed_only;
};

std::vector<Mode> modes() {
    std::vector<Mode> m;
    OsdCullSettings s;
    s.frustum = true;
    m.push_back({"frustum", s, false});
    for (BackpatchMethod b : {BackpatchMethod::tcone, BackpatchMethod::ncone, BackpatchMethod::ptp}) {
        OsdCullSettings c;
        c.backpatch = b;
        m.push_back({b == BackpatchMethod::tcone ? "tcone" : b == BackpatchMethod::ncone ? "ncone" : "ptp", c, true});
    }
    OsdCullSettings o;
    o.occlusion = true;
    m.push_back({"occlusion", o, false});
    OsdCullSettings all;
    all.frustum = true;
    all.occlusion = true;
    m.push_back({"all", all, false});  // + tcone on closed shapes
    return m;
}

struct Totals {
    std::map<std::string, std::size_t> culled;
    std::size_t frames = 0, pixels = 0;
    std::size_t gregory_pixels = 0;  // of pixels: Gregory-basis end caps
    std::set<std::string> closed_shapes;
};

// Every pixel of ids lies in the window box of its patch's control points (1 pixel of slack).
void expect_ids_name_their_patches(const GpuTable& t, const OsdView& view, const std::vector<std::uint32_t>& ids,
                                   const std::string& what) {
    const Mat4 clip = view.projection * view.model_view;
    int bad = 0;
    std::map<std::uint32_t, std::array<float, 4>> boxes;  // x0, y0, x1, y1; x0 > x1: unbounded
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const std::uint32_t id = ids[static_cast<std::size_t>(y) * W + static_cast<std::size_t>(x)];
            if (id == 0) continue;
            auto it = boxes.find(id);
            if (it == boxes.end()) {
                std::array<float, 4> box{1e30f, 1e30f, -1e30f, -1e30f};
                for (const Vec4& q : patch_points(t.cpu, id - 1)) {
                    const Vec4 c = clip * q;
                    if (!(c.w > 0)) {
                        box = {1, 1, 0, 0};
                        break;
                    }
                    const float wx = (c.x / c.w * 0.5f + 0.5f) * W, wy = (c.y / c.w * 0.5f + 0.5f) * H;
                    box = {std::min(box[0], wx), std::min(box[1], wy), std::max(box[2], wx), std::max(box[3], wy)};
                }
                it = boxes.emplace(id, box).first;
            }
            const auto& b = it->second;
            if (b[0] > b[2]) continue;
            const float px = static_cast<float>(x) + 0.5f, py = static_cast<float>(y) + 0.5f;
            if ((px < b[0] - 1 || px > b[2] + 1 || py < b[1] - 1 || py > b[3] + 1) && ++bad <= 5)
                ADD_FAILURE() << what << ": pixel (" << x << ", " << y << ") has patch " << id - 1
                              << ", whose control points cover [" << b[0] << ", " << b[2] << "] x [" << b[1] << ", "
                              << b[3] << "]";
        }
    EXPECT_GT(boxes.size(), 3u) << what << ": too few patches in view";
}

void run_table(const Shape& shape, int level, Totals& totals) {
    if (shape.closed) totals.closed_shapes.insert(shape.name);
    GpuTable t(shape.mesh, level);
    gl::PassContext& passes = gl::test::passes();
    OsdPatchTableDraw draw(passes, *t.table.table);
    ASSERT_EQ(draw.patch_count(), t.cpu.patch_count());
    OsdCullFrame frame(passes, draw, W, H);
    for (const Mode& m : modes()) {
        if (m.closed_only && !shape.closed) continue;
        OsdCullSettings settings = m.settings;
        if (std::string(m.name) == "all" && shape.closed) settings.backpatch = BackpatchMethod::tcone;
        frame.reset();
        for (int view = 0; view < 2; ++view)
            for (int f = 0; f < 2; ++f) {
                const OsdView v = orbit_view(t, view, f, shape.closed);
                const std::string what = shape.name + " level " + std::to_string(level) + ", " + m.name + ", view " +
                                         std::to_string(view) + " frame " + std::to_string(f);
                frame.render_unculled(t.vertices, v);
                const std::vector<std::uint32_t> want = frame.read_ids();
                if (m.settings.frustum && !m.settings.occlusion) expect_ids_name_their_patches(t, v, want, what);
                const OsdFrameStats stats = frame.render(t.vertices, v, settings);
                const std::vector<std::uint32_t> got = frame.read_ids();
                int diff = 0;
                for (std::size_t i = 0; i < got.size(); ++i)
                    if (got[i] != want[i] && ++diff <= 3)
                        ADD_FAILURE() << what << ": pixel (" << i % W << ", " << i / W << ") culled id " << got[i]
                                      << ", unculled " << want[i];
                EXPECT_EQ(diff, 0) << what;
                totals.culled[m.name] += stats.frustum + stats.backpatch + stats.occlusion;
                ++totals.frames;
                for (std::uint32_t id : want) {
                    if (id == 0) continue;
                    ++totals.pixels;
                    for (const OsdPatchArraySource& a : t.cpu.arrays())
                        if (a.source.basis == PatchBasis::gregory && id - 1 >= a.first_patch &&
                            id - 1 < a.first_patch + a.source.count)
                            ++totals.gregory_pixels;
                }
            }
    }
}

}  // namespace

TEST(OsdGlDraw, CulledFramesEqualTheUnculledDrawOnRegressionShapes) {
    gl::test::context().make_current();
    Totals totals;
    const struct {
        const char* shape;
        int level;
    } cases[] = {{"catmark_chaikin1", 1},   {"catmark_cubes_infsharp", 2}, {"catmark_edgeonly", 3},
                 {"catmark_hole_test1", 4}, {"catmark_chaikin1", 3},       {"catmark_cubes_infsharp", 4}};
    for (const auto& c : cases) {
        const Shape shape = load_shape(c.shape);
        run_table(shape, c.level, totals);
    }
    for (const Mode& m : modes()) EXPECT_GT(totals.culled[m.name], 0u) << m.name << " culled nothing";
    EXPECT_GT(totals.pixels, totals.frames * 200);
    EXPECT_GT(totals.gregory_pixels, totals.frames * 5) << "the Gregory-basis programs drew too little";
    EXPECT_EQ(totals.closed_shapes, (std::set<std::string>{"catmark_chaikin1", "catmark_cubes_infsharp"}));
    for (const auto& [name, n] : totals.culled) std::printf("%s culled %zu\n", name.c_str(), n);
    std::printf("%zu frames, %zu pixels drawn unculled, %zu of them by Gregory-basis end caps\n", totals.frames,
                totals.pixels, totals.gregory_pixels);
}

// OsdDrawOptions: OpenSubdiv's own OSD_ENABLE_PATCH_CULL draws the same pixels as the unculled
// draw with fewer patches tessellated, and the record counts what the frame's counters say.
TEST(OsdGlDraw, OpenSubdivPatchCullAndTheTessellatedRecord) {
    gl::test::context().make_current();
    gl::PassContext& passes = gl::test::passes();
    const Shape shape = load_shape("catmark_chaikin1");
    GpuTable t(shape.mesh, 2);
    OsdDrawOptions plain_options, native_options;
    plain_options.record_tessellated = true;
    native_options.record_tessellated = true;
    native_options.opensubdiv_patch_cull = true;
    const OsdPatchTableDraw plain(passes, *t.table.table, plain_options),
        native(passes, *t.table.table, native_options);
    OsdCullFrame plain_frame(passes, plain, W, H), native_frame(passes, native, W, H);
    std::size_t native_total = 0, plain_total = 0;
    for (int view = 0; view < 3; ++view) {
        const OsdView v = orbit_view(t, view, 0, shape.closed);
        const std::string what = "view " + std::to_string(view);
        plain.clear_tessellated();
        plain_frame.render_unculled(t.vertices, v);
        EXPECT_EQ(plain.tessellated_count(), plain.patch_count()) << what;
        const std::vector<std::uint32_t> want = plain_frame.read_ids();
        native.clear_tessellated();
        native_frame.render_unculled(t.vertices, v);
        const std::size_t kept = native.tessellated_count();
        EXPECT_LE(kept, native.patch_count()) << what;
        EXPECT_GT(kept, 0u) << what;
        native_total += kept;
        plain_total += native.patch_count();
        EXPECT_TRUE(native_frame.read_ids() == want) << what << ": OSD_ENABLE_PATCH_CULL changed pixels";
        OsdCullSettings frustum;
        frustum.frustum = true;
        plain.clear_tessellated();
        const OsdFrameStats stats = plain_frame.render(t.vertices, v, frustum);
        EXPECT_EQ(plain.tessellated_count(), stats.drawn_pass1) << what;
        EXPECT_TRUE(plain_frame.read_ids() == want) << what;
        // The compacted draw's programs: the record marks the listed patches (the TES's patch
        // index is the pulled one), OpenSubdiv's clip flags come from the pulled points.
        OsdCullSettings listed = frustum;
        listed.draw = OsdDrawMode::indirect;
        plain.clear_tessellated();
        const OsdFrameStats plain_listed = plain_frame.render(t.vertices, v, listed);
        EXPECT_EQ(plain_listed.submitted_pass1, plain_listed.drawn_pass1) << what;
        EXPECT_EQ(plain.tessellated_count(), plain_listed.drawn_pass1) << what << ": indirect";
        EXPECT_TRUE(plain_frame.read_ids() == want) << what << ": indirect";
        native.clear_tessellated();
        const OsdFrameStats native_listed = native_frame.render(t.vertices, v, listed);
        EXPECT_LE(native.tessellated_count(), native_listed.drawn_pass1) << what << ": indirect, native";
        EXPECT_GT(native.tessellated_count(), 0u) << what << ": indirect, native";
        EXPECT_TRUE(native_frame.read_ids() == want) << what << ": indirect, OSD_ENABLE_PATCH_CULL";
    }
    EXPECT_LT(native_total, plain_total) << "OpenSubdiv's patch cull culled nothing";
    std::printf("OSD_ENABLE_PATCH_CULL tessellated %zu of %zu patches over 3 views\n", native_total, plain_total);
    OsdPatchTableDraw unrecorded(passes, *t.table.table);
    EXPECT_THROW(unrecorded.clear_tessellated(), Error);
    EXPECT_THROW((void)unrecorded.tessellated_count(), Error);
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(OsdGlDraw, BadInputIsAOneLineError) {
    gl::test::context().make_current();
    gl::PassContext& passes = gl::test::passes();
    const auto expect_error = [](const std::function<void()>& f, const std::string& part) {
        try {
            f();
            ADD_FAILURE() << "no error (expected one naming " << part << ")";
        } catch (const Error& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find(part), std::string::npos) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        }
    };
    const Shape shape = load_shape("catmark_cubes_infsharp");
    // Bilinear end caps: QUADS arrays, which OpenSubdiv's patch shaders here do not draw.
    osd_detail::RefinerPtr refiner = osd_detail::create_refiner(shape.mesh);
    Far::PatchTableFactory::Options options(2);
    options.SetEndCapType(Far::PatchTableFactory::Options::ENDCAP_BILINEAR_BASIS);
    refiner->RefineAdaptive(options.GetRefineAdaptiveOptions());
    std::unique_ptr<const Far::PatchTable> bilinear(Far::PatchTableFactory::Create(*refiner, options));
    expect_error([&] { OsdPatchTableDraw draw(passes, *bilinear); }, "QUADS");
    expect_error([&] { (void)make_osd_adaptive_table(shape.mesh, 0); }, "isolation level 0");

    GpuTable t(shape.mesh, 1);
    OsdPatchTableDraw draw(passes, *t.table.table);
    OsdVertexBuffer v = t.vertices;
    v.stride_bytes = 10;
    expect_error([&] { (void)draw.sources(v, 1); }, "stride 10");
    v = t.vertices;
    v.point_count = draw.points_needed() - 1;
    expect_error([&] { (void)draw.sources(v, 1); }, "the table reads");
    v = t.vertices;
    v.offset_bytes = v.stride_bytes - 8;
    expect_error([&] { (void)draw.sources(v, 1); }, "leaves no room");
    OsdView view = orbit_view(t, 0, 0, true);
    view.tess_level = 0;
    OsdCullFrame frame(passes, draw, 8, 8);
    expect_error([&] { frame.render(t.vertices, view, {}); }, "tess_level");
    expect_error([&] { OsdCullFrame f(passes, draw, 0, 8); }, "size 0x8");
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

namespace {

// Pixels where a and b differ, and of those where the depths are not equal (a depth tie is two
// patches at exactly the same depth drawn in another order).
struct IdDiff {
    std::size_t pixels = 0, not_ties = 0;
};
IdDiff diff_ids(const std::vector<std::uint32_t>& a, const std::vector<float>& a_depth,
                const std::vector<std::uint32_t>& b, const std::vector<float>& b_depth) {
    IdDiff d;
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (a[i] == b[i]) continue;
        ++d.pixels;
        if (a[i] == 0 || b[i] == 0 || a_depth[i] != b_depth[i]) ++d.not_ties;
    }
    return d;
}

}  // namespace

// The compacted draw against the flag path, frame by frame over the same views (so the flags
// evolve alike): the scan lists ascending, as the flag path draws, so the ids are equal pixel for
// pixel; the append lists in any order, so only depth ties may differ. Every mode, closed and
// open shapes, B-spline and Gregory-basis arrays; on llvmpipe many commands per array.
TEST(OsdGlDraw, IndirectFramesEqualTheFlagPath) {
    gl::test::context().make_current();
    gl::PassContext& passes = gl::test::passes();
    const struct {
        const char* shape;
        int level;
    } cases[] = {{"catmark_chaikin1", 3}, {"catmark_hole_test1", 4}, {"catmark_cubes_infsharp", 2}};
    std::size_t frames = 0, culled = 0, listed = 0, all_patches = 0, gregory_listed = 0;
    for (const auto& c : cases) {
        const Shape shape = load_shape(c.shape);
        GpuTable t(shape.mesh, c.level);
        OsdPatchTableDraw draw(passes, *t.table.table);
        OsdCullFrame flags(passes, draw, W, H), scan(passes, draw, W, H), append(passes, draw, W, H);
        for (const Mode& m : modes()) {
            if (m.closed_only && !shape.closed) continue;
            OsdCullSettings settings = m.settings;
            if (std::string(m.name) == "all" && shape.closed) settings.backpatch = BackpatchMethod::tcone;
            OsdCullSettings scan_settings = settings, append_settings = settings;
            scan_settings.draw = append_settings.draw = OsdDrawMode::indirect;
            append_settings.compact = gl::CompactMethod::atomic_append;
            flags.reset();
            scan.reset();
            append.reset();
            for (int view = 0; view < 2; ++view)
                for (int f = 0; f < 2; ++f) {
                    const OsdView v = orbit_view(t, view, f, shape.closed);
                    const std::string what = std::string(c.shape) + " level " + std::to_string(c.level) + ", " +
                                             m.name + ", view " + std::to_string(view) + " frame " + std::to_string(f);
                    const OsdFrameStats a = flags.render(t.vertices, v, settings);
                    const OsdFrameStats b = scan.render(t.vertices, v, scan_settings);
                    const OsdFrameStats e = append.render(t.vertices, v, append_settings);
                    for (const OsdFrameStats* x : {&b, &e}) {
                        EXPECT_EQ(x->frustum, a.frustum) << what;
                        EXPECT_EQ(x->backpatch, a.backpatch) << what;
                        EXPECT_EQ(x->occlusion, a.occlusion) << what;
                        EXPECT_EQ(x->drawn_pass1, a.drawn_pass1) << what;
                        EXPECT_EQ(x->drawn_pass2, a.drawn_pass2) << what;
                        EXPECT_EQ(x->submitted_pass1, x->drawn_pass1) << what << ": pass 1 issued what it drew";
                        EXPECT_EQ(x->submitted_pass2, x->drawn_pass2) << what << ": pass 2 issued what it drew";
                    }
                    EXPECT_EQ(a.submitted_pass1, draw.patch_count()) << what;
                    EXPECT_EQ(a.submitted_pass2, settings.occlusion ? draw.patch_count() : 0u) << what;
                    const std::vector<std::uint32_t> want = flags.read_ids();
                    const std::vector<float> want_depth = flags.read_depth();
                    const IdDiff ds = diff_ids(want, want_depth, scan.read_ids(), scan.read_depth());
                    EXPECT_EQ(ds.pixels, 0u) << what << ": the scan's ids differ from the flag path's";
                    const IdDiff da = diff_ids(want, want_depth, append.read_ids(), append.read_depth());
                    EXPECT_EQ(da.not_ties, 0u) << what << ": the append's ids differ beyond depth ties";
                    ++frames;
                    culled += a.frustum + a.backpatch + a.occlusion;
                    listed += b.submitted_pass1 + b.submitted_pass2;
                    all_patches += draw.patch_count();
                    std::set<std::uint32_t> gregory_ids;
                    for (std::uint32_t id : want)
                        for (const OsdPatchArraySource& arr : t.cpu.arrays())
                            if (id != 0 && arr.source.basis == PatchBasis::gregory && id - 1 >= arr.first_patch &&
                                id - 1 < arr.first_patch + arr.source.count)
                                gregory_ids.insert(id);
                    gregory_listed += gregory_ids.size();
                }
        }
    }
    EXPECT_GT(culled, 0u);
    EXPECT_LT(listed, all_patches) << "the compacted draws issued every patch";
    EXPECT_GT(gregory_listed, frames) << "too few Gregory-basis patches drawn";
    std::printf("%zu frames: the compacted draws issued %zu patches where the flag path issued %zu per pass\n", frames,
                listed, all_patches);
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// OsdPatchTableDraw::compact and draw_indirect by hand: every patch listed draws the unculled
// picture; the same list with one visible patch's entry overwritten by its neighbour's (a
// surviving patch dropped) loses exactly that patch's pixels, which the id comparison above sees.
TEST(OsdGlDraw, ACompactedDrawThatDropsAPatchIsCaught) {
    gl::test::context().make_current();
    gl::PassContext& passes = gl::test::passes();
    const Shape shape = load_shape("catmark_hole_test1");
    GpuTable t(shape.mesh, 3);
    OsdPatchTableDraw draw(passes, *t.table.table);
    OsdCullFrame frame(passes, draw, W, H);
    const OsdView view = orbit_view(t, 1, 0, shape.closed);
    frame.render_unculled(t.vertices, view);
    const std::vector<std::uint32_t> want = frame.read_ids();

    // Targets of our own, the frame's conventions (zero-to-one unless the view says otherwise).
    GLuint ids = 0, depth = 0, fbo = 0, list = 0, commands = 0, counts = 0, flags = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &ids);
    glTextureStorage2D(ids, 1, GL_R32UI, W, H);
    glCreateTextures(GL_TEXTURE_2D, 1, &depth);
    glTextureStorage2D(depth, 1, GL_DEPTH_COMPONENT32F, W, H);
    glCreateFramebuffers(1, &fbo);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, ids, 0);
    glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, depth, 0);
    const std::size_t k = 7;  // several commands per array
    glCreateBuffers(1, &list);
    glNamedBufferStorage(list, static_cast<GLsizeiptr>(4 * draw.patch_count()), nullptr, GL_DYNAMIC_STORAGE_BIT);
    glCreateBuffers(1, &commands);
    glNamedBufferStorage(commands, static_cast<GLsizeiptr>(16 * draw.command_count(k)), nullptr, 0);
    glCreateBuffers(1, &counts);
    glNamedBufferStorage(counts, static_cast<GLsizeiptr>(4 * draw.array_count()), nullptr, 0);
    glCreateBuffers(1, &flags);
    const std::vector<std::uint32_t> zero(draw.patch_count(), 0u);
    glNamedBufferStorage(flags, static_cast<GLsizeiptr>(4 * zero.size()), zero.data(), 0);
    const OsdDrawList out{list, commands, counts, k};
    gl::CompactPass compact(passes);
    const auto draw_list = [&] {
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glViewport(0, 0, W, H);
        const bool reversed = is_reversed(view.depth);
        glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(reversed ? GL_GREATER : GL_LESS);
        const GLuint clear_id = 0;
        const float far_depth = reversed ? 0.0f : 1.0f;
        glClearNamedFramebufferuiv(fbo, GL_COLOR, 0, &clear_id);
        glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &far_depth);
        draw.draw_indirect(t.vertices, flags, out, view);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
        glDepthFunc(GL_LESS);
        glDisable(GL_DEPTH_TEST);
        std::vector<std::uint32_t> got(static_cast<std::size_t>(W) * H);
        glGetTextureImage(ids, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, static_cast<GLsizei>(4 * got.size()), got.data());
        return got;
    };
    draw.compact(compact, flags, 0u, 0u, out);
    EXPECT_EQ(draw.listed_count(out), draw.patch_count());
    EXPECT_TRUE(draw_list() == want) << "every patch listed: not the unculled picture";

    // Drop the patch at the most pixels: its entry (the scan lists ascending, entry p = patch p
    // when every patch is listed) becomes a neighbour's.
    std::map<std::uint32_t, std::size_t> pixels;
    for (std::uint32_t id : want)
        if (id) ++pixels[id];
    ASSERT_FALSE(pixels.empty());
    const auto top = std::max_element(pixels.begin(), pixels.end(),
                                      [](const auto& a, const auto& b) { return a.second < b.second; });
    const std::uint32_t dropped = top->first - 1;
    std::uint32_t neighbour = dropped;  // another patch of the same array
    for (const OsdPatchArraySource& a : t.cpu.arrays())
        if (dropped >= a.first_patch && dropped < a.first_patch + a.source.count)
            neighbour = dropped > a.first_patch ? dropped - 1 : dropped + 1;
    ASSERT_NE(neighbour, dropped);
    glNamedBufferSubData(list, static_cast<GLintptr>(4 * dropped), 4, &neighbour);
    const std::vector<std::uint32_t> got = draw_list();
    std::size_t lost = 0, present = 0;
    for (std::size_t i = 0; i < got.size(); ++i) {
        if (got[i] == dropped + 1) ++present;
        if (want[i] == dropped + 1 && got[i] != want[i]) ++lost;
    }
    EXPECT_EQ(present, 0u) << "the dropped patch " << dropped << " still drew";
    EXPECT_EQ(lost, top->second) << "the comparison misses the dropped patch's pixels";
    EXPECT_FALSE(got == want);
    for (GLuint b : {list, commands, counts, flags}) glDeleteBuffers(1, &b);
    glDeleteFramebuffers(1, &fbo);
    for (GLuint x : {ids, depth}) glDeleteTextures(1, &x);
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}
