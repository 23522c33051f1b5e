// OpenGL contexts (patchcull/gl/gl_context.h: GlContext): headless EGL, or a GLFW window.
//
// GLFW is loaded at run time (dlopen libglfw.so.3) by create_window, so patchcull::gl links no
// GLFW: an engine with its own SDL, EGL or GLFW context does not get it. A program that links
// GLFW itself (the CLI's viewer, for Dear ImGui's backend) shares the same loaded library.
//
// libepoxy dispatches EGL and GL; it loads libEGL.so.1 and libOpenGL.so.0 / libGL.so.1 at run
// time, and aborts the process when they are missing, so create_headless() dlopen()s them first
// and throws a one-line patchcull::Error instead. EGL extension entry points come from
// eglGetProcAddress: with libepoxy, calling eglGetPlatformDisplay(EXT) through its dispatch before
// any display exists aborts (Mesa 22.3.6 with Debian 12's libepoxy).
#include <dlfcn.h>
#include <epoxy/egl.h>
#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE  // GL declarations come from libepoxy
#include <GLFW/glfw3.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <map>
#include <mutex>
#include <string>
#include <type_traits>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/core/thread_placement.h"
#include "patchcull/gl/gl_context.h"
#include "png_file.h"

namespace patchcull::gl {

// The GLFW functions create_window's contexts use, from libglfw.so.3 (GLFW's declarations give
// their types).
struct GlfwApi {
    decltype(&::glfwInit) init = nullptr;
    decltype(&::glfwTerminate) terminate = nullptr;
    decltype(&::glfwSetErrorCallback) set_error_callback = nullptr;
    decltype(&::glfwWindowHint) window_hint = nullptr;
    decltype(&::glfwCreateWindow) create_window = nullptr;
    decltype(&::glfwDestroyWindow) destroy_window = nullptr;
    decltype(&::glfwMakeContextCurrent) make_context_current = nullptr;
    decltype(&::glfwSwapInterval) swap_interval = nullptr;
    decltype(&::glfwPollEvents) poll_events = nullptr;
    decltype(&::glfwGetKey) get_key = nullptr;
    decltype(&::glfwSetWindowShouldClose) set_window_should_close = nullptr;
    decltype(&::glfwWindowShouldClose) window_should_close = nullptr;
    decltype(&::glfwSwapBuffers) swap_buffers = nullptr;
    decltype(&::glfwGetFramebufferSize) get_framebuffer_size = nullptr;
};

struct GlContext::Impl {
    EGLDisplay display = EGL_NO_DISPLAY;
    EGLContext context = EGL_NO_CONTEXT;
    GLFWwindow* window = nullptr;   // a window context instead of EGL
    const GlfwApi* glfw = nullptr;  // the loaded GLFW of a window context
    std::string renderer, vendor, version, platform;
    bool software = false;
    std::size_t pinned_driver_threads = 0;
    ~Impl();
};

namespace {

// EGL displays are process-wide and eglTerminate ends every context on one: count our users.
std::mutex g_display_mutex;
std::map<EGLDisplay, int> g_display_users;

void acquire_display(EGLDisplay d) {
    std::lock_guard<std::mutex> lock(g_display_mutex);
    ++g_display_users[d];
}
void release_display(EGLDisplay d) {
    std::lock_guard<std::mutex> lock(g_display_mutex);
    if (--g_display_users[d] == 0) {
        g_display_users.erase(d);
        eglTerminate(d);
    }
}

std::string hex(unsigned value) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%04X", value);
    return buf;
}

bool has_extension(const char* list, const char* name) {
    if (!list) return false;
    const std::string s = std::string(" ") + list + " ";
    return s.find(std::string(" ") + name + " ") != std::string::npos;
}

void require_library(const char* const* names, const char* what) {
    for (const char* const* n = names; *n; ++n)
        if (dlopen(*n, RTLD_LAZY | RTLD_GLOBAL)) return;
    throw Error(std::string("EGL: no display: cannot load ") + what + " (" + names[0] +
                "; install libegl1 libopengl0 and Mesa's libegl-mesa0 libgl1-mesa-dri)");
}

struct Candidate {
    EGLenum platform;
    void* native;
    std::string name;   // "device", "surfaceless", "software-device"
    std::string label;  // for messages
};

// Tries to make a GL 4.5 core context on candidate c; returns an empty string on success (and
// fills impl), else the reason.
std::string try_candidate(const Candidate& c, PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display,
                          GlContext::Impl& impl) {
    EGLDisplay display = get_platform_display(c.platform, c.native, nullptr);
    if (display == EGL_NO_DISPLAY) return c.label + ": eglGetPlatformDisplayEXT failed (" + hex(eglGetError()) + ")";
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor)) return c.label + ": eglInitialize failed (" + hex(eglGetError()) + ")";
    acquire_display(display);
    auto fail = [&](const std::string& why) {
        release_display(display);
        return c.label + ": " + why + " (" + hex(eglGetError()) + ")";
    };
    const char* exts = eglQueryString(display, EGL_EXTENSIONS);
    if (!has_extension(exts, "EGL_KHR_surfaceless_context")) return fail("no EGL_KHR_surfaceless_context");
    if (!eglBindAPI(EGL_OPENGL_API)) return fail("eglBindAPI(EGL_OPENGL_API) failed");
    EGLConfig config = EGL_NO_CONFIG_KHR;
    if (!has_extension(exts, "EGL_KHR_no_config_context") && !has_extension(exts, "EGL_MESA_configless_context")) {
        const EGLint attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};
        EGLint n = 0;
        if (!eglChooseConfig(display, attribs, &config, 1, &n) || n < 1) return fail("no OpenGL EGLConfig");
    }
    const EGLint ctx_attribs[] = {
        EGL_CONTEXT_MAJOR_VERSION,           4,       EGL_CONTEXT_MINOR_VERSION, 5, EGL_CONTEXT_OPENGL_PROFILE_MASK,
        EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, ctx_attribs);
    if (context == EGL_NO_CONTEXT) return fail("no OpenGL 4.5 core context");
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
        eglDestroyContext(display, context);
        return fail("eglMakeCurrent failed");
    }
    if (epoxy_gl_version() < 45) {
        eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(display, context);
        return fail("context is not OpenGL 4.5");
    }
    auto str = [](GLenum e) {
        const GLubyte* s = glGetString(e);
        return s ? std::string(reinterpret_cast<const char*>(s)) : std::string();
    };
    impl.display = display;
    impl.context = context;
    impl.renderer = str(GL_RENDERER);
    impl.vendor = str(GL_VENDOR);
    impl.version = str(GL_VERSION);
    impl.platform = c.name;
    impl.software = impl.renderer.find("llvmpipe") != std::string::npos ||
                    impl.renderer.find("softpipe") != std::string::npos ||
                    impl.renderer.find("swrast") != std::string::npos;
    return {};
}

// Pins the threads started since `before` when asked to and the context is a software one.
void place_driver_threads(GlContext::Impl& impl, DriverThreads threads, const std::vector<int>& before) {
    if (threads != DriverThreads::spread || !impl.software) return;
    impl.pinned_driver_threads = spread_threads(threads_started(before, process_thread_ids()));
}

}  // namespace

// The last GLFW error, for one-line messages (GLFW reports through a callback).
std::string g_glfw_error;

// Loads GLFW once; throws a one-line Error when the library or one of its functions is missing.
const GlfwApi& glfw_api() {
    static const GlfwApi api = [] {
        void* library = nullptr;
        for (const char* name : {"libglfw.so.3", "libglfw.so"})
            if (!library) library = dlopen(name, RTLD_NOW | RTLD_GLOBAL);
        if (!library) throw Error("GLFW: cannot load libglfw.so.3 (Debian: libglfw3) for a window context");
        GlfwApi a;
        auto load = [library](auto& function, const char* name) {
            function = reinterpret_cast<std::remove_reference_t<decltype(function)>>(dlsym(library, name));
            if (!function) throw Error(std::string("GLFW: libglfw.so.3 has no ") + name);
        };
        load(a.init, "glfwInit");
        load(a.terminate, "glfwTerminate");
        load(a.set_error_callback, "glfwSetErrorCallback");
        load(a.window_hint, "glfwWindowHint");
        load(a.create_window, "glfwCreateWindow");
        load(a.destroy_window, "glfwDestroyWindow");
        load(a.make_context_current, "glfwMakeContextCurrent");
        load(a.swap_interval, "glfwSwapInterval");
        load(a.poll_events, "glfwPollEvents");
        load(a.get_key, "glfwGetKey");
        load(a.set_window_should_close, "glfwSetWindowShouldClose");
        load(a.window_should_close, "glfwWindowShouldClose");
        load(a.swap_buffers, "glfwSwapBuffers");
        load(a.get_framebuffer_size, "glfwGetFramebufferSize");
        return a;
    }();
    return api;
}

void remember_glfw_error(int code, const char* description) {
    g_glfw_error = description ? description : "error " + std::to_string(code);
}

GlContext::Impl::~Impl() {
    if (window) {
        glfw->destroy_window(window);
        glfw->terminate();  // one window context at a time (create_window)
        return;
    }
    if (context != EGL_NO_CONTEXT) {
        if (eglGetCurrentContext() == context) eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(display, context);
    }
    if (display != EGL_NO_DISPLAY) release_display(display);
}

GlContext GlContext::create_headless(DriverThreads threads) {
    const std::vector<int> threads_before = process_thread_ids();
    static const char* const egl_names[] = {"libEGL.so.1", "libEGL.so", nullptr};
    static const char* const gl_names[] = {"libOpenGL.so.0", "libGL.so.1", "libOpenGL.so", "libGL.so", nullptr};
    require_library(egl_names, "the EGL library");
    require_library(gl_names, "the OpenGL library");

    const char* client_exts = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    auto get_platform_display =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!client_exts || !get_platform_display || !has_extension(client_exts, "EGL_EXT_platform_base"))
        throw Error("EGL: no display: EGL_EXT_platform_base is missing (no EGL vendor library installed?)");

    std::vector<Candidate> hardware, software;
    if (has_extension(client_exts, "EGL_EXT_platform_device")) {
        auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
        auto query_string =
            reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
        EGLint n = 0;
        if (query_devices && query_string && query_devices(0, nullptr, &n) && n > 0) {
            std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(n));
            query_devices(n, devices.data(), &n);
            for (EGLint i = 0; i < n; ++i) {
                const char* dev_exts = query_string(devices[i], EGL_EXTENSIONS);
                const bool soft = has_extension(dev_exts, "EGL_MESA_device_software");
                Candidate c{EGL_PLATFORM_DEVICE_EXT, devices[i], soft ? "software-device" : "device",
                            std::string(soft ? "software device " : "device ") + std::to_string(i)};
                (soft ? software : hardware).push_back(c);
            }
        }
    }
    std::vector<Candidate> candidates = hardware;
    if (has_extension(client_exts, "EGL_MESA_platform_surfaceless"))
        candidates.push_back({EGL_PLATFORM_SURFACELESS_MESA, nullptr, "surfaceless", "surfaceless"});
    candidates.insert(candidates.end(), software.begin(), software.end());
    if (candidates.empty())
        throw Error("EGL: no display: neither EGL_EXT_platform_device nor EGL_MESA_platform_surfaceless is available");

    std::string reasons;
    for (const Candidate& c : candidates) {
        auto impl = std::make_unique<Impl>();
        const std::string why = try_candidate(c, get_platform_display, *impl);
        if (why.empty()) {
            place_driver_threads(*impl, threads, threads_before);
            return GlContext(std::move(impl));
        }
        reasons += (reasons.empty() ? "" : "; ") + why;
    }
    throw Error("EGL: no OpenGL 4.5 core context: " + reasons);
}

GlContext GlContext::create_window(int width, int height, const std::string& title, DriverThreads threads) {
    if (width < 1 || height < 1) throw Error("GLFW: window size must be positive");
    const std::vector<int> threads_before = process_thread_ids();
    const GlfwApi& glfw = glfw_api();
    glfw.set_error_callback(remember_glfw_error);
    g_glfw_error.clear();
    if (!glfw.init()) throw Error("GLFW: cannot start: " + g_glfw_error + " (no X display? run under xvfb-run)");
    glfw.window_hint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfw.window_hint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfw.window_hint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfw.window_hint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfw.window_hint(GLFW_RESIZABLE, GLFW_FALSE);  // the renderer's framebuffer has a fixed size
    GLFWwindow* window = glfw.create_window(width, height, title.c_str(), nullptr, nullptr);
    if (!window) {
        const std::string why = g_glfw_error;
        glfw.terminate();
        throw Error("GLFW: no OpenGL 4.5 core window: " + why);
    }
    glfw.make_context_current(window);
    glfw.swap_interval(0);  // measure frames, not the display's refresh
    auto impl = std::make_unique<Impl>();
    impl->window = window;
    impl->glfw = &glfw;
    if (epoxy_gl_version() < 45) throw Error("GLFW: the window's context is not OpenGL 4.5");
    auto str = [](GLenum e) {
        const GLubyte* v = glGetString(e);
        return v ? std::string(reinterpret_cast<const char*>(v)) : std::string();
    };
    impl->renderer = str(GL_RENDERER);
    impl->vendor = str(GL_VENDOR);
    impl->version = str(GL_VERSION);
    impl->platform = "window";
    impl->software = impl->renderer.find("llvmpipe") != std::string::npos ||
                     impl->renderer.find("softpipe") != std::string::npos ||
                     impl->renderer.find("swrast") != std::string::npos;
    place_driver_threads(*impl, threads, threads_before);
    return GlContext(std::move(impl));
}

GlContext::GlContext(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
GlContext::GlContext(GlContext&&) noexcept = default;
GlContext& GlContext::operator=(GlContext&&) noexcept = default;
GlContext::~GlContext() = default;

void GlContext::make_current() const {
    if (impl_->window) {
        impl_->glfw->make_context_current(impl_->window);
        return;
    }
    if (!eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl_->context))
        throw Error("EGL: eglMakeCurrent failed (" + hex(eglGetError()) + ")");
}

bool GlContext::has_window() const { return impl_->window != nullptr; }
GLFWwindow* GlContext::glfw_window() const { return impl_->window; }

bool GlContext::window_open() const {
    if (!impl_->window) return true;
    const GlfwApi& glfw = *impl_->glfw;
    glfw.poll_events();
    if (glfw.get_key(impl_->window, GLFW_KEY_ESCAPE) == GLFW_PRESS)
        glfw.set_window_should_close(impl_->window, GLFW_TRUE);
    return !glfw.window_should_close(impl_->window);
}

void GlContext::swap_buffers() const {
    if (impl_->window) impl_->glfw->swap_buffers(impl_->window);
}

void GlContext::write_window_png(const std::string& path) const {
    if (!impl_->window) throw Error(path + ": cannot write a window screenshot: the context has no window");
    int width = 0, height = 0;
    impl_->glfw->get_framebuffer_size(impl_->window, &width, &height);
    std::vector<std::uint8_t> rgba(static_cast<std::size_t>(width) * height * 4);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
    if (const GLenum e = glGetError(); e != GL_NO_ERROR) throw Error("GL: error " + hex(e) + " reading the window");
    // GL rows start at the bottom; PNG rows at the top.
    const std::size_t row = static_cast<std::size_t>(width) * 4;
    for (int y = 0; y < height / 2; ++y)
        std::swap_ranges(rgba.begin() + static_cast<std::ptrdiff_t>(y * row),
                         rgba.begin() + static_cast<std::ptrdiff_t>((y + 1) * row),
                         rgba.begin() + static_cast<std::ptrdiff_t>((height - 1 - y) * row));
    detail::write_png_file(path, width, height, 4, rgba.data(), static_cast<int>(row));
}
const std::string& GlContext::renderer() const { return impl_->renderer; }
const std::string& GlContext::vendor() const { return impl_->vendor; }
const std::string& GlContext::version() const { return impl_->version; }
const std::string& GlContext::platform() const { return impl_->platform; }
bool GlContext::is_software() const { return impl_->software; }
std::size_t GlContext::pinned_driver_threads() const { return impl_->pinned_driver_threads; }

}  // namespace patchcull::gl
