// `patchcull eval osd-cull MODEL [--level N] [--tess L] [--size WxH] [--rounds R] [--warmup K]`:
// OpenSubdiv's own TCS frustum culling against patchcull's passes, on the same feature-adaptive
// patch table (make_osd_adaptive_table at --level) drawn by OpenSubdiv's GLSL patch shaders
// (gl_osd/osd_gl_draw.h), the same views and the same uniform tessellation level, in one run.
//
// Four modes:
//   (a) none     every patch drawn (OsdCullFrame::render_unculled);
//   (b) osd      programs compiled with OSD_ENABLE_PATCH_CULL (OsdDrawOptions): OpenSubdiv's
//                OSD_PATCH_CULL(N) gives levels 0 to a patch whose control points (B-spline or
//                Gregory-basis) all lie beyond one clip plane; no patchcull pass runs;
//   (c) frustum  patchcull's FrustumPass on the table in place, then one draw;
//   (d) all      frustum, back-patch tcone (closed models) and two-pass Hi-Z occlusion, as
//                OsdCullFrame runs them (its flag readback included).
// Views (clip depth -1..1, OpenSubdiv's convention, so its near plane is the projection's):
//   orbit  orbit_sequence's first camera: the whole model in view;
//   zoom   the same camera with a fifth of the field of view (12 degrees): much of the model
//          outside the frustum;
//   aside  the orbit camera moved sideways by 1.2 bounding radii: about half the model outside.
// Per view: --warmup untimed rounds, then --rounds rounds; a round draws one frame of each mode,
// the order rotated each round (a b c d, b c d a, ...), each frame timed as wall time between two
// glFinish calls (on llvmpipe the "GPU" is the CPU: its time is wall time). Reported: the median
// per mode and its ratio to (a)'s median. Mode (d) keeps its statuses from frame to frame, so with
// a still camera its timed frames are the steady state (pass 2 draws nothing new).
// Patches tessellated are counted apart from the timing, in one more frame per mode drawn by
// programs with OsdDrawOptions::record_tessellated (the TES marks its patch; a patch the TCS
// gives levels 0 never reaches the TES), beside the pipeline statistics query's
// GL_TESS_EVALUATION_SHADER_INVOCATIONS for that frame when the driver has
// ARB_pipeline_statistics_query. That frame's id buffer is compared with (a)'s: any differing
// pixel makes the exit status 1.
#include "eval_osd_cull.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "commands.h"
#include "patchcull/core/camera.h"
#include "patchcull/core/error.h"
#include "patchcull/gl/gl_context.h"
#include "patchcull/gl/gl_passes.h"
#include "patchcull/gl_osd/osd_gl_draw.h"
#include "patchcull/import/model_loader.h"
#include "patchcull/import/osd_patch_table.h"

namespace patchcull::cli {
namespace osd_cull_eval {  // named: the CLI compiles as a unity build

constexpr int kModes = 4;
const char* const kModeLabels[kModes] = {"(a) none", "(b) OpenSubdiv OSD_ENABLE_PATCH_CULL", "(c) patchcull frustum",
                                         "(d) patchcull frustum+tcone+Hi-Z"};

struct NamedView {
    const char* name;
    gl_osd::OsdView view;
};

gl_osd::OsdView to_view(Camera c, int tess, bool one_sided) {
    c.depth = ClipDepth::minus_one_to_one;
    gl_osd::OsdView v;
    v.model_view = c.view();
    v.projection = c.projection();
    v.depth = c.depth;
    v.eye = c.eye;
    v.tess_level = static_cast<float>(tess);
    v.one_sided = one_sided;
    return v;
}

std::vector<NamedView> make_views(const ControlMesh& mesh, float aspect, int tess, bool one_sided) {
    const Bounds b = compute_bounds(mesh.positions);
    const Camera orbit = orbit_sequence(b, 1, 0.0f, aspect)[0];
    Camera zoom = orbit;
    zoom.fovy_radians = orbit.fovy_radians / 5;
    Camera aside = orbit;
    const Vec3 side = 1.2f * b.radius() * normalize(cross(orbit.target - orbit.eye, orbit.up));
    aside.eye = orbit.eye + side;
    aside.target = orbit.target + side;
    return {{"orbit", to_view(orbit, tess, one_sided)},
            {"zoom", to_view(zoom, tess, one_sided)},
            {"aside", to_view(aside, tess, one_sided)}};
}

// /proc/loadavg's three averages.
std::string load_average() {
    std::ifstream in("/proc/loadavg");
    std::string a, b, c;
    in >> a >> b >> c;
    return in ? a + " " + b + " " + c : std::string("unknown");
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Modes {
    gl_osd::OsdCullSettings frustum, all;
    // One frame of mode m: (a) and (b) unculled (frame_b's draw has OSD_ENABLE_PATCH_CULL).
    void run(int m, gl_osd::OsdCullFrame& frame, const gl_osd::OsdVertexBuffer& vertices,
             const gl_osd::OsdView& view) const {
        if (m < 2) {
            frame.render_unculled(vertices, view);
        } else {
            (void)frame.render(vertices, view, m == 2 ? frustum : all);
        }
    }
};

}  // namespace osd_cull_eval

int run_osd_cull_eval(const OsdCullEvalOptions& o) {
    using namespace osd_cull_eval;
    int width = 0, height = 0;
    parse_size("--size", o.size, width, height);
    if (o.model == "teapot") throw Error("eval osd-cull: the teapot has no control mesh (use an OBJ model)");
    const LoadedModel model = load_model(o.model, Scheme::osd, 0);
    print_warnings(model.warnings);
    const ControlMesh& mesh = model.subdiv->mesh;
    const OsdAdaptiveTable table = make_osd_adaptive_table(mesh, o.level);
    Modes modes;
    modes.frustum.frustum = true;
    modes.all.frustum = true;
    modes.all.occlusion = true;
    if (model.closed) modes.all.backpatch = BackpatchMethod::tcone;
    const std::vector<NamedView> views =
        make_views(mesh, static_cast<float>(width) / static_cast<float>(height), o.tess, model.closed);

    gl::GlContext context = gl::GlContext::create_headless();
    const bool statistics = epoxy_gl_version() >= 46 || epoxy_has_gl_extension("GL_ARB_pipeline_statistics_query");
    const std::string load_before = load_average();
    struct Guard {  // the vertex buffer and the query, deleted before the context
        GLuint buffer = 0, query = 0;
        ~Guard() {
            if (buffer) glDeleteBuffers(1, &buffer);
            if (query) glDeleteQueries(1, &query);
        }
    } guard;
    int status = 0;
    {
        gl::PassContext passes;
        gl_osd::OsdDrawOptions native_options, plain_record, native_record;
        native_options.opensubdiv_patch_cull = true;
        plain_record.record_tessellated = true;
        native_record = plain_record;
        native_record.opensubdiv_patch_cull = true;
        const gl_osd::OsdPatchTableDraw plain(passes, *table.table), native(passes, *table.table, native_options);
        const gl_osd::OsdPatchTableDraw plain_rec(passes, *table.table, plain_record),
            native_rec(passes, *table.table, native_record);
        glCreateBuffers(1, &guard.buffer);
        glNamedBufferStorage(guard.buffer, static_cast<GLsizeiptr>(table.points.size() * sizeof(Vec3)),
                             table.points.data(), 0);
        // glGenQueries: Mesa 22.3's glCreateQueries refuses the pipeline statistics targets.
        if (statistics) glGenQueries(1, &guard.query);
        const gl_osd::OsdVertexBuffer vertices{guard.buffer, sizeof(Vec3), 0, table.points.size()};
        const std::size_t patches = plain.patch_count();
        std::printf(
            "eval osd-cull: %s, adaptive level %d, %zu patches, tess %d, %dx%d, %d rounds after %d, renderer %s, "
            "load average %s\n",
            model.name.c_str(), o.level, patches, o.tess, width, height, o.rounds, o.warmup, context.renderer().c_str(),
            load_before.c_str());
        for (const NamedView& nv : views) {
            std::array<gl_osd::OsdCullFrame, kModes> timed = {
                gl_osd::OsdCullFrame(passes, plain, width, height), gl_osd::OsdCullFrame(passes, native, width, height),
                gl_osd::OsdCullFrame(passes, plain, width, height), gl_osd::OsdCullFrame(passes, plain, width, height)};
            std::array<std::vector<double>, kModes> seconds;
            for (int r = 0; r < o.warmup + o.rounds; ++r)
                for (int k = 0; k < kModes; ++k) {
                    const int m = (r + k) % kModes;
                    glFinish();
                    const auto t0 = std::chrono::steady_clock::now();
                    modes.run(m, timed[static_cast<std::size_t>(m)], vertices, nv.view);
                    glFinish();
                    const auto t1 = std::chrono::steady_clock::now();
                    if (r >= o.warmup)
                        seconds[static_cast<std::size_t>(m)].push_back(std::chrono::duration<double>(t1 - t0).count());
                }
            // The counted frames: the recording programs, (d) after the same warm-up as its timed frames.
            std::array<gl_osd::OsdCullFrame, kModes> counted = {gl_osd::OsdCullFrame(passes, plain_rec, width, height),
                                                                gl_osd::OsdCullFrame(passes, native_rec, width, height),
                                                                gl_osd::OsdCullFrame(passes, plain_rec, width, height),
                                                                gl_osd::OsdCullFrame(passes, plain_rec, width, height)};
            for (int r = 0; r < o.warmup; ++r) modes.run(3, counted[3], vertices, nv.view);
            std::array<std::size_t, kModes> tessellated{};
            std::array<GLuint64, kModes> invocations{};
            std::vector<std::uint32_t> reference;
            std::printf("\nview %s\n  %-36s %12s %7s %14s %7s %10s %7s %9s\n", nv.name, "mode", "tessellated", "ratio",
                        "TES invocs", "ratio", "median ms", "ratio", "diff px");
            const double base_time = median(seconds[0]);
            for (int m = 0; m < kModes; ++m) {
                const gl_osd::OsdPatchTableDraw& rec = m == 1 ? native_rec : plain_rec;
                rec.clear_tessellated();
                if (statistics) glBeginQuery(GL_TESS_EVALUATION_SHADER_INVOCATIONS_ARB, guard.query);
                modes.run(m, counted[static_cast<std::size_t>(m)], vertices, nv.view);
                if (statistics) {
                    glEndQuery(GL_TESS_EVALUATION_SHADER_INVOCATIONS_ARB);
                    glGetQueryObjectui64v(guard.query, GL_QUERY_RESULT, &invocations[static_cast<std::size_t>(m)]);
                }
                tessellated[static_cast<std::size_t>(m)] = rec.tessellated_count();
                const std::vector<std::uint32_t> ids = counted[static_cast<std::size_t>(m)].read_ids();
                if (m == 0) reference = ids;
                std::size_t differing = 0;
                for (std::size_t i = 0; i < ids.size(); ++i) differing += ids[i] != reference[i];
                if (differing) status = 1;
                const double t = median(seconds[static_cast<std::size_t>(m)]);
                const auto ratio = [](double x, double base) { return base > 0 ? x / base : 0.0; };
                std::printf("  %-36s %12zu %7.3f", kModeLabels[m], tessellated[static_cast<std::size_t>(m)],
                            ratio(static_cast<double>(tessellated[static_cast<std::size_t>(m)]),
                                  static_cast<double>(tessellated[0])));
                if (statistics) {
                    std::printf(" %14llu %7.3f",
                                static_cast<unsigned long long>(invocations[static_cast<std::size_t>(m)]),
                                ratio(static_cast<double>(invocations[static_cast<std::size_t>(m)]),
                                      static_cast<double>(invocations[0])));
                } else {
                    std::printf(" %14s %7s", "n/a", "n/a");
                }
                std::printf(" %10.2f %7.3f %9zu\n", 1e3 * t, ratio(t, base_time), differing);
            }
        }
    }
    std::printf("\nload average after: %s\n", load_average().c_str());
    return status;
}

}  // namespace patchcull::cli
