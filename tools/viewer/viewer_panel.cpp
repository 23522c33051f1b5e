// The viewer's ImGui panel (viewer_panel.h).
#include "viewer_panel.h"

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <cstdio>
#include <iterator>

#include "patchcull/core/error.h"
#include "patchcull/gl/gl_backpatch_passes.h"

namespace patchcull::cli {
namespace {

bool combo(const char* label, int& index, const char* const* items, int count) {
    return ImGui::Combo(label, &index, items, count);
}

// A row of the counts table: name, patches, share of all patches.
void count_row(const char* name, std::size_t count, std::size_t total) {
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    ImGui::TextUnformatted(name);
    ImGui::TableNextColumn();
    ImGui::Text("%zu", count);
    ImGui::TableNextColumn();
    ImGui::Text("%5.1f%%", total ? 100.0 * double(count) / double(total) : 0.0);
}

void stats_section(const PanelInfo& info) {
    ImGui::Text("frame %d, %.1f fps; %s", info.frame, info.fps, info.renderer.c_str());
    if (!info.stats) return;
    const gl::FrameStats& s = *info.stats;
    ImGui::Text("patches %zu: drawn %zu (pass 1) + %zu (pass 2)", s.patches, s.pass1_drawn, s.pass2_drawn);
    // Issued to the vertex shader and TCS: flags, every patch of the spans drawn; indirect, the listed.
    ImGui::Text("submitted %zu (pass 1) + %zu (pass 2), %s draw", s.pass1_submitted, s.pass2_submitted,
                gl::draw_mode_name(s.draw));
    if (ImGui::BeginTable("counts", 3, ImGuiTableFlags_SizingFixedFit)) {
        count_row("frustum", s.frustum_culled, s.patches);
        count_row("back-patch", s.backpatch_culled, s.patches);
        count_row("occlusion", s.occlusion_culled, s.patches);
        count_row(" of them displaced", s.displaced_occlusion_culled, s.patches);
        count_row("object level", s.object_culled, s.patches);
        count_row("culled in all", s.frustum_culled + s.backpatch_culled + s.occlusion_culled + s.object_culled,
                  s.patches);
        count_row("visible", s.visible, s.patches);
        count_row(" newly visible", s.newly_visible, s.patches);
        ImGui::EndTable();
    }
    ImGui::Text("ms: pass1 %.2f  hiz %.2f  cull %.2f", s.pass1_ms, s.hiz_ms, s.cull_ms);
    ImGui::Text("    pass2 %.2f  total %.2f (%s)", s.pass2_ms, s.total_ms, gl::timing_method_name(s.timing));
    if (info.object_level && info.objects) {
        const ObjectCullStats& o = *info.objects;
        ImGui::Text("objects: %zu of %zu culled (frustum %zu, back-face %zu, detail %zu)",
                    o.frustum_culled + o.backface_culled + o.detail_culled, o.total, o.frustum_culled,
                    o.backface_culled, o.detail_culled);
    }
}

void culling_section(ViewerSettings& s, const PanelInfo& info) {
    ImGui::Checkbox("frustum [1]", &s.frustum);
    ImGui::SameLine();
    ImGui::Checkbox("back-patch [2]", &s.backpatch);
    ImGui::SameLine();
    ImGui::Checkbox("occlusion [3]", &s.occlusion);
    if (s.backpatch && !info.one_sided)
        ImGui::TextColored(ImVec4(1, 0.5f, 0.3f, 1), "open surface: back-patch culling is not conservative here");
    ImGui::Checkbox("auto: cull only where it pays [4]", &s.cull_auto);
    const std::vector<gl::BackpatchMethod> ids = gl::gpu_backpatch_methods();
    std::vector<const char*> methods;
    int method = 0;
    for (std::size_t i = 0; i < ids.size(); ++i) {
        methods.push_back(gl::backpatch_method_name(ids[i]));
        if (ids[i] == s.backpatch_method) method = static_cast<int>(i);
    }
    if (combo("back-patch test [b]", method, methods.data(), static_cast<int>(methods.size())))
        s.backpatch_method = ids[static_cast<std::size_t>(method)];
    ImGui::Checkbox("aggressive: no second pass [g]", &s.aggressive);
    if (s.displace) {
        static const char* const bounds[] = {"oobb", "caf"};
        static const char* const cones[] = {"full", "acon", "con"};
        int bound = static_cast<int>(s.bound), cone = static_cast<int>(s.cone);
        if (combo("displaced bound", bound, bounds, 2)) s.bound = static_cast<DisplacedBoundKind>(bound);
        if (combo("normal cone", cone, cones, 3)) s.cone = static_cast<NormalConeKind>(cone);
    }
    static const char* const objects[] = {"none", "frustum", "bvh", "bvh+backface"};
    int object = 0;
    for (int i = 0; i < 4; ++i)
        if (s.objects == objects[i]) object = i;
    if (combo("object level", object, objects, 4)) s.objects = objects[object];
    // The draw: indirect (the survivors compacted, only they issued) or flags (every patch issued,
    // the TCS drops the culled); the same image either way.
    static const char* const draws[] = {"flags", "indirect"};
    int draw = s.draw == gl::DrawMode::indirect ? 1 : 0;
    if (combo("draw", draw, draws, 2)) s.draw = draw == 1 ? gl::DrawMode::indirect : gl::DrawMode::flags;
    if (s.draw == gl::DrawMode::indirect) {
        static const char* const compactions[] = {"scan (same order)", "append (any order)",
                                                  "fused (append in the chain's end)"};
        static const gl::CompactMethod methods[] = {gl::CompactMethod::prefix_scan, gl::CompactMethod::atomic_append,
                                                    gl::CompactMethod::fused_append};
        int compact = 0;
        for (int i = 0; i < 3; ++i)
            if (s.compact == methods[i]) compact = i;
        if (combo("compaction", compact, compactions, 3)) s.compact = methods[compact];
    }
}

void scene_section(ViewerSettings& s) {
    ImGui::SliderInt("tess level [+/-]", &s.tess, 1, 64);
    ImGui::Checkbox("adaptive (by distance)", &s.adaptive_tess);
    ImGui::Checkbox("displacement [x]", &s.displace);
    if (s.displace) {
        // Applied when the slider is let go: a new scale rebuilds the displaced scene.
        static float pending = 0;
        static bool dragging = false;
        if (!dragging) pending = s.displace_scale;
        ImGui::SliderFloat("scale", &pending, 0.001f, 0.1f, "%.3f", ImGuiSliderFlags_Logarithmic);
        dragging = ImGui::IsItemActive();
        if (!dragging) s.displace_scale = pending;
    }
}

PanelActions view_section(ViewerSettings& s) {
    PanelActions actions;
    static const char* const views[] = {"colour", "status (this camera)", "status (second camera)"};
    int view = static_cast<int>(s.view);
    if (combo("view [v]", view, views, 3)) s.view = static_cast<ViewerView>(view);
    if (s.view != ViewerView::colour)
        ImGui::TextWrapped(
            "green visible, yellow newly visible, blue frustum, magenta back-patch, red occlusion, "
            "cyan object level, grey occluders");
    static const char* const cameras[] = {"path", "orbit", "fly"};
    int camera = static_cast<int>(s.camera);
    if (combo("camera [c]", camera, cameras, 3)) s.camera = static_cast<ViewerCameraMode>(camera);
    ImGui::Checkbox("pause [space]", &s.paused);
    ImGui::SameLine();
    actions.reset_camera = ImGui::Button("reset camera [r]");
    ImGui::SameLine();
    actions.screenshot = ImGui::Button("screenshot [p]");
    return actions;
}

}  // namespace

ViewerPanel::ViewerPanel(GLFWwindow* window) {
    if (!window) throw Error("view: the panel needs a window context");
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini in the working directory
    ImGui::StyleColorsDark();
    ImGui_ImplGlfw_InitForOpenGL(window, true);
    ImGui_ImplOpenGL3_Init("#version 450");
}

ViewerPanel::~ViewerPanel() {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
}

bool ViewerPanel::wants_mouse() const { return visible_ && ImGui::GetIO().WantCaptureMouse; }
bool ViewerPanel::wants_keyboard() const { return visible_ && ImGui::GetIO().WantCaptureKeyboard; }

PanelActions ViewerPanel::draw(ViewerSettings& settings, const PanelInfo& info) {
    visible_ = true;
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    ImGui::SetNextWindowPos(ImVec2(0, 0), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(420, 0), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSizeConstraints(ImVec2(0, 0), ImVec2(1e6f, ImGui::GetIO().DisplaySize.y));  // scrolls
    ImGui::SetNextWindowBgAlpha(0.8f);
    PanelActions actions;
    const std::string title = "patchcull view: " + info.scene_name + "###panel";
    if (ImGui::Begin(title.c_str())) {
        ImGui::PushItemWidth(150);  // widgets narrow enough for their labels beside them
        if (ImGui::CollapsingHeader("Frame", ImGuiTreeNodeFlags_DefaultOpen)) stats_section(info);
        if (ImGui::CollapsingHeader("Culling", ImGuiTreeNodeFlags_DefaultOpen)) culling_section(settings, info);
        if (ImGui::CollapsingHeader("Tessellation and displacement")) scene_section(settings);
        if (ImGui::CollapsingHeader("View and camera", ImGuiTreeNodeFlags_DefaultOpen))
            actions = view_section(settings);
        if (ImGui::CollapsingHeader("Keys and mouse"))
            ImGui::TextWrapped(
                "orbit: left-drag, wheel zoom, W/S zoom, A/D/Q/E turn; fly: right-drag look, "
                "WASD move, Q/E down/up; c camera mode (orbit, fly, path), r reset; 1 2 3 "
                "frustum / back-patch / occlusion, 4 auto, b back-patch test, g aggressive, "
                "+/- tess level, x displacement, v view, space pause, p or F12 screenshot, "
                "h hide this panel, Esc quit");
        if (!info.message.empty()) ImGui::TextWrapped("%s", info.message.c_str());
        ImGui::PopItemWidth();
    }
    ImGui::End();
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    return actions;
}

}  // namespace patchcull::cli
