// The viewer's settings, `set` lines and keys (viewer_settings.h).
#include "viewer_settings.h"

#include <charconv>
#include <cmath>
#include <iterator>
#include <utility>
#include <vector>
#include "patchcull/gl/gl_backpatch_passes.h"

namespace patchcull::cli {
namespace {

// "on"/"off" -> target; the error names the setting.
std::string set_switch(bool& target, const std::string& name, const std::string& value) {
    if (value == "on") return target = true, "";
    if (value == "off") return target = false, "";
    return "set " + name + ": expected on or off, got '" + value + "'";
}

// One of choices -> its index in choices.
template <typename T>
std::string set_choice(T& target, const std::string& name, const std::string& value,
                       const std::vector<std::pair<const char*, T>>& choices) {
    std::string list;
    for (const auto& [text, v] : choices) {
        if (value == text) return target = v, "";
        if (!list.empty()) list += ", ";
        list += text;
    }
    return "set " + name + ": expected one of " + list + ", got '" + value + "'";
}

// Whole decimal text only (from_chars; no spaces, signs other than '-', or trailing characters).
template <typename T>
bool parse_whole(const std::string& text, T& out) {
    const char* end = text.data() + text.size();
    const auto [ptr, ec] = std::from_chars(text.data(), end, out);
    return !text.empty() && ec == std::errc() && ptr == end;
}

const std::vector<std::pair<const char*, ViewerKey>>& key_table() {
    static const std::vector<std::pair<const char*, ViewerKey>> table = {
        {"1", ViewerKey::toggle_frustum},
        {"2", ViewerKey::toggle_backpatch},
        {"3", ViewerKey::toggle_occlusion},
        {"4", ViewerKey::toggle_auto},
        {"b", ViewerKey::next_backpatch},
        {"g", ViewerKey::toggle_aggressive},
        {"v", ViewerKey::next_view},
        {"c", ViewerKey::next_camera},
        {"r", ViewerKey::reset_camera},
        {"h", ViewerKey::toggle_panel},
        {"x", ViewerKey::toggle_displace},
        {"plus", ViewerKey::tess_up},
        {"minus", ViewerKey::tess_down},
        {"space", ViewerKey::pause},
        {"p", ViewerKey::screenshot},
        {"f12", ViewerKey::screenshot},
        {"escape", ViewerKey::quit},
        {"w", ViewerKey::forward},
        {"s", ViewerKey::back},
        {"a", ViewerKey::left},
        {"d", ViewerKey::right},
        {"e", ViewerKey::up},
        {"q", ViewerKey::down},
    };
    return table;
}

}  // namespace

std::string apply_setting(ViewerSettings& settings, const std::string& name, const std::string& value) {
    if (name == "cull.frustum") return set_switch(settings.frustum, name, value);
    if (name == "cull.backpatch") return set_switch(settings.backpatch, name, value);
    if (name == "cull.occlusion") return set_switch(settings.occlusion, name, value);
    if (name == "cull.auto") return set_switch(settings.cull_auto, name, value);
    if (name == "aggressive") return set_switch(settings.aggressive, name, value);
    if (name == "tess.adaptive") return set_switch(settings.adaptive_tess, name, value);
    if (name == "displace") return set_switch(settings.displace, name, value);
    if (name == "pause") return set_switch(settings.paused, name, value);
    if (name == "panel") return set_switch(settings.panel, name, value);
    if (name == "backpatch") {
        std::vector<std::pair<const char*, gl::BackpatchMethod>> methods;
        for (gl::BackpatchMethod m : gl::gpu_backpatch_methods()) methods.emplace_back(gl::backpatch_method_name(m), m);
        return set_choice(settings.backpatch_method, name, value, methods);
    }
    if (name == "bound")
        return set_choice(settings.bound, name, value,
                          {{"caf", DisplacedBoundKind::caf}, {"oobb", DisplacedBoundKind::oobb}});
    if (name == "cone")
        return set_choice(
            settings.cone, name, value,
            {{"full", NormalConeKind::full}, {"acon", NormalConeKind::acon}, {"con", NormalConeKind::con}});
    if (name == "objects")
        return set_choice(settings.objects, name, value,
                          {{"none", std::string("none")},
                           {"frustum", std::string("frustum")},
                           {"bvh", std::string("bvh")},
                           {"bvh+backface", std::string("bvh+backface")}});
    if (name == "draw")
        return set_choice(settings.draw, name, value,
                          {{"flags", gl::DrawMode::flags}, {"indirect", gl::DrawMode::indirect}});
    if (name == "compact")
        return set_choice(settings.compact, name, value,
                          {{"scan", gl::CompactMethod::prefix_scan},
                           {"append", gl::CompactMethod::atomic_append},
                           {"fused", gl::CompactMethod::fused_append}});
    if (name == "view")
        return set_choice(settings.view, name, value,
                          {{"colour", ViewerView::colour},
                           {"status", ViewerView::status},
                           {"status-second", ViewerView::status_second}});
    if (name == "camera")
        return set_choice(
            settings.camera, name, value,
            {{"path", ViewerCameraMode::path}, {"orbit", ViewerCameraMode::orbit}, {"fly", ViewerCameraMode::fly}});
    if (name == "tess") {
        int level = 0;
        if (!parse_whole(value, level) || level < 1 || level > 64)
            return "set tess: expected an integer in 1..64, got '" + value + "'";
        settings.tess = level;
        return "";
    }
    if (name == "displace.scale") {
        float scale = 0;
        if (!parse_whole(value, scale) || !std::isfinite(scale) || !(scale > 0) || scale > 1)
            return "set displace.scale: expected a number in (0, 1], got '" + value + "'";
        settings.displace_scale = scale;
        return "";
    }
    return "unknown setting '" + name +
           "' (cull.frustum, cull.backpatch, cull.occlusion, cull.auto, backpatch, bound, cone, aggressive, tess, "
           "tess.adaptive, displace, displace.scale, objects, draw, compact, view, camera, pause, panel)";
}

bool parse_viewer_key(const std::string& name, ViewerKey& key) {
    for (const auto& [text, k] : key_table())
        if (name == text) return key = k, true;
    return false;
}

std::string viewer_key_names() {
    std::string list;
    for (const auto& entry : key_table()) {
        if (!list.empty()) list += ' ';
        list += entry.first;
    }
    return list;
}

bool is_movement_key(ViewerKey key) {
    return key == ViewerKey::forward || key == ViewerKey::back || key == ViewerKey::left || key == ViewerKey::right ||
           key == ViewerKey::up || key == ViewerKey::down;
}

bool apply_settings_key(ViewerSettings& s, ViewerKey key) {
    switch (key) {
        case ViewerKey::toggle_frustum:
            s.frustum = !s.frustum;
            return true;
        case ViewerKey::toggle_backpatch:
            s.backpatch = !s.backpatch;
            return true;
        case ViewerKey::toggle_occlusion:
            s.occlusion = !s.occlusion;
            return true;
        case ViewerKey::toggle_auto:
            s.cull_auto = !s.cull_auto;
            return true;
        case ViewerKey::next_backpatch: {  // the next of gl::gpu_backpatch_methods, round
            const std::vector<gl::BackpatchMethod> ids = gl::gpu_backpatch_methods();
            const std::size_t n = ids.size();
            std::size_t at = 0;
            while (at < n && ids[at] != s.backpatch_method) ++at;
            s.backpatch_method = ids[(at + 1) % n];
            return true;
        }
        case ViewerKey::toggle_aggressive:
            s.aggressive = !s.aggressive;
            return true;
        case ViewerKey::next_view:
            s.view = s.view == ViewerView::colour   ? ViewerView::status
                     : s.view == ViewerView::status ? ViewerView::status_second
                                                    : ViewerView::colour;
            return true;
        case ViewerKey::next_camera:
            s.camera = s.camera == ViewerCameraMode::orbit ? ViewerCameraMode::fly
                       : s.camera == ViewerCameraMode::fly ? ViewerCameraMode::path
                                                           : ViewerCameraMode::orbit;
            return true;
        case ViewerKey::toggle_panel:
            s.panel = !s.panel;
            return true;
        case ViewerKey::toggle_displace:
            s.displace = !s.displace;
            return true;
        case ViewerKey::tess_up:
            s.tess = s.tess < 64 ? s.tess + 1 : 64;
            return true;
        case ViewerKey::tess_down:
            s.tess = s.tess > 1 ? s.tess - 1 : 1;
            return true;
        case ViewerKey::pause:
            s.paused = !s.paused;
            return true;
        default:
            return false;
    }
}

gl::CullMode settings_cull_mode(const ViewerSettings& s) {
    const std::uint32_t bits = (s.frustum ? gl::kCullFrustum : 0u) | (s.backpatch ? gl::kCullBackPatch : 0u) |
                               (s.occlusion ? gl::kCullOcclusion : 0u);
    return static_cast<gl::CullMode>(bits);
}

void set_cull_toggles(ViewerSettings& s, gl::CullMode mode) {
    const std::uint32_t bits = static_cast<std::uint32_t>(mode);
    s.frustum = (bits & gl::kCullFrustum) != 0;
    s.backpatch = (bits & gl::kCullBackPatch) != 0;
    s.occlusion = (bits & gl::kCullOcclusion) != 0;
}

const char* viewer_view_name(ViewerView view) {
    return view == ViewerView::colour ? "colour" : view == ViewerView::status ? "status" : "status-second";
}

const char* viewer_camera_mode_name(ViewerCameraMode mode) {
    return mode == ViewerCameraMode::path ? "path" : mode == ViewerCameraMode::orbit ? "orbit" : "fly";
}

}  // namespace patchcull::cli
