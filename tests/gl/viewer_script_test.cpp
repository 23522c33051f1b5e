// The interactive viewer (`patchcull view`): its --script parser and settings (no GL),
// its orbit/fly camera, the one-line errors of malformed scripts (before any window opens), and a
// scripted session under a virtual X server (xvfb-run): a camera move, a cull toggle through
// `set` and through its key, and the panel, each checked on the screenshots.
#include <gtest/gtest.h>
#include <stb_image.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "cli/cli_test_util.h"
#include "patchcull/core/error.h"
#include "viewer/viewer_camera.h"
#include "viewer/viewer_controls.h"
#include "viewer/viewer_script.h"
#include "viewer/viewer_settings.h"

using namespace patchcull;
using namespace patchcull::cli;
using namespace patchcull::cli_test;

namespace {

std::string parse_error(const std::string& text) {
    try {
        parse_viewer_script(text, "s.txt");
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

struct Rgb {
    int width = 0, height = 0;
    std::vector<unsigned char> rgb;  // top row first
    const unsigned char* at(int x, int y) const { return &rgb[(static_cast<std::size_t>(y) * width + x) * 3]; }
};

Rgb load_rgb(const std::string& path) {
    Rgb image;
    int channels = 0;
    unsigned char* data = stbi_load(path.c_str(), &image.width, &image.height, &channels, 3);
    if (!data) return image;
    image.rgb.assign(data, data + static_cast<std::size_t>(image.width) * image.height * 3);
    stbi_image_free(data);
    return image;
}

// Pixels of the status colouring's magenta (back-patch-culled: (0.85, 0.3, 0.9) times a shade in
// 0.25..1, patch.frag.glsl) and red (occlusion-culled: (1, 0.2, 0.15) shaded). Grey occluders,
// the dark background and the other statuses' green, yellow and blue are none of them.
bool is_magenta(const unsigned char* p) {
    const float r = p[0], g = p[1], b = p[2];
    return b >= 40 && r >= 0.8f * b && r <= 1.05f * b && g >= 0.2f * b && g <= 0.45f * b;
}
bool is_red(const unsigned char* p) { return p[0] >= 40 && p[0] > 3 * p[1] && p[0] > 3 * p[2]; }

std::size_t count(const Rgb& image, bool (*pick)(const unsigned char*)) {
    std::size_t n = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) n += pick(image.at(x, y));
    return n;
}

// Pixels that differ between a and b in columns [x0, x1).
std::size_t differing(const Rgb& a, const Rgb& b, int x0, int x1) {
    std::size_t n = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = x0; x < x1; ++x) {
            const unsigned char *p = a.at(x, y), *q = b.at(x, y);
            n += p[0] != q[0] || p[1] != q[1] || p[2] != q[2];
        }
    return n;
}

const char* const kXvfb = "xvfb-run -a -s '-screen 0 1280x1024x24'";

// xvfb-run -a picks a free display number racily: another xvfb-run started at the same moment
// (ctest -j) can take it, and this one's server then fails to start. Such runs are retried.
CliRun run_under_xvfb(const std::string& args) {
    CliRun r;
    for (int attempt = 0; attempt < 3; ++attempt) {
        r = run(args, kXvfb);
        if (r.err.find("Xvfb failed to start") == std::string::npos) break;
    }
    return r;
}

}  // namespace

TEST(ViewerScript, ParsesEveryEvent) {
    const ViewerScript s = parse_viewer_script(
        "# a comment\n\n0 orbit 10 -2.5\n0 look 1 2  # trailing comment\n1 zoom -3\n2 key space\n2 key f12\n"
        "3 set cull.occlusion off\n3 set view status-second\n4 screenshot out/a.png\n4 quit\n",
        "s.txt");
    ASSERT_EQ(s.events.size(), 9u);
    EXPECT_EQ(s.events[0].kind, ScriptEvent::Kind::orbit);
    EXPECT_EQ(s.events[0].line, 3);
    EXPECT_EQ(s.events[0].x, 10.0f);
    EXPECT_EQ(s.events[0].y, -2.5f);
    EXPECT_EQ(s.events[1].kind, ScriptEvent::Kind::look);
    EXPECT_EQ(s.events[2].kind, ScriptEvent::Kind::zoom);
    EXPECT_EQ(s.events[2].x, -3.0f);
    EXPECT_EQ(s.events[3].key, ViewerKey::pause);
    EXPECT_EQ(s.events[4].key, ViewerKey::screenshot);
    EXPECT_EQ(s.events[5].name, "cull.occlusion");
    EXPECT_EQ(s.events[5].value, "off");
    EXPECT_EQ(s.events[7].value, "out/a.png");
    EXPECT_EQ(s.events[8].kind, ScriptEvent::Kind::quit);
    EXPECT_EQ(s.events[8].frame, 4);
}

TEST(ViewerScript, MalformedLinesNameFileAndLine) {
    EXPECT_EQ(parse_error("0 quit\nx orbit 1 1\n"), "s.txt:2: expected a frame number in 0..10000000, got 'x'");
    EXPECT_EQ(parse_error("-1 quit\n"), "s.txt:1: expected a frame number in 0..10000000, got '-1'");
    EXPECT_EQ(parse_error("5 quit\n4 quit\n"), "s.txt:2: frame 4 comes after frame 5 (events must be in frame order)");
    EXPECT_EQ(parse_error("1 jump\n").rfind("s.txt:1: unknown event 'jump'", 0), 0u);
    EXPECT_EQ(parse_error("1\n").rfind("s.txt:1: expected an event", 0), 0u);
    EXPECT_EQ(parse_error("1 orbit 1\n"), "s.txt:1: orbit: expected 'FRAME orbit DX DY'");
    EXPECT_EQ(parse_error("1 orbit 1 nan\n"), "s.txt:1: orbit: DY must be a number in -1e6..1e6, got 'nan'");
    EXPECT_EQ(parse_error("1 zoom 1e9\n"), "s.txt:1: zoom: STEPS must be a number in -1e6..1e6, got '1e9'");
    EXPECT_EQ(parse_error("1 key z\n").rfind("s.txt:1: unknown key 'z' (1 2 3", 0), 0u);
    EXPECT_EQ(parse_error("1 set cull.everything off\n").rfind("s.txt:1: unknown setting 'cull.everything'", 0), 0u);
    EXPECT_EQ(parse_error("1 set cull.frustum maybe\n"), "s.txt:1: set cull.frustum: expected on or off, got 'maybe'");
    EXPECT_EQ(parse_error("1 set tess 65\n"), "s.txt:1: set tess: expected an integer in 1..64, got '65'");
    EXPECT_EQ(parse_error("1 set view side\n"),
              "s.txt:1: set view: expected one of colour, status, status-second, got 'side'");
    EXPECT_EQ(parse_error("1 set displace.scale 0\n"),
              "s.txt:1: set displace.scale: expected a number in (0, 1], got '0'");
    EXPECT_EQ(parse_error("1 screenshot\n"), "s.txt:1: screenshot: expected 'FRAME screenshot PATH'");
    EXPECT_EQ(parse_error("1 quit now\n"), "s.txt:1: quit: expected 'FRAME quit'");
    EXPECT_EQ(parse_error("1 key \x01\n").rfind("s.txt:1: unknown key '\\x01'", 0), 0u);  // printable
    EXPECT_EQ(parse_error("1 key F12\n").rfind("s.txt:1: unknown key 'F12'", 0), 0u);
}

TEST(ViewerSettings, KeysAndSetsChangeTheSameState) {
    ViewerSettings s;
    EXPECT_EQ(settings_cull_mode(s), gl::CullMode::all);
    EXPECT_TRUE(apply_settings_key(s, ViewerKey::toggle_occlusion));
    EXPECT_FALSE(s.occlusion);
    EXPECT_EQ(apply_setting(s, "cull.occlusion", "on"), "");
    EXPECT_TRUE(s.occlusion);
    EXPECT_EQ(apply_setting(s, "cull.frustum", "off"), "");
    EXPECT_EQ(settings_cull_mode(s), static_cast<gl::CullMode>(gl::kCullBackPatch | gl::kCullOcclusion));
    apply_settings_key(s, ViewerKey::next_backpatch);
    EXPECT_EQ(s.backpatch_method, gl::BackpatchMethod::ncone);
    apply_settings_key(s, ViewerKey::next_view);
    apply_settings_key(s, ViewerKey::next_view);
    EXPECT_EQ(s.view, ViewerView::status_second);
    s.tess = 64;
    apply_settings_key(s, ViewerKey::tess_up);
    EXPECT_EQ(s.tess, 64);
    EXPECT_EQ(apply_setting(s, "tess", "3"), "");
    EXPECT_EQ(s.tess, 3);
    EXPECT_FALSE(apply_settings_key(s, ViewerKey::forward));  // the camera's, not a setting
    const ViewerSettings before = s;
    EXPECT_NE(apply_setting(s, "tess", "3x"), "");
    EXPECT_EQ(s.tess, before.tess);  // unchanged on error
}

// The draw mode and the compaction (the panel's "draw" and "compaction", `set draw`, `set compact`).
TEST(ViewerSettings, DrawModeAndCompactionSwitch) {
    ViewerSettings s;
    EXPECT_EQ(s.draw, gl::DrawMode::indirect);
    EXPECT_EQ(s.compact, gl::CompactMethod::prefix_scan);
    EXPECT_EQ(apply_setting(s, "draw", "flags"), "");
    EXPECT_EQ(s.draw, gl::DrawMode::flags);
    EXPECT_EQ(apply_setting(s, "compact", "append"), "");
    EXPECT_EQ(s.compact, gl::CompactMethod::atomic_append);
    EXPECT_EQ(apply_setting(s, "compact", "fused"), "");
    EXPECT_EQ(s.compact, gl::CompactMethod::fused_append);
    EXPECT_EQ(apply_setting(s, "draw", "indirect"), "");
    EXPECT_EQ(apply_setting(s, "compact", "scan"), "");
    EXPECT_EQ(s.draw, gl::DrawMode::indirect);
    EXPECT_EQ(s.compact, gl::CompactMethod::prefix_scan);
    EXPECT_EQ(apply_setting(s, "draw", "list"), "set draw: expected one of flags, indirect, got 'list'");
    EXPECT_EQ(apply_setting(s, "compact", "atomic"), "set compact: expected one of scan, append, fused, got 'atomic'");
    EXPECT_EQ(s.draw, gl::DrawMode::indirect);  // unchanged on error
    EXPECT_EQ(s.compact, gl::CompactMethod::prefix_scan);
    EXPECT_EQ(parse_error("3 set draw sometimes\n").rfind("s.txt:1: set draw: expected one of flags, indirect", 0), 0u);
}

TEST(ViewerCamera, OrbitKeepsTheDistanceAndZoomChangesIt) {
    Camera start;
    start.eye = {0, 1, 4};
    start.target = {0, 0.5f, 0};
    ViewerCamera camera(start, start.target);
    const float d0 = length(camera.eye() - start.target);
    const Vec3 right = cross(camera.forward(), Vec3{0, 1, 0});
    camera.orbit(360, 0);  // 90 degrees about the vertical; dragged right, the eye goes left
    EXPECT_LT(dot(camera.eye() - start.eye, right), -3.0f);
    EXPECT_NEAR(length(camera.eye() - start.target), d0, 1e-4f * d0);
    EXPECT_NEAR(camera.eye().z, 0.0f, 1e-3f);  // from +z to the side
    EXPECT_GT(std::fabs(camera.eye().x), 3.0f);
    const Vec3 to_centre = normalize(start.target - camera.eye());
    EXPECT_GT(dot(camera.forward(), to_centre), 0.9999f);  // still looking at the centre
    camera.orbit(0, 10000);                                // far past the pole: clamped below it
    EXPECT_LT(camera.forward().y, 0);
    EXPECT_GT(std::fabs(camera.forward().y), 0.99f);
    EXPECT_LT(std::fabs(camera.forward().y), 1.0f);
    camera.zoom(1);
    EXPECT_NEAR(length(camera.eye() - start.target), 0.9f * d0, 1e-3f * d0);
    camera.zoom(1000);
    EXPECT_NEAR(length(camera.eye() - start.target), d0 / 50, 1e-3f * d0);  // clamped
    camera.reset();
    EXPECT_NEAR(length(camera.eye() - start.eye), 0.0f, 1e-5f);
}

TEST(ViewerCamera, FlyMovesAlongTheViewAndLooks) {
    Camera start;
    start.eye = {0, 0, 4};
    start.target = {0, 0, 0};
    ViewerCamera camera(start, start.target);
    camera.move(0, 0, 1, 1.0f);  // 1 s forward: half the start distance
    EXPECT_NEAR(camera.eye().z, 2.0f, 1e-4f);
    camera.move(1, 0, 0, 1.0f);  // right of a view along -z is +x
    EXPECT_NEAR(camera.eye().x, 2.0f, 1e-4f);
    camera.move(0, -1, 0, 0.5f);
    EXPECT_NEAR(camera.eye().y, -1.0f, 1e-4f);
    camera.look(600, 0);  // 90 degrees to the right: now looking along +x
    EXPECT_NEAR(camera.forward().x, 1.0f, 1e-4f);
    camera.look_at_centre();
    EXPECT_GT(dot(camera.forward(), normalize(start.target - camera.eye())), 0.9999f);
    const Camera c = camera.camera();
    EXPECT_NEAR(length(c.target - c.eye), 4.0f, 1e-4f);
    const Camera second = second_status_camera(start);  // beside and above, as demo's cull.png
    EXPECT_GT(second.eye.y, start.eye.y + 1);
    EXPECT_NEAR(dot(normalize(second.eye - second.target) - Vec3{0, normalize(second.eye - second.target).y, 0},
                    normalize(start.eye - start.target)),
                0.0f, 1e-4f);
}

TEST(ViewerControls, LeavingThePathStartsWhereThePathCameraIs) {
    Camera start;
    start.eye = {0, 1, 4};
    start.target = {0, 0, 0};
    Camera path = start;  // the path's camera of this frame, elsewhere on the circle
    path.eye = {4, 1, 0};
    ViewerSettings s;
    s.camera = ViewerCameraMode::path;
    ViewerCamera camera(start, start.target);
    ViewerControls controls(s, camera);
    controls.drag(true, 0, 0, path);  // a left-drag on the path: orbit from the path camera
    EXPECT_EQ(s.camera, ViewerCameraMode::orbit);
    EXPECT_NEAR(length(camera.eye() - path.eye), 0.0f, 1e-5f);
    controls.wheel(1, path);
    EXPECT_NEAR(length(camera.eye() - start.target), 0.9f * length(path.eye - start.target), 1e-4f);
    // c: orbit -> fly -> path -> orbit; the eye stays where it is when flying starts.
    const Vec3 before = camera.eye();
    controls.key(ViewerKey::next_camera, path);
    EXPECT_EQ(s.camera, ViewerCameraMode::fly);
    EXPECT_NEAR(length(camera.eye() - before), 0.0f, 1e-6f);
    controls.key(ViewerKey::next_camera, path);
    EXPECT_EQ(s.camera, ViewerCameraMode::path);
    controls.drag(false, 0, 0, path);  // a right-drag on the path: fly from the path camera
    EXPECT_EQ(s.camera, ViewerCameraMode::fly);
    EXPECT_NEAR(length(camera.eye() - path.eye), 0.0f, 1e-5f);
    controls.key(ViewerKey::reset_camera, path);
    EXPECT_NEAR(length(camera.eye() - start.eye), 0.0f, 1e-5f);
}

TEST(ViewerControls, HeldKeysMoveForTheFrameOnly) {
    Camera start;
    start.eye = {0, 0, 4};
    start.target = {0, 0, 0};
    ViewerSettings s;
    s.camera = ViewerCameraMode::fly;
    ViewerCamera camera(start, start.target);
    ViewerControls controls(s, camera);
    controls.key(ViewerKey::forward, start);  // a script's `key w`: held for one frame
    controls.move(0.5f, start);               // half a second: a quarter of the start distance
    EXPECT_NEAR(camera.eye().z, 3.0f, 1e-4f);
    controls.move(0.5f, start);  // not held any more
    EXPECT_NEAR(camera.eye().z, 3.0f, 1e-4f);
    // Orbiting: e raises the eye, d moves it to the view's right; the distance stays.
    s.camera = ViewerCameraMode::orbit;
    controls.sync(start);
    const float d = length(camera.eye() - start.target);
    const Vec3 right = cross(camera.forward(), Vec3{0, 1, 0});
    const Vec3 before = camera.eye();
    controls.hold(ViewerKey::up);
    controls.hold(ViewerKey::right);
    controls.move(0.1f, start);
    EXPECT_GT(camera.eye().y, before.y);
    EXPECT_GT(dot(camera.eye() - before, right), 0.0f);
    EXPECT_NEAR(length(camera.eye() - start.target), d, 1e-4f * d);
    // Screenshot and quit keys are remembered, not settings.
    const ViewerSettings settings_before = s;
    controls.key(ViewerKey::screenshot, start);
    EXPECT_TRUE(controls.take_screenshot());
    EXPECT_FALSE(controls.take_screenshot());
    EXPECT_FALSE(controls.quit());
    controls.key(ViewerKey::quit, start);
    EXPECT_TRUE(controls.quit());
    EXPECT_EQ(s.tess, settings_before.tess);
    controls.key(ViewerKey::tess_down, start);  // the others are settings keys
    EXPECT_EQ(s.tess, settings_before.tess - 1);
}

TEST(ViewerCli, MalformedScriptsAreOneLineErrorsBeforeAnyWindow) {
    // No DISPLAY: had the window been opened first, the error would be GLFW's.
    const std::string no_display = "env -u DISPLAY -u WAYLAND_DISPLAY";
    const std::string bad =
        write_file("bad_script.txt", "0 orbit 1 1\n# fine so far\n3 set cull.occlusion sometimes\n");
    expect_one_line_error(run("view teapot --script " + bad, no_display),
                          bad + ":3: set cull.occlusion: expected on or off");
    const std::string order = write_file("order_script.txt", "2 quit\n1 quit\n");
    expect_one_line_error(run("view teapot --script " + order, no_display), order + ":2: frame 1 comes after frame 2");
    const std::string shot = write_file("shot_script.txt", "0 screenshot /nonexistent/dir/a.png\n");
    expect_one_line_error(run("view teapot --script " + shot, no_display),
                          shot + ":1: screenshot: cannot write '/nonexistent/dir/a.png'");
    expect_one_line_error(run("view teapot --script " + scratch_dir() + "/missing.txt", no_display),
                          "--script: cannot read '" + scratch_dir() + "/missing.txt'");
    expect_one_line_error(run("view teapot --script " + scratch_dir(), no_display), "--script: cannot read");
}

TEST(ViewerCli, ScriptedCameraMoveToggleAndPanelShowInTheScreenshots) {
    ASSERT_EQ(std::system("command -v xvfb-run >/dev/null 2>&1"), 0)
        << "xvfb-run is missing: scripts/install-deps.sh installs xvfb";
    const std::string d = scratch_dir() + "/viewer";
    std::filesystem::remove_all(d);
    std::filesystem::create_directories(d);
    // BigGuy is closed: back-patch culling runs, and from the second camera (turned 90 degrees and
    // raised, as cull.png) its culled back shows magenta. Paused, so only the script changes the
    // picture.
    const std::string script =
        write_file("viewer_script.txt",
                   "0 set panel off\n"
                   "0 key space\n"
                   "2 screenshot " +
                       d +
                       "/still0.png\n"
                       "3 screenshot " +
                       d +
                       "/still1.png\n"
                       "3 key p\n"  // the screenshot key: DIR/view_0000.png
                       "4 orbit 200 0\n"
                       "4 screenshot " +
                       d +
                       "/orbited.png\n"
                       "5 set view status-second\n"
                       "6 screenshot " +
                       d +
                       "/status_on.png\n"
                       "7 set cull.backpatch off\n"
                       "8 screenshot " +
                       d +
                       "/status_off.png\n"
                       "9 key 2\n"
                       "10 screenshot " +
                       d +
                       "/status_again.png\n"
                       "11 key h\n"  // ImGui sizes a new window on its first frame, draws it on the next
                       "12 screenshot " +
                       d +
                       "/panel.png\n"
                       "13 set panel off\n"
                       "13 set view colour\n"
                       "14 screenshot " +
                       d +
                       "/plain.png\n"
                       "15 set displace on\n"  // BigGuy has no map: the procedural one
                       "15 set displace.scale 0.05\n"
                       "15 set objects bvh\n"  // rebuilds the scene with an object level
                       "16 screenshot " +
                       d +
                       "/displaced.png\n"
                       "16 quit\n");
    const CliRun r = run_under_xvfb("view " + model("bigguy.obj") + " --size 640x300 --tess 2 --script " + script +
                                    " --screenshot-dir " + d + "/keyed");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("screenshot " + d + "/panel.png (frame 12)"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("frame 17:"), std::string::npos) << "quit did not stop the viewer\n" << r.out;
    EXPECT_NE(r.out.find("screenshot " + d + "/keyed/view_0000.png (frame 3)"), std::string::npos) << r.out;
    const Rgb still0 = load_rgb(d + "/still0.png"), still1 = load_rgb(d + "/still1.png"),
              orbited = load_rgb(d + "/orbited.png"), on = load_rgb(d + "/status_on.png"),
              off = load_rgb(d + "/status_off.png"), again = load_rgb(d + "/status_again.png"),
              panel = load_rgb(d + "/panel.png"), plain = load_rgb(d + "/plain.png"),
              displaced = load_rgb(d + "/displaced.png");
    for (const Rgb* image : {&still0, &still1, &orbited, &on, &off, &again, &panel, &plain, &displaced}) {
        ASSERT_EQ(image->width, 640);
        ASSERT_EQ(image->height, 300);
    }
    const std::size_t pixels = 640 * 300;
    // Paused and unmoved, the picture stays (statuses settle, the image does not change); the
    // orbit (50 degrees) changes a large part of it.
    EXPECT_LT(differing(still0, still1, 0, 640), pixels / 200);
    const Rgb keyed = load_rgb(d + "/keyed/view_0000.png");
    ASSERT_EQ(keyed.width, 640);
    ASSERT_EQ(keyed.height, 300);
    EXPECT_EQ(differing(still1, keyed, 0, 640), 0u);  // the same frame
    EXPECT_GT(differing(still1, orbited, 0, 640), pixels / 20);
    // Status colouring from the second camera: the back-patch test's magenta is there when the
    // test runs, gone when it is off (occlusion then culls the back: red), back with its key.
    EXPECT_GT(count(on, is_magenta), 200u);
    EXPECT_EQ(count(off, is_magenta), 0u);
    EXPECT_GT(count(off, is_red), 200u);
    EXPECT_GT(count(again, is_magenta), 200u);
    EXPECT_EQ(count(still1, is_red) + count(orbited, is_red), 0u) << "the colour view shows no statuses";
    // The panel (key h, 420 pixels wide) at the top left: most of its area changes, the right
    // edge does not.
    EXPECT_GT(differing(again, panel, 0, 320), 320u * 300 / 4);
    EXPECT_LT(differing(again, panel, 560, 640), 80u * 300 / 50);
    // Displacement turned on through `set` (and an object level with it: the scene is rebuilt)
    // moves the surface: the picture changes although the camera and the animation stand still.
    EXPECT_GT(differing(plain, displaced, 0, 640), pixels / 100);
    EXPECT_NE(r.out.find("objects (bvh)"), std::string::npos) << r.out;
}

namespace {

// Frame lines of a scripted run: frame number -> (pass 1 + pass 2 submitted, draw mode name).
struct SubmittedLine {
    long submitted = -1;
    std::string draw;
};
std::vector<SubmittedLine> submitted_lines(const std::string& out) {
    std::vector<SubmittedLine> lines;
    std::size_t at = 0;
    while ((at = out.find("frame ", at)) != std::string::npos) {
        const std::size_t end = out.find('\n', at);
        const std::string line = out.substr(at, end == std::string::npos ? std::string::npos : end - at);
        at = end == std::string::npos ? out.size() : end;
        int frame = -1;
        long p1 = 0, p2 = 0;
        char mode[16] = {};
        const std::size_t sub = line.find("submitted ");
        if (std::sscanf(line.c_str(), "frame %d:", &frame) != 1 || sub == std::string::npos) continue;
        if (std::sscanf(line.c_str() + sub, "submitted %ld + %ld (%15[a-z])", &p1, &p2, mode) != 3) continue;
        if (frame != static_cast<int>(lines.size())) continue;
        lines.push_back({p1 + p2, mode});
    }
    return lines;
}

}  // namespace

// The draw mode and the compaction switched live by a script's `set` (the panel's controls set the
// same settings): each frame reports its mode and submitted patches (indirect: only the drawn;
// flags: every patch of the spans drawn, in both passes), and the picture does not change.
TEST(ViewerCli, ScriptedDrawAndCompactionSwitchesKeepThePicture) {
    ASSERT_EQ(std::system("command -v xvfb-run >/dev/null 2>&1"), 0)
        << "xvfb-run is missing: scripts/install-deps.sh installs xvfb";
    const std::string d = scratch_dir() + "/viewer_draw";
    std::filesystem::remove_all(d);
    std::filesystem::create_directories(d);
    const std::string script = write_file("viewer_draw_script.txt",
                                          "0 set panel off\n"
                                          "0 key space\n"
                                          "2 screenshot " +
                                              d +
                                              "/indirect.png\n"
                                              "3 set draw flags\n"
                                              "4 screenshot " +
                                              d +
                                              "/flags.png\n"
                                              "5 set draw indirect\n"
                                              "5 set compact append\n"
                                              "6 screenshot " +
                                              d +
                                              "/append.png\n"
                                              "6 quit\n");
    const CliRun r = run_under_xvfb("view " + model("bigguy.obj") + " --size 320x200 --tess 2 --script " + script);
    ASSERT_EQ(r.status, 0) << r.err;
    const std::vector<SubmittedLine> lines = submitted_lines(r.out);
    ASSERT_EQ(lines.size(), 7u) << r.out;
    for (int f : {0, 1, 2, 5, 6}) EXPECT_EQ(lines[static_cast<std::size_t>(f)].draw, "indirect") << r.out;
    for (int f : {3, 4}) EXPECT_EQ(lines[static_cast<std::size_t>(f)].draw, "flags") << r.out;
    // Flags issue every patch in pass 1 and again in pass 2; indirect only the drawn ones.
    EXPECT_GT(lines[4].submitted, 2 * lines[2].submitted) << r.out;
    EXPECT_GT(lines[2].submitted, 0) << r.out;
    const Rgb indirect = load_rgb(d + "/indirect.png"), flags = load_rgb(d + "/flags.png"),
              append = load_rgb(d + "/append.png");
    for (const Rgb* image : {&indirect, &flags, &append}) {
        ASSERT_EQ(image->width, 320);
        ASSERT_EQ(image->height, 200);
    }
    // The same patches are tessellated: the same picture (paused, unmoved), up to depth ties.
    EXPECT_LT(differing(indirect, flags, 0, 320), 320u * 200 / 200);
    EXPECT_LT(differing(indirect, append, 0, 320), 320u * 200 / 200);
}
