// The viewer's Dear ImGui panel (`patchcull view`): the cull toggles, methods, bound and
// cone, the draw mode and compaction, tessellation, displacement, view mode and camera, edited in
// place in ViewerSettings (the same state the keys and a --script's `set` lines change), and the
// last frame's per-pass times, cull counts and rates, and patches submitted per draw pass. Uses ImGui's GLFW and OpenGL
// 3 backends on the viewer's window.
#pragma once

#include <string>

#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/objects/object_culling.h"
#include "viewer_settings.h"

struct GLFWwindow;

namespace patchcull::cli {

/// What the panel shows besides the settings.
struct PanelInfo {
    std::string scene_name;
    std::string renderer;       ///< GL_RENDERER
    bool one_sided = true;      ///< false: back-patch culling is not conservative on the scene
    bool object_level = false;  ///< the object level ran (objects below is meaningful)
    int frame = 0;
    double fps = 0;  ///< frames per wall-clock second, smoothed
    const gl::FrameStats* stats = nullptr;
    const ObjectCullStats* objects = nullptr;
    std::string message;  ///< the last screenshot written, or a warning
};

/// Buttons pressed in the panel this frame.
struct PanelActions {
    bool screenshot = false;
    bool reset_camera = false;
};

class ViewerPanel {
public:
    /// Creates the ImGui context on window (its GL 4.5 context current) with the GLFW backend's
    /// callbacks installed (they chain to callbacks installed before) and no imgui.ini file.
    explicit ViewerPanel(GLFWwindow* window);
    ~ViewerPanel();
    ViewerPanel(const ViewerPanel&) = delete;
    ViewerPanel& operator=(const ViewerPanel&) = delete;

    /// ImGui has the mouse (over the panel, or dragging a widget) or the keyboard (a text field):
    /// the viewer then leaves that input to it. False while the panel is hidden.
    bool wants_mouse() const;
    bool wants_keyboard() const;

    /// Builds and draws the panel into the current draw framebuffer (the window's back buffer).
    PanelActions draw(ViewerSettings& settings, const PanelInfo& info);
    /// Call on frames the panel is not drawn (its input state is then stale).
    void hidden() { visible_ = false; }

private:
    bool visible_ = false;
};

}  // namespace patchcull::cli
