// `patchcull view`'s window loop (viewer_app.h).
#include "viewer_app.h"

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE  // GL declarations come from libepoxy
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <vector>

#include "commands.h"
#include "patchcull/core/error.h"
#include "patchcull/eval_gl/reference_frame.h"
#include "patchcull/gl/cull_auto_policy.h"
#include "render_support.h"
#include "viewer_camera.h"
#include "viewer_controls.h"
#include "viewer_panel.h"
#include "viewer_world.h"

namespace patchcull::cli {
namespace {

// Key presses and wheel steps from GLFW's callbacks (installed before ImGui's, which chain to them),
// kept until the frame takes them.
struct InputQueue {
    std::vector<ViewerKey> pressed;
    double wheel = 0;
};

bool key_of(int glfw_key, ViewerKey& key) {
    switch (glfw_key) {
        case GLFW_KEY_1:
            key = ViewerKey::toggle_frustum;
            return true;
        case GLFW_KEY_2:
            key = ViewerKey::toggle_backpatch;
            return true;
        case GLFW_KEY_3:
            key = ViewerKey::toggle_occlusion;
            return true;
        case GLFW_KEY_4:
            key = ViewerKey::toggle_auto;
            return true;
        case GLFW_KEY_B:
            key = ViewerKey::next_backpatch;
            return true;
        case GLFW_KEY_G:
            key = ViewerKey::toggle_aggressive;
            return true;
        case GLFW_KEY_V:
            key = ViewerKey::next_view;
            return true;
        case GLFW_KEY_C:
            key = ViewerKey::next_camera;
            return true;
        case GLFW_KEY_R:
            key = ViewerKey::reset_camera;
            return true;
        case GLFW_KEY_H:
            key = ViewerKey::toggle_panel;
            return true;
        case GLFW_KEY_X:
            key = ViewerKey::toggle_displace;
            return true;
        case GLFW_KEY_EQUAL:
        case GLFW_KEY_KP_ADD:
            key = ViewerKey::tess_up;
            return true;
        case GLFW_KEY_MINUS:
        case GLFW_KEY_KP_SUBTRACT:
            key = ViewerKey::tess_down;
            return true;
        case GLFW_KEY_SPACE:
            key = ViewerKey::pause;
            return true;
        case GLFW_KEY_P:
        case GLFW_KEY_F12:
            key = ViewerKey::screenshot;
            return true;
        default:
            return false;  // movement keys are polled (held), Escape closes the window (GlContext)
    }
}

void on_key(GLFWwindow* window, int glfw_key, int, int action, int) {
    ViewerKey key{};
    if (action == GLFW_RELEASE || !key_of(glfw_key, key)) return;
    // Auto-repeat only steps the tessellation level; a held toggle flips once.
    if (action == GLFW_REPEAT && key != ViewerKey::tess_up && key != ViewerKey::tess_down) return;
    static_cast<InputQueue*>(glfwGetWindowUserPointer(window))->pressed.push_back(key);
}

void on_scroll(GLFWwindow* window, double, double dy) {
    static_cast<InputQueue*>(glfwGetWindowUserPointer(window))->wheel += dy;
}

// The status colouring shown in the window: the RGBA image (row 0 = top) uploaded to a texture and
// blitted, flipped, to the back buffer.
class StatusDisplay {
public:
    ~StatusDisplay() {
        if (fbo_) glDeleteFramebuffers(1, &fbo_);
        if (texture_) glDeleteTextures(1, &texture_);
    }
    void show(const std::vector<std::uint8_t>& rgba, int width, int height) {
        if (!texture_) {
            glCreateTextures(GL_TEXTURE_2D, 1, &texture_);
            glTextureStorage2D(texture_, 1, GL_RGBA8, width, height);
            glCreateFramebuffers(1, &fbo_);
            glNamedFramebufferTexture(fbo_, GL_COLOR_ATTACHMENT0, texture_, 0);
        }
        glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
        glTextureSubImage2D(texture_, 0, 0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
        glBlitNamedFramebuffer(fbo_, 0, 0, 0, width, height, 0, height, width, 0, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    }

private:
    GLuint texture_ = 0, fbo_ = 0;
};

// The next free DIR/view_NNNN.png from counter on (created directory), or "" with why set.
std::string numbered_screenshot(const std::string& dir, int& counter, std::string& why) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) {
        why = "view: screenshot: cannot create directory '" + dir + "': " + ec.message();
        return "";
    }
    for (;; ++counter) {
        char name[32];
        std::snprintf(name, sizeof name, "view_%04d.png", counter);
        const std::filesystem::path p = std::filesystem::path(dir) / name;
        if (!std::filesystem::exists(p, ec)) return ++counter, p.string();
    }
}

}  // namespace

int run_viewer(ViewerConfig& config) {
    const int width = config.width, height = config.height;
    ViewerSettings settings = config.settings;
    const bool scripted = config.script != nullptr;
    const bool print_frames = !config.interactive || scripted || config.frames > 0;
    // A model's scene is named by its path: the panel's title shows the file name.
    const std::string scene_name = std::filesystem::path(config.scene.name).filename().string();
    ViewerWorld world(std::move(config.scene), config.objects);
    int anim_frame = 0;        // frames the animation (and the path camera) advanced: time = anim_frame / 12 s
    world.build(settings, 0);  // before the window: a bad object-level flag is an error without one
    gl::GlContext context = gl::GlContext::create_window(width, height, "patchcull view: " + scene_name);
    gl::CullPipeline pipeline(context);
    // The object level's query objects (--object-occlusion) go before the context does.
    struct ReleaseWorldGl {
        ViewerWorld& world;
        ~ReleaseWorldGl() { world.object_level().release_gl(); }
    } release_world_gl{world};
    world.upload(pipeline);
    // One lap of the camera path, repeated (the same cameras as `render --frames lap`).
    const int lap = !config.interactive && config.frames > 0 ? config.frames : 72;
    const std::vector<Camera> cameras = world.scene().camera_path(lap, float(width) / float(height));
    ViewerCamera camera(cameras[0], cameras[0].target);
    ViewerControls controls(settings, camera);
    gl::CullAutoPolicy policy(world.ranges(), world.scene().patch_count());
    gl::DrawMode auto_draw = settings.draw;  // the draw mode policy's costs were measured in

    InputQueue queue;
    GLFWwindow* window = context.glfw_window();
    std::unique_ptr<ViewerPanel> panel;
    if (config.interactive) {
        glfwSetWindowUserPointer(window, &queue);
        glfwSetKeyCallback(window, on_key);
        glfwSetScrollCallback(window, on_scroll);
        panel = std::make_unique<ViewerPanel>(window);  // after ours: ImGui's callbacks chain to them
    }
    StatusDisplay status_display;
    std::size_t next_event = 0;
    double cursor_x = 0, cursor_y = 0, last_time = glfwGetTime(), fps = 0;
    glfwGetCursorPos(window, &cursor_x, &cursor_y);
    int shot_counter = 0;
    std::string message;
    bool warned_open_backpatch = false;
    gl::FrameStats stats;
    for (int f = 0; config.frames == 0 || f < config.frames; ++f) {
        if (!context.window_open()) break;  // polls events: the callbacks fill the queue
        const double now = glfwGetTime();
        const double wall_dt = std::clamp(now - last_time, 0.0, 0.25);
        last_time = now;
        if (f > 1 && wall_dt > 0) fps = fps == 0 ? 1 / wall_dt : 0.9 * fps + 0.1 / wall_dt;  // from frame 1's time
        const Camera& path_camera = cameras[static_cast<std::size_t>(anim_frame % lap)];

        // Input: the script's events of this frame, then the user's (both through Controls).
        std::vector<std::string> script_shots;
        bool script_quit = false;
        while (scripted && next_event < config.script->events.size() && config.script->events[next_event].frame == f) {
            const ScriptEvent& e = config.script->events[next_event++];
            switch (e.kind) {
                case ScriptEvent::Kind::orbit:
                    controls.drag(true, e.x, e.y, path_camera);
                    break;
                case ScriptEvent::Kind::look:
                    controls.drag(false, e.x, e.y, path_camera);
                    break;
                case ScriptEvent::Kind::zoom:
                    controls.wheel(e.x, path_camera);
                    break;
                case ScriptEvent::Kind::key:
                    controls.key(e.key, path_camera);
                    break;
                case ScriptEvent::Kind::set:
                    apply_setting(settings, e.name, e.value);  // checked by the parser
                    controls.sync(path_camera);
                    break;
                case ScriptEvent::Kind::screenshot:
                    script_shots.push_back(e.value);
                    break;
                case ScriptEvent::Kind::quit:
                    script_quit = true;
                    break;
            }
        }
        if (panel) {
            double x = 0, y = 0;
            glfwGetCursorPos(window, &x, &y);
            const float dx = float(x - cursor_x), dy = float(y - cursor_y);
            cursor_x = x, cursor_y = y;
            if (!panel->wants_mouse()) {
                if (glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS && (dx || dy))
                    controls.drag(true, dx, dy, path_camera);
                else if (glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS && (dx || dy))
                    controls.drag(false, dx, dy, path_camera);
                if (queue.wheel != 0) controls.wheel(float(queue.wheel), path_camera);
            }
            queue.wheel = 0;
            if (!panel->wants_keyboard()) {
                for (ViewerKey k : queue.pressed) controls.key(k, path_camera);
                const std::pair<int, ViewerKey> held[] = {
                    {GLFW_KEY_W, ViewerKey::forward}, {GLFW_KEY_S, ViewerKey::back}, {GLFW_KEY_A, ViewerKey::left},
                    {GLFW_KEY_D, ViewerKey::right},   {GLFW_KEY_E, ViewerKey::up},   {GLFW_KEY_Q, ViewerKey::down}};
                for (const auto& [glfw_key, k] : held)
                    if (glfwGetKey(window, glfw_key) == GLFW_PRESS) controls.hold(k);
            }
            queue.pressed.clear();
        }
        // Script time is frames (deterministic); the user's is the wall clock.
        controls.move(scripted ? kSecondsPerFrame : float(wall_dt), path_camera);

        // The scene: rebuilt for another displacement or object level, else posed when playing.
        if (world.needs_build(settings)) {
            world.build(settings, anim_frame * kSecondsPerFrame);
            world.upload(pipeline);
        } else if (f > 0 && !settings.paused) {
            ++anim_frame;
            world.pose(anim_frame * kSecondsPerFrame, pipeline);
        }
        Camera view_camera = settings.camera == ViewerCameraMode::path
                                 ? cameras[static_cast<std::size_t>(anim_frame % lap)]
                                 : camera.camera();
        view_camera.depth = config.clip_depth;

        gl::PipelineParams params;
        params.frame.render = eval_gl::render_params(view_camera, width, height, settings.tess, world.one_sided());
        TessMode tess_mode = config.tess_mode;
        tess_mode.adaptive = settings.adaptive_tess;
        apply_tess_mode(tess_mode, params.frame.render);
        params.frame.cull = settings_cull_mode(settings);
        params.frame.aggressive = settings.aggressive;
        params.backpatch = settings.backpatch_method;
        params.bound = settings.bound;
        params.cone = settings.cone;
        params.frustum = config.frustum;
        params.draw = settings.draw;
        params.compact = settings.compact;
        if (settings.cull_auto && settings.draw != auto_draw) {
            // The policy's costs are of one draw mode (an indirect pass costs no culled patch):
            // measured again after a switch.
            policy = gl::CullAutoPolicy(world.ranges(), world.scene().patch_count());
        }
        auto_draw = settings.draw;
        if (settings.backpatch && !world.one_sided() && config.interactive && !warned_open_backpatch) {
            // As `render --cull backpatch` on an open surface: kept, with one warning.
            warned_open_backpatch = true;
            print_warnings(
                {"view: the scene has an open surface: back-patch culling may remove patches seen "
                 "through its openings"});
        }
        world.object_level().apply(world.poser(), world.current_pose(), anim_frame * kSecondsPerFrame, view_camera,
                                   height, params);
        if (settings.cull_auto) {
            policy.decide(gl::object_tess_factors(world.current_pose(), world.ranges(), params.frame.render));
            params.objects = policy.objects();
            params.frame.cull = policy.frame_cull_mode(params.frame.cull);
            if (policy.resumes_culling()) pipeline.forget_visibility();
        }
        stats = pipeline.render_frame(params);
        if (settings.cull_auto) policy.observe(stats);

        // The window: the colour image or the status colouring, then the panel.
        if (settings.view == ViewerView::colour) {
            pipeline.renderer().blit_color_to_window(width, height);
        } else {
            gl::RenderParams seen = params.frame.render;
            if (settings.view == ViewerView::status_second) {
                seen = eval_gl::render_params(second_status_camera(view_camera), width, height, settings.tess,
                                              world.one_sided());
                apply_tess_mode(tess_mode, seen);
            }
            status_display.show(pipeline.renderer().render_status_image(seen), width, height);
        }
        if (panel && settings.panel) {
            PanelInfo info;
            info.scene_name = scene_name;
            info.renderer = context.renderer();
            info.one_sided = world.one_sided();
            info.object_level = world.object_level().enabled();
            info.frame = f;
            info.fps = fps;
            info.stats = &stats;
            info.objects = &world.object_level().result().stats;
            info.message = message;
            const PanelActions actions = panel->draw(settings, info);
            if (actions.reset_camera) controls.reset();
            if (actions.screenshot) controls.key(ViewerKey::screenshot, path_camera);
            controls.sync(path_camera);
        } else if (panel) {
            panel->hidden();
        }

        // Screenshots: the window's content as shown (panel included when drawn).
        for (const std::string& path : script_shots) {
            context.write_window_png(path);
            std::printf("screenshot %s (frame %d)\n", path.c_str(), f);
        }
        if (controls.take_screenshot()) {
            std::string why;
            const std::string path = numbered_screenshot(config.screenshot_dir, shot_counter, why);
            try {
                if (path.empty()) throw Error(why);
                context.write_window_png(path);
                message = "wrote " + path;
                std::printf("screenshot %s (frame %d)\n", path.c_str(), f);
            } catch (const Error& e) {
                message = e.what();  // a failed screenshot does not end the session
                print_warnings({message});
            }
        }
        const bool last = config.frames > 0 && f + 1 == config.frames;
        if (last && !config.final_screenshot.empty()) context.write_window_png(config.final_screenshot);
        context.swap_buffers();
        if (print_frames) {
            std::printf(
                "frame %d: drawn %zu + %zu of %zu; culled frustum %zu, back-patch %zu, occlusion %zu "
                "(displaced %zu); submitted %zu + %zu (%s); %.1f ms\n",
                f, stats.pass1_drawn, stats.pass2_drawn, stats.patches, stats.frustum_culled, stats.backpatch_culled,
                stats.occlusion_culled, stats.displaced_occlusion_culled, stats.pass1_submitted, stats.pass2_submitted,
                gl::draw_mode_name(stats.draw), stats.total_ms);
            if (settings.cull_auto)
                std::printf("%s\n", gl::auto_summary_line(world.names(), policy.decisions()).c_str());
            if (world.object_level().enabled())
                std::printf("  objects (%s): %zu frustum-culled, %zu back-face-culled of %zu; %zu patches skipped\n",
                            world.object_level().method_name(), world.object_level().result().stats.frustum_culled,
                            world.object_level().result().stats.backface_culled,
                            world.object_level().result().stats.total,
                            world.object_level().result().stats.patches_culled);
        }
        if (script_quit || controls.quit()) break;
    }
    std::fflush(stdout);
    return 0;
}

}  // namespace patchcull::cli
