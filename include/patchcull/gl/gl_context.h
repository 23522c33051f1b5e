// patchcull/gl/gl_context.h: the OpenGL 4.5 core context of library patchcull_gl, headless (EGL)
// or in a window (GLFW). The renderer (gl_renderer.h) and the library's other GL objects are
// created on one; the cull passes (gl_passes.h) run on any current 4.5 context, an engine's own too.
//
// Contexts: headless EGL (create_headless) or a GLFW window (create_window); the renderer is the
// same code in both.
//
// Threads and lifetime: a GlContext is current on the thread that created it; every GL object of
// patchcull_gl (renderers, passes, pipelines, posers, queries) must be created, used and destroyed
// on its context's thread while that context lives (destroy them before their context). Objects
// are move-only.
//
// Linking: patchcull_gl links libepoxy, which loads libEGL.so.1 and libOpenGL.so.0 (or libGL.so.1)
// at run time; binaries start without them and create_headless() reports their absence.
//
// Errors: factories and calls that can fail throw patchcull::Error with a one-line message
// ("EGL: no display ...", "GL: shader patch.tesc.glsl: <first log line>", "GL: error 0x0502 after
// render"). patchcull prints nothing (Mesa itself may write driver warnings to stderr).
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "patchcull/core/error.h"
#include "patchcull/core/thread_placement.h"

struct GLFWwindow;  // GLFW's window type (GlContext::glfw_window); GLFW's header is not needed here

namespace patchcull::gl {

/// What create_headless and create_window do with the threads the driver starts
/// (core/thread_placement.h; default: spread them on a software rasterizer).
using patchcull::DriverThreads;

/// An OpenGL 4.5 core context: headless (EGL) or in a window (GLFW).
class GlContext {
public:
    /// Creates a headless context and makes it current on the calling thread. Tries, in order:
    /// an EGL device (EGL_EXT_platform_device) that is not Mesa's software device (a GPU), then
    /// Mesa's surfaceless platform (EGL_MESA_platform_surfaceless: llvmpipe without a GPU), then
    /// the software EGL device. Throws patchcull::Error with a one-line message naming the last
    /// failure when none gives a GL 4.5 core context (e.g. "EGL: no display: ...").
    static GlContext create_headless(DriverThreads threads = DriverThreads::spread);

    GlContext(GlContext&&) noexcept;
    GlContext& operator=(GlContext&&) noexcept;
    GlContext(const GlContext&) = delete;
    GlContext& operator=(const GlContext&) = delete;
    ~GlContext();

    /// Opens a window of width x height pixels with an OpenGL 4.5 core context, current on the
    /// calling thread: the same renderer and cull pipeline as create_headless, shown on screen
    /// (PatchRenderer::blit_color_to_window, swap_buffers). GLFW 3 on X11, loaded at run time
    /// (libglfw.so.3: patchcull::gl does not link GLFW); without a screen, run under a virtual X
    /// server (`xvfb-run -a -s "-screen 0 1280x1024x24" ...`, llvmpipe). At most one window
    /// context at a time. Throws patchcull::Error with one line ("GLFW: ...") when libglfw.so.3 is
    /// missing, there is no X display or no 4.5 core context.
    static GlContext create_window(int width, int height, const std::string& title,
                                   DriverThreads threads = DriverThreads::spread);

    /// Makes this context current on the calling thread (needed only after another context was).
    void make_current() const;

    /// True for a create_window context.
    bool has_window() const;
    /// Window: the GLFW window, for the caller's own input handling and UI (e.g. Dear ImGui's GLFW
    /// backend; install callbacks before window_open() polls). Headless: nullptr.
    GLFWwindow* glfw_window() const;
    /// Window: processes pending events; false once the user has closed the window (or Escape).
    /// Headless: always true.
    bool window_open() const;
    /// Window: shows the back buffer. Headless: nothing.
    void swap_buffers() const;
    /// Window: writes the back buffer (what the next swap_buffers shows) as an RGBA PNG, top row
    /// first (a screenshot). Throws patchcull::Error for a headless context or an unwritable path.
    void write_window_png(const std::string& path) const;

    /// GL_RENDERER, GL_VENDOR and GL_VERSION strings.
    const std::string& renderer() const;
    const std::string& vendor() const;
    const std::string& version() const;
    /// How the display was obtained: "device" (GPU), "surfaceless", "software-device" or "window".
    const std::string& platform() const;
    /// True for a software rasterizer (llvmpipe, softpipe, swrast).
    bool is_software() const;
    /// How many driver threads this context pinned (DriverThreads::spread on a software
    /// rasterizer with two CPUs or more); 0 otherwise.
    std::size_t pinned_driver_threads() const;

    struct Impl;

private:
    explicit GlContext(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace patchcull::gl
