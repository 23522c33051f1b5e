// `patchcull view [MODEL|default] ...`: the `render` pipeline (Niessner & Loop §3, with Loop,
// Niessner & Eisenacher's GPU back-patch pass) in a window (viewer/viewer_app.h). Interactive (no --frames, or with
// --script): an orbit/fly camera, a Dear ImGui panel with every cull test, method, bound and cone, the tessellation,
// the displacement and the status colouring of cull.png live, keys for the main toggles and a screenshot key; --script
// FILE drives it by frame number (viewer/viewer_script.h).
// --frames N without a script plays render's camera path for N frames with no panel (the window
// shows `render --out`'s images; --screenshot writes the last one), a line per frame.
// --tess-mode / --tess-distance, --displace, --cull auto, --draw, --compact and the object-level flags as
// `render`; the panel and a script's `set draw` / `set compact` switch the last two live.
#include <algorithm>
#include <cstdio>
#include <memory>

#include <CLI/CLI.hpp>

#include "cli_options.h"
#include "commands.h"
#include "cull_mode_names.h"
#include "object_level_options.h"
#include "patchcull/core/error.h"
#include "patchcull/import/scene_file.h"
#include "patchcull/import/scene_model.h"
#include "render_options.h"
#include "render_support.h"
#include "viewer/viewer_app.h"
#include "viewer/viewer_script.h"

namespace patchcull::cli {
namespace {

// Every screenshot PATH of the script must be writable before the window opens.
void check_script_outputs(const ViewerScript& script) {
    for (const ScriptEvent& e : script.events) {
        if (e.kind != ScriptEvent::Kind::screenshot) continue;
        try {
            check_output_file("screenshot", e.value);
        } catch (const Error& error) {
            throw Error(script.path + ":" + std::to_string(e.line) + ": " + error.what());
        }
    }
}

}  // namespace

Runner add_view_command(CLI::App& app) {
    struct State {
        std::string model = "default";
        std::string scheme = "acc";
        int split = 0;
        int frames = 0;
        std::string cull = "all";
        std::string backpatch = "tcone";
        std::string frustum = "hull";
        std::string draw = "indirect";
        std::string compact = "scan";
        int tess = 8;
        TessOptions tess_options;
        DisplaceOptions displace;
        std::string size = "960x540";
        std::string clip_depth = "zero-to-one";
        bool aggressive = false;
        std::string screenshot;
        std::string screenshot_dir = "out";
        std::string script;
        ObjectLevelOptions objects;
    };
    auto state = std::make_shared<State>();
    CLI::App* command = app.add_subcommand("view", "Show the GPU cull pipeline in a window (GLFW, Dear ImGui panel)");
    add_text_option(*command, "MODEL", state->model,
                    "OBJ control mesh, 'teapot', 'bigguy', 'monsterfrog', a built-in scene ('default', 'city', "
                    "'building') or a scene file (.json)");
    add_choice_option(*command, "--scheme", state->scheme, {"acc", "osd"}, "Catmull-Clark to Bezier scheme");
    add_int_option(*command, "--split", state->split, 0, 4, "uniform 1-to-4 patch splits of MODEL");
    add_int_option(*command, "--frames", state->frames, 0, 1000000,
                   "stop after N frames; without --script: render's camera path, no panel (0: interactive, until "
                   "the window is closed)");
    add_choice_option(*command, "--cull", state->cull, cull_mode_choices(),
                      "cull tests at the start (auto: all, per object where it pays, Niessner & Loop §6.3)");
    add_choice_option(*command, "--backpatch", state->backpatch, backpatch_method_choices(),
                      "back-patch test of backpatch/all");
    add_choice_option(*command, "--frustum", state->frustum, {"hull", "aabb"},
                      "frustum test: hull (control points, Niessner & Loop) or aabb (box grown by max |D|, Sathe)");
    add_choice_option(*command, "--draw", state->draw, {"flags", "indirect"},
                      "how the draw passes issue patches: indirect (the default: the survivors compacted into indirect "
                      "draws) or flags (every patch, the TCS drops the culled)");
    add_compact_option(*command, state->compact);
    add_clip_depth_option(*command, state->clip_depth);
    add_int_option(*command, "--tess", state->tess, 1, 64, "tessellation level (adaptive: the maximum)");
    add_tess_options(*command, state->tess_options);
    add_displace_options(*command, state->displace);
    add_object_level_options(*command, state->objects);
    add_size_option(*command, "--size", state->size, "window size");
    command->add_flag("--aggressive", state->aggressive,
                      "skip the second pass (Niessner & Loop §3.1; not conservative)");
    add_output_file_option(*command, "--screenshot", state->screenshot,
                           "after the last of --frames, write the window's content as a PNG");
    add_text_option(*command, "--screenshot-dir", state->screenshot_dir,
                    "directory of the screenshot key's view_NNNN.png (created when first needed)");
    add_text_option(
        *command, "--script", state->script,
        "timed input events by frame number (orbit, look, zoom, key, set, screenshot, quit; docs/VIEWER.md)");
    return [state]() {
        // The script first: a malformed line is reported before anything is loaded or opened.
        std::unique_ptr<ViewerScript> script;
        if (!state->script.empty()) {
            script = std::make_unique<ViewerScript>(load_viewer_script(state->script));
            check_script_outputs(*script);
        }
        ViewerConfig config;
        parse_size("--size", state->size, config.width, config.height);
        const bool automatic = state->cull == "auto";
        const gl::CullMode cull = automatic ? gl::CullMode::all : parse_cull_mode_option("--cull", state->cull);
        if (!state->screenshot.empty() && state->frames == 0)
            throw Error("--screenshot: needs --frames N (the last frame is the one saved)");
        Scene scene = load_scene(state->model, state->scheme, state->split);
        // The viewer draws in one float frame, at its first camera's grid point: the frames of
        // its path must stay within kMaxSingleFrameReach of it (interactive: where it starts).
        place_scene_at_first_camera(scene, state->model, std::max(state->frames, 1), kSecondsPerFrame);
        apply_displace_options(state->displace, scene);
        config.tess_mode = resolve_tess_mode(state->tess_options, scene.camera);
        config.frustum = state->frustum == "aabb" ? gl::FrustumTest::aabb : gl::FrustumTest::hull;
        config.clip_depth = parse_clip_depth_option(state->clip_depth);

        ViewerSettings& s = config.settings;
        s.draw = state->draw == "indirect" ? gl::DrawMode::indirect : gl::DrawMode::flags;
        s.compact = parse_compact_option(state->compact);
        set_cull_toggles(s, applicable_cull_mode(scene, cull, "view"));
        s.cull_auto = automatic;
        s.backpatch_method = parse_backpatch_method("--backpatch", state->backpatch);
        s.bound = displace_bound(state->displace);
        s.cone = displace_cone(state->displace);
        s.aggressive = state->aggressive;
        s.tess = state->tess;
        s.adaptive_tess = config.tess_mode.adaptive;
        s.displace = !scene.displacement.empty();
        if (s.displace) s.displace_scale = scene.displacement.scale;
        s.objects = state->objects.method;
        config.interactive = state->frames == 0 || script;
        s.camera = config.interactive ? ViewerCameraMode::orbit : ViewerCameraMode::path;
        s.panel = config.interactive;
        config.frames = state->frames;
        config.final_screenshot = state->screenshot;
        config.screenshot_dir = state->screenshot_dir;
        config.script = script.get();
        config.objects = state->objects;
        config.scene = std::move(scene);
        return run_viewer(config);
    };
}

}  // namespace patchcull::cli
