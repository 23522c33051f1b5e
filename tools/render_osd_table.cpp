// render --patch-source osd-table (render_osd_table.h).
#include "render_osd_table.h"

#include <epoxy/gl.h>

#include <cstdio>
#include <iostream>
#include <set>
#include <vector>

#include <nlohmann/json.hpp>

#include "patchcull/core/camera.h"
#include "patchcull/core/error.h"
#include "patchcull/gl/gl_context.h"
#include "patchcull/gl/gl_passes.h"
#include "patchcull/gl_osd/osd_gl_draw.h"
#include "patchcull/import/model_loader.h"
#include "patchcull/import/osd_patch_table.h"
#include "render_options.h"

namespace patchcull::cli {

int run_osd_table_render(const OsdTableRender& o) {
    if (o.model == "teapot") throw Error("--patch-source osd-table: the teapot has no control mesh (use an OBJ model)");
    if (o.tess > 16) throw Error("--tess: at most 16 with --patch-source osd-table (OpenSubdiv's uniform level)");
    const LoadedModel model = load_model(o.model, Scheme::osd, 0);
    for (const std::string& w : model.warnings) std::fprintf(stderr, "render: %s\n", w.c_str());
    const ControlMesh& mesh = model.subdiv->mesh;
    const OsdAdaptiveTable table = make_osd_adaptive_table(mesh, 2);
    // Back-patch culling only on a closed surface (drawn one-sided), as applicable_cull_mode.
    std::uint32_t tests = static_cast<std::uint32_t>(o.cull);
    if (!model.closed && (tests & gl::kCullBackPatch)) {
        if (o.cull == gl::CullMode::all) {
            tests &= ~static_cast<std::uint32_t>(gl::kCullBackPatch);
        } else {
            std::fprintf(stderr, "render: back-patch culling on an open surface is not conservative\n");
        }
    }
    gl_osd::OsdCullSettings settings;
    settings.frustum = (tests & gl::kCullFrustum) != 0;
    settings.occlusion = (tests & gl::kCullOcclusion) != 0;
    if (tests & gl::kCullBackPatch) settings.backpatch = o.backpatch;
    settings.draw = o.indirect ? gl_osd::OsdDrawMode::indirect : gl_osd::OsdDrawMode::flags;
    settings.compact = o.compact;

    gl::GlContext context = gl::GlContext::create_headless(o.driver_threads);
    struct BufferGuard {  // the vertex buffer, deleted before the context
        GLuint name = 0;
        ~BufferGuard() {
            if (name) glDeleteBuffers(1, &name);
        }
    } buffer;
    nlohmann::json frames = nlohmann::json::array();
    std::size_t total_false = 0;
    std::size_t patches = 0;
    {
        gl::PassContext passes;
        gl_osd::OsdPatchTableDraw draw(passes, *table.table);
        gl_osd::OsdCullFrame frame(passes, draw, o.width, o.height);
        patches = draw.patch_count();
        glCreateBuffers(1, &buffer.name);
        glNamedBufferStorage(buffer.name, static_cast<GLsizeiptr>(table.points.size() * sizeof(Vec3)),
                             table.points.data(), 0);
        const gl_osd::OsdVertexBuffer vertices{buffer.name, sizeof(Vec3), 0, table.points.size()};
        const std::vector<Camera> cameras =
            orbit_sequence(compute_bounds(mesh.positions), o.frames, 4.0f, float(o.width) / float(o.height));
        for (int f = 0; f < o.frames; ++f) {
            Camera c = cameras[static_cast<std::size_t>(f)];
            c.depth = o.depth;
            gl_osd::OsdView view;
            view.model_view = c.view();
            view.projection = c.projection();
            view.depth = o.depth;
            view.eye = c.eye;
            view.tess_level = static_cast<float>(o.tess);
            view.one_sided = model.closed;
            std::vector<std::uint32_t> want;
            std::vector<float> want_depth;
            if (o.verify) {
                frame.render_unculled(vertices, view);
                want = frame.read_ids();
                want_depth = frame.read_depth();
            }
            const gl_osd::OsdFrameStats s = frame.render(vertices, view, settings);
            std::size_t false_culls = 0, differing = 0, ties = 0;
            if (o.verify) {
                const std::vector<std::uint32_t> got = frame.read_ids();
                const std::vector<float> got_depth = frame.read_depth();
                std::set<std::uint32_t> present(got.begin(), got.end()), missing;
                for (std::size_t i = 0; i < got.size(); ++i) {
                    if (got[i] == want[i]) continue;
                    ++differing;
                    if (got[i] != 0 && want[i] != 0 && got_depth[i] == want_depth[i]) ++ties;
                    if (want[i] != 0 && !present.count(want[i])) missing.insert(want[i]);
                }
                false_culls = missing.size();
            }
            total_false += false_culls;
            frames.push_back({{"frame", f},
                              {"pass1_drawn", s.drawn_pass1},
                              {"pass2_drawn", s.drawn_pass2},
                              {"submitted", {{"pass1", s.submitted_pass1}, {"pass2", s.submitted_pass2}}},
                              {"frustum_culled", s.frustum},
                              {"backpatch_culled", s.backpatch},
                              {"occlusion_culled", s.occlusion},
                              {"false_culls", false_culls},
                              {"differing_pixels", differing},
                              {"depth_ties", ties}});
            if (!o.json) {
                std::printf("frame %d: drawn %zu + %zu of %zu; culled frustum %zu, back-patch %zu, occlusion %zu", f,
                            s.drawn_pass1, s.drawn_pass2, patches, s.frustum, s.backpatch, s.occlusion);
                if (o.indirect) std::printf("; submitted %zu + %zu", s.submitted_pass1, s.submitted_pass2);
                if (o.verify)
                    std::printf("; false culls %zu, differing pixels %zu (depth ties %zu)", false_culls, differing,
                                ties);
                std::printf("\n");
            }
        }
    }
    if (o.json) {
        nlohmann::json out;
        out["model"] = model.name;
        out["patches"] = patches;
        out["size"] = {o.width, o.height};
        out["patch_source"] = "osd-table";
        out["draw"] = o.indirect ? "indirect" : "flags";
        if (o.indirect) out["compact"] = compact_option_name(o.compact);
        out["clip_depth"] = clip_depth_name(o.depth);
        out["tess"] = o.tess;
        out["cull"] = gl::cull_mode_name(o.cull);
        out["backpatch"] = settings.backpatch ? backpatch_method_name(*settings.backpatch) : "off";
        out["verified"] = o.verify;
        out["renderer"] = context.renderer();
        out["driver_threads"] = driver_threads_name(o.driver_threads);
        out["pinned_driver_threads"] = context.pinned_driver_threads();
        out["frames"] = frames;
        out["false_culls"] = total_false;
        std::cout << out.dump() << "\n";
    } else if (o.verify) {
        std::printf("false culls in total: %zu\n", total_false);
    }
    return total_false > 0 ? 1 : 0;
}

}  // namespace patchcull::cli
