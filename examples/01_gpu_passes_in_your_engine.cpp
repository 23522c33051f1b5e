// examples/01_gpu_passes_in_your_engine.cpp: patchcull's GPU cull passes (patchcull/gl_passes.h)
// in a program that is NOT patchcull's renderer: it opens its own window and OpenGL 4.5 core
// context with GLFW, loads GL through libepoxy, owns every buffer, texture, framebuffer and shader
// program, draws with its own tessellation shaders, and calls only the passes. This is what an
// engine does to adopt them (docs/ENGINE.md explains each piece).
//
// Per frame it runs Niessner & Loop's two-pass occlusion-culling frame ("Patch-Based Occlusion
// Culling for Hardware Tessellation", §3, the sequence gl_pipeline.h describes):
//   1. draw the patches tagged visible by the previous frame     (kDrawMaskFirstPass)
//   2. build the Hi-Z pyramid from that depth buffer             (HiZBuildPass)
//   3. the flag chain: CullStatusPass::begin, FrustumPass, OcclusionPass, CullStatusPass::end
//   4. draw the patches that became visible in step 3            (kDrawMaskSecondPass)
// and then checks the result: the final id buffer must equal the id buffer of its own unculled
// draw (every patch, selection (0, 0)) of the same camera. The model is the Utah teapot split
// twice (512 patches), an OPEN surface drawn two-sided, so back-patch culling (BackpatchConePass,
// Loop, Niessner & Eisenacher, "Effective Back-Patch Culling for Hardware Tessellation") is not
// run: it is conservative only for closed surfaces drawn one-sided (docs/ENGINE.md).
//
// Usage: 01_gpu_passes_in_your_engine [--frames N] [--size WxH] [--aggressive]
//   --frames N    frames per camera position (3 positions, the camera moving), N in 1..1000, default 4
//   --size WxH    framebuffer (and window) size, each in 1..8192, default 320x240
//   --aggressive  skip pass 2 (seed 000 §3.1's aggressive variant: newly visible patches appear a
//                 frame late). NOT conservative: shows that the check catches missing patches.
// Prints one line per frame (patches culled per reason, from the counters; whether the ids match).
// Exit status: 0 every frame matched; 1 a frame did not (or the run culled nothing, so the check
// proved nothing); 2 a setup error (bad option, no X display, no GL 4.5 core context, a shader
// header missing), with one line on stderr. Without a screen: xvfb-run -a -s "-screen 0 1280x1024x24".
//
// GLSL headers: the TCS includes shared.h and patchcull_tcs.h. The library ships their text
// (gl::shipped_glsl, the files of shaders/ embedded at build time), and this program pastes it
// where the TCS says #include, as an engine's own include system would (patchcull's build does the
// same for its shaders, cmake/GlShaders.cmake). The same shared.h is also valid C++ (shaders/ is
// on patchcull_gl's public include path): included here for the binding points, flag bits, draw
// selections and counter indices.

#include <epoxy/gl.h>  // GL through libepoxy, as patchcull_gl loads it; before GLFW
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "patchcull/error.h"
#include "patchcull/frustum.h"
#include "patchcull/gl_passes.h"
#include "patchcull/math.h"
#include "patchcull/patch.h"
#include "patchcull/teapot.h"
#include "shared.h"  // shaders/shared.h: C++ and GLSL at once

namespace pc = patchcull;
namespace sh = patchcull::gl::shared;

namespace {

// ---- setup errors: one line, exit status 2 ---------------------------------------------------

struct SetupError {
    std::string message;
};

[[noreturn]] void setup_error(const std::string& message) { throw SetupError{message}; }

std::string g_glfw_error = "no details";  // GLFW's last error description
void remember_glfw_error(int, const char* description) { g_glfw_error = description ? description : "?"; }

// Strict decimal integer in [lo, hi]: digits only, the whole text, no overflow.
bool parse_int(const std::string& text, int lo, int hi, int& out) {
    if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) return false;
    int value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc() || end != text.data() + text.size() || value < lo || value > hi) return false;
    out = value;
    return true;
}

struct Options {
    int frames = 4;  // per camera position
    int width = 320, height = 240;
    bool aggressive = false;
};

Options parse_options(int argc, char** argv) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "--aggressive") {
            o.aggressive = true;
            continue;
        }
        if (flag != "--frames" && flag != "--size")
            setup_error("unknown option " + pc::quote_input(flag) + " (usage: [--frames N] [--size WxH] [--aggressive])");
        if (i + 1 >= argc) setup_error(flag + ": missing value");
        const std::string value = argv[++i];
        if (flag == "--frames") {
            if (!parse_int(value, 1, 1000, o.frames))
                setup_error("--frames: expected an integer in 1..1000, got " + pc::quote_input(value));
        } else {
            const std::size_t x = value.find('x');
            if (x == std::string::npos || !parse_int(value.substr(0, x), 1, 8192, o.width) ||
                !parse_int(value.substr(x + 1), 1, 8192, o.height))
                setup_error("--size: expected WIDTHxHEIGHT, each in 1..8192, got " + pc::quote_input(value));
        }
    }
    return o;
}

// ---- the engine's shaders ---------------------------------------------------------------------

// The engine's include system: each line `#include "NAME"` becomes the text patchcull ships for
// NAME (gl::shipped_glsl).
std::string expand_includes(const std::string& source) {
    std::istringstream in(source);
    std::string out, line;
    while (std::getline(in, line)) {
        const std::string directive = "#include \"";
        if (line.rfind(directive, 0) == 0 && line.size() > directive.size() + 1 && line.back() == '"') {
            const std::string name = line.substr(directive.size(), line.size() - directive.size() - 1);
            const std::string_view text = pc::gl::shipped_glsl(name);
            if (text.empty()) setup_error("GLSL header " + name + " is not shipped by patchcull");
            out += std::string(text) + "\n";
        } else {
            out += line + "\n";
        }
    }
    return out;
}

// Control points come in as a vertex attribute from the engine's patch buffer (the same GL buffer
// the passes read as a shader storage buffer). The patch index is gl_VertexID / 16: llvmpipe
// restarts gl_PrimitiveID every 4096 vertices, so it is not used (shaders/patchcull_tcs.h).
const char* const kVertexShader = R"(#version 450 core
layout(location = 0) in vec4 a_point;  // homogeneous control point (w x, w y, w z, w)
out vec4 vs_point;
flat out uint vs_patch;
void main() {
    vs_point = a_point;
    vs_patch = uint(gl_VertexID) / 16u;
}
)";

// The only patchcull-specific part of the draw: the two includes and the two lines at the end of
// invocation 0 that give a patch outside the selection (u_draw_mask, u_draw_value) levels 0.
const char* const kControlShader = R"(#version 450 core
#include "shared.h"
#include "patchcull_tcs.h"
layout(vertices = 16) out;
uniform float u_level;
uniform uint u_draw_mask;
uniform uint u_draw_value;
in vec4 vs_point[];
flat in uint vs_patch[];
out vec4 tcs_point[];
patch out uint tcs_patch;
void main() {
    tcs_point[gl_InvocationID] = vs_point[gl_InvocationID];
    if (gl_InvocationID == 0) {
        gl_TessLevelOuter[0] = gl_TessLevelOuter[1] = gl_TessLevelOuter[2] = gl_TessLevelOuter[3] = u_level;
        gl_TessLevelInner[0] = gl_TessLevelInner[1] = u_level;
        // patchcull: honour the cull decisions (after the engine's own level writes).
        if (!patchcull_patch_drawn(vs_patch[0], u_draw_mask, u_draw_value)) patchcull_skip_patch();
        tcs_patch = vs_patch[0];
    }
}
)";

// Bicubic rational Bezier evaluation, control point (i, j) (i along u) at tcs_point[4 j + i].
const char* const kEvaluationShader = R"(#version 450 core
layout(quads, equal_spacing, ccw) in;
uniform mat4 u_object_to_clip;
in vec4 tcs_point[];
patch in uint tcs_patch;
out vec3 tes_position;
out vec3 tes_normal;
flat out uint tes_patch;
void bernstein(float t, out vec4 b, out vec4 db) {
    float s = 1.0 - t;
    b = vec4(s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t);
    db = vec4(-3.0 * s * s, 3.0 * s * s - 6.0 * t * s, 6.0 * t * s - 3.0 * t * t, 3.0 * t * t);
}
void main() {
    vec4 bu, dbu, bv, dbv;
    bernstein(gl_TessCoord.x, bu, dbu);
    bernstein(gl_TessCoord.y, bv, dbv);
    vec4 h = vec4(0.0), hu = vec4(0.0), hv = vec4(0.0);
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            vec4 c = tcs_point[4 * j + i];
            h += bu[i] * bv[j] * c;
            hu += dbu[i] * bv[j] * c;
            hv += bu[i] * dbv[j] * c;
        }
    vec3 p = h.xyz / h.w;
    tes_position = p;
    tes_normal = cross((hu.xyz - p * hu.w) / h.w, (hv.xyz - p * hv.w) / h.w);  // zero where degenerate
    tes_patch = tcs_patch;
    gl_Position = u_object_to_clip * vec4(p, 1.0);
}
)";

// Colour (shaded two-sided: the teapot is open) and the patch id, p + 1 (0 = background).
const char* const kFragmentShader = R"(#version 450 core
uniform vec3 u_eye;
in vec3 tes_position;
in vec3 tes_normal;
flat in uint tes_patch;
layout(location = 0) out vec4 out_color;
layout(location = 1) out uint out_id;
void main() {
    float len = length(tes_normal);
    float facing = len > 0.0 ? abs(dot(tes_normal / len, normalize(u_eye - tes_position))) : 1.0;
    vec3 hue = 0.4 + 0.6 * fract(vec3(0.37, 0.61, 0.83) * float(tes_patch % 97u));
    out_color = vec4(hue * (0.25 + 0.75 * facing), 1.0);
    out_id = tes_patch + 1u;
}
)";

GLuint compile(GLenum stage, const std::string& source, const char* name) {
    const GLuint shader = glCreateShader(stage);
    const char* text = source.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[512] = {};
        glGetShaderInfoLog(shader, sizeof log, nullptr, log);
        setup_error(std::string("GL: ") + name + " shader: " + std::string(log).substr(0, std::string(log).find('\n')));
    }
    return shader;
}

GLuint link_patch_program() {
    const GLuint program = glCreateProgram();
    const GLuint stages[] = {compile(GL_VERTEX_SHADER, kVertexShader, "vertex"),
                             compile(GL_TESS_CONTROL_SHADER, expand_includes(kControlShader), "control"),
                             compile(GL_TESS_EVALUATION_SHADER, kEvaluationShader, "evaluation"),
                             compile(GL_FRAGMENT_SHADER, kFragmentShader, "fragment")};
    for (GLuint s : stages) glAttachShader(program, s);
    glLinkProgram(program);
    for (GLuint s : stages) glDeleteShader(s);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) setup_error("GL: the patch program does not link");
    return program;
}

// ---- the engine's scene ------------------------------------------------------------------------

// The teapot's 32 patches, each split twice (4^2 children): 512 patches, in patch.h's layout.
std::vector<pc::BezierPatch> make_patches() {
    std::vector<pc::BezierPatch> patches = pc::teapot_patches();
    for (int level = 0; level < 2; ++level) {
        std::vector<pc::BezierPatch> children(patches.size() * 4);
        for (std::size_t i = 0; i < patches.size(); ++i) pc::split_patch(patches[i], &children[4 * i]);
        patches.swap(children);
    }
    return patches;
}

struct View {
    pc::Mat4 view, projection;
    pc::Vec3 eye;
};

// Three camera positions (the teapot is z-up, about 6 x 4 x 3 units around (0.2, 0, 1.5)), each
// orbiting 4 degrees per frame: whole in view from the side (its far half occluded by the near
// one); close to the spout (parts leave the frustum); steep from above (the lid hides the inside).
View camera(int frame, int frames_per_position, float aspect) {
    struct Position {
        float azimuth, elevation, distance;
    };
    const Position positions[] = {{20, 15, 9}, {-10, 10, 3.5f}, {140, 60, 7}};
    const Position& p = positions[frame / frames_per_position];
    const float deg = 3.14159265f / 180;
    const float azimuth = (p.azimuth + 4.0f * static_cast<float>(frame % frames_per_position)) * deg;
    const float elevation = p.elevation * deg;
    const pc::Vec3 target{0.2f, 0, 1.5f};
    const pc::Vec3 eye = target + pc::Vec3{std::cos(elevation) * std::cos(azimuth),
                                           std::cos(elevation) * std::sin(azimuth), std::sin(elevation)} * p.distance;
    // patchcull's perspective() is a zero-to-one depth projection (clip_space.h), matching
    // glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE) below.
    return {pc::look_at(eye, target, {0, 0, 1}), pc::perspective(0.9f, aspect, 0.1f, 40.0f), eye};
}

// ---- the engine's renderer ---------------------------------------------------------------------

struct Renderer {
    int width = 0, height = 0;
    GLuint fbo = 0, color = 0, ids = 0, depth = 0;
    GLuint vao = 0, program = 0;
    GLint loc_level = -1, loc_mask = -1, loc_value = -1, loc_object_to_clip = -1, loc_eye = -1;
    GLuint patch_buffer = 0, flag_buffer = 0;
    std::size_t patch_count = 0;
    float level = 8;

    // Clears the framebuffer: depth 1 (the far plane of zero-to-one depth), id 0, a grey colour.
    void clear() const {
        const float grey[4] = {0.15f, 0.15f, 0.18f, 1}, far_depth = 1;
        const GLuint background = sh::kIdBackground;
        glClearNamedFramebufferfv(fbo, GL_COLOR, 0, grey);
        glClearNamedFramebufferuiv(fbo, GL_COLOR, 1, &background);
        glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &far_depth);
    }

    // One draw of every patch; the TCS keeps those whose flag word w has (w & mask) == value.
    void draw(const View& v, std::uint32_t mask, std::uint32_t value) const {
        // The passes leave their own program, buffers and textures bound (gl_passes.h's state
        // contract): a draw sets everything it needs itself.
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
        glViewport(0, 0, width, height);
        glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
        glDisable(GL_CULL_FACE);  // two-sided: the teapot is open
        glUseProgram(program);
        const pc::Mat4 object_to_clip = v.projection * v.view;
        glUniformMatrix4fv(loc_object_to_clip, 1, GL_FALSE, object_to_clip.m);
        glUniform3f(loc_eye, v.eye.x, v.eye.y, v.eye.z);
        glUniform1f(loc_level, level);
        glUniform1ui(loc_mask, mask);
        glUniform1ui(loc_value, value);
        glBindVertexArray(vao);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingCullFlags, flag_buffer);  // read by the TCS
        glPatchParameteri(GL_PATCH_VERTICES, 16);
        // llvmpipe garbles a 4096-vertex chunk that yields more than 65536 tessellated vertices
        // (gl_renderer.h): sub-draws of at most 65536 / (level + 1)^2 patches avoid it.
        const std::size_t per_draw = std::max<std::size_t>(1, 65536 / static_cast<std::size_t>((level + 1) * (level + 1)));
        for (std::size_t first = 0; first < patch_count; first += per_draw)
            glDrawArrays(GL_PATCHES, static_cast<GLint>(16 * first),
                         static_cast<GLsizei>(16 * std::min(per_draw, patch_count - first)));
        glBindVertexArray(0);
        glUseProgram(0);
        // Unbind: the depth texture is sampled next (HiZBuildPass), never while it is attached to
        // the draw framebuffer. Framebuffer writes are visible to later texture fetches without
        // a barrier (only shader stores need glMemoryBarrier).
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    }

    template <class T>
    std::vector<T> read(GLuint texture, GLenum format, GLenum type) const {
        std::vector<T> texels(static_cast<std::size_t>(width) * height);
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        glGetTextureImage(texture, 0, format, type, static_cast<GLsizei>(texels.size() * sizeof(T)), texels.data());
        return texels;
    }
};

void check_gl(const char* where) {
    const GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        char code[16];
        std::snprintf(code, sizeof code, "0x%04x", e);
        setup_error(std::string("GL: error ") + code + " " + where);
    }
}

// ---- the check ---------------------------------------------------------------------------------

struct Comparison {
    std::size_t differing = 0;  // pixels whose id or depth differs and that are no verified tie
    std::size_t ties = 0;       // exact depth ties between two drawn patches (see below)
};

// The culled frame against the unculled draw. Where the ids agree the depths must too. Where they
// differ, the only legitimate cause is an exact depth tie (two patches with fragments at exactly
// the same depth, e.g. where the spout enters the body; GL_LESS keeps whichever was drawn first,
// and the two frames draw in different orders): the depths are then bit-identical AND the
// unculled winner was drawn in the culled frame too (pass 1 or pass 2). A winner that was not
// drawn is a false cull, counted as a difference.
Comparison compare(const std::vector<std::uint32_t>& ids, const std::vector<float>& depth,
                   const std::vector<std::uint32_t>& ref_ids, const std::vector<float>& ref_depth,
                   const std::vector<std::uint32_t>& words_before, const std::vector<std::uint32_t>& words_after,
                   bool aggressive) {
    Comparison c;
    for (std::size_t i = 0; i < ids.size(); ++i) {
        if (ids[i] == ref_ids[i] && depth[i] == ref_depth[i]) continue;
        const std::uint32_t winner = ref_ids[i];
        bool tie = ids[i] != sh::kIdBackground && winner != sh::kIdBackground && depth[i] == ref_depth[i];
        if (tie) {
            const std::uint32_t p = winner - 1;
            const bool pass1 = (words_before[p] & sh::kDrawMaskFirstPass) == sh::kDrawValueFirstPass;
            const bool pass2 = !aggressive && (words_after[p] & sh::kDrawMaskSecondPass) == sh::kDrawValueSecondPass;
            tie = pass1 || pass2;
        }
        if (tie) ++c.ties;
        else ++c.differing;
    }
    return c;
}

std::vector<std::uint32_t> read_words(GLuint buffer, std::size_t count) {
    std::vector<std::uint32_t> words(count);
    glGetNamedBufferSubData(buffer, 0, static_cast<GLsizeiptr>(count * sizeof(std::uint32_t)), words.data());
    return words;
}

int run(const Options& options) {
    // 1. The engine's window and context: GLFW, OpenGL 4.5 core (no patchcull GlContext).
    glfwSetErrorCallback(remember_glfw_error);
    if (!glfwInit()) setup_error("GLFW: cannot start: " + g_glfw_error + " (no X display? run under xvfb-run)");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
    GLFWwindow* window = glfwCreateWindow(options.width, options.height, "patchcull passes in your engine", nullptr, nullptr);
    if (!window) setup_error("GLFW: no OpenGL 4.5 core context: " + g_glfw_error);
    glfwMakeContextCurrent(window);
    glfwSwapInterval(0);
    if (epoxy_gl_version() < 45) setup_error("GL: the context is not OpenGL 4.5");

    // 2. The engine's buffers. Patch buffer: 16 vec4 per patch, patch p's point k at 16 p + k
    //    (BezierPatch's memory layout). Flag buffer: one uint per patch. Counters: kCounterCount
    //    uints, cleared by the engine before each frame, added to by CullStatusPass::end.
    const std::vector<pc::BezierPatch> patches = make_patches();
    Renderer r;
    r.width = options.width;
    r.height = options.height;
    r.patch_count = patches.size();
    GLuint counters = 0;
    glCreateBuffers(1, &r.patch_buffer);
    glNamedBufferStorage(r.patch_buffer, static_cast<GLsizeiptr>(patches.size() * sizeof(pc::BezierPatch)),
                         patches.data(), 0);
    glCreateBuffers(1, &r.flag_buffer);
    // First frame: no previous frame tagged anything, so tag the even-indexed patches visible
    // (as CullPipeline does; seed 000 §3): pass 1 draws half, pass 2 the rest of what shows.
    std::vector<std::uint32_t> words(patches.size(), 0);
    for (std::size_t p = 0; p < words.size(); p += 2) words[p] = sh::kStatusVisible;
    glNamedBufferStorage(r.flag_buffer, static_cast<GLsizeiptr>(words.size() * sizeof(std::uint32_t)), words.data(),
                         GL_DYNAMIC_STORAGE_BIT);
    glCreateBuffers(1, &counters);
    glNamedBufferStorage(counters, sh::kCounterCount * sizeof(std::uint32_t), nullptr, GL_DYNAMIC_STORAGE_BIT);
    // The draw reads control points as vertex attribute 0 from the same buffer.
    glCreateVertexArrays(1, &r.vao);
    glVertexArrayVertexBuffer(r.vao, 0, r.patch_buffer, 0, sizeof(pc::Vec4));
    glEnableVertexArrayAttrib(r.vao, 0);
    glVertexArrayAttribFormat(r.vao, 0, 4, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(r.vao, 0, 0);

    // 3. The engine's framebuffer: colour, R32UI ids and a DEPTH32F depth texture (the Hi-Z
    //    input: no compare mode, nearest filtering) of the same size.
    glCreateTextures(GL_TEXTURE_2D, 1, &r.color);
    glCreateTextures(GL_TEXTURE_2D, 1, &r.ids);
    glCreateTextures(GL_TEXTURE_2D, 1, &r.depth);
    glTextureStorage2D(r.color, 1, GL_RGBA8, r.width, r.height);
    glTextureStorage2D(r.ids, 1, GL_R32UI, r.width, r.height);
    glTextureStorage2D(r.depth, 1, GL_DEPTH_COMPONENT32F, r.width, r.height);
    for (GLuint t : {r.color, r.ids, r.depth}) {
        glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    glCreateFramebuffers(1, &r.fbo);
    glNamedFramebufferTexture(r.fbo, GL_COLOR_ATTACHMENT0, r.color, 0);
    glNamedFramebufferTexture(r.fbo, GL_COLOR_ATTACHMENT1, r.ids, 0);
    glNamedFramebufferTexture(r.fbo, GL_DEPTH_ATTACHMENT, r.depth, 0);
    const GLenum draw_buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glNamedFramebufferDrawBuffers(r.fbo, 2, draw_buffers);
    if (glCheckNamedFramebufferStatus(r.fbo, GL_DRAW_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        setup_error("GL: the framebuffer is incomplete");

    // 4. The engine's patch program, its TCS with patchcull_tcs.h.
    r.program = link_patch_program();
    r.loc_level = glGetUniformLocation(r.program, "u_level");
    r.loc_mask = glGetUniformLocation(r.program, "u_draw_mask");
    r.loc_value = glGetUniformLocation(r.program, "u_draw_value");
    r.loc_object_to_clip = glGetUniformLocation(r.program, "u_object_to_clip");
    r.loc_eye = glGetUniformLocation(r.program, "u_eye");
    check_gl("in setup");

    // 5. The passes, on the context current now. The Hi-Z pyramid texture is ours too.
    pc::gl::PassContext passes;
    pc::gl::CullStatusPass status(passes);
    pc::gl::FrustumPass frustum(passes);
    pc::gl::OcclusionPass occlusion(passes);
    pc::gl::HiZBuildPass hiz_build(passes);
    const pc::gl::HiZTexture hiz = pc::gl::create_hiz_texture(r.width, r.height);
    // The patches the passes cover: the whole buffer, no displacement margins (none displaced).
    const pc::gl::PatchBuffers range{r.patch_buffer, r.flag_buffer, 0, 0, patches.size()};

    std::printf("%s, %zu patches, %dx%d, tessellation level %g, %d frames at 3 camera positions\n",
                reinterpret_cast<const char*>(glGetString(GL_RENDERER)), patches.size(), r.width, r.height,
                static_cast<double>(r.level), 3 * options.frames);
    const float aspect = static_cast<float>(r.width) / static_cast<float>(r.height);
    int mismatched = 0;
    std::size_t total_frustum = 0, total_occlusion = 0;
    const int frames = 3 * options.frames;
    for (int f = 0; f < frames && !glfwWindowShouldClose(window); ++f) {
        const View v = camera(f, options.frames, aspect);
        const pc::Mat4 object_to_clip = v.projection * v.view;
        // For the check only: which patches pass 1 draws (the statuses of the previous frame).
        const std::vector<std::uint32_t> words_before = read_words(r.flag_buffer, patches.size());
        glClearNamedBufferData(counters, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);

        // ---- the culled frame: seed 000 §3's two passes ----
        // Pass 1: the patches the previous frame tagged visible.
        r.clear();
        r.draw(v, sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass);
        // Hi-Z pyramid of pass 1's depth (max per texel: a conservative occluder depth).
        hiz_build.run(r.depth, hiz);
        // The flag chain, on every patch: clear the reasons, frustum test, Hi-Z test (frustum
        // already done: with_frustum = false), then reasons -> statuses and counts. State
        // contract (gl_passes.h): each run() binds its program, its parameter block (a uniform
        // buffer at kUniformPassParams = 0), our buffers at kBindingControlPoints (0),
        // kBindingCullFlags (1) and kBindingCullCounters (6), the textures at kTextureUnitDepth
        // (1) / kTextureUnitHiZ (2) and the image unit kImageUnitHiZOut (0); it leaves those
        // bindings as it set them and glUseProgram(0), touches no framebuffer, viewport, depth or
        // VAO state, and ends with glMemoryBarrier(SSBO | texture fetch | image | buffer update),
        // so the next pass, the TCS of pass 2 and our read-backs see its writes: no barrier of
        // ours is needed. A closed surface drawn one-sided would add BackpatchConePass between
        // the frustum and occlusion passes (skipped here: the teapot is open).
        status.begin(range);
        frustum.run(range, pc::make_frustum_planes(object_to_clip, pc::ClipDepth::zero_to_one));
        occlusion.run(range, object_to_clip, pc::ClipDepth::zero_to_one, hiz, false);
        status.end(range, counters);
        // Pass 2: the patches newly visible (passed now, not drawn in pass 1), into the same
        // colour, id and depth.
        if (!options.aggressive) r.draw(v, sh::kDrawMaskSecondPass, sh::kDrawValueSecondPass);

        std::uint32_t c[sh::kCounterCount] = {};
        glGetNamedBufferSubData(counters, 0, sizeof c, c);
        const std::vector<std::uint32_t> ids = r.read<std::uint32_t>(r.ids, GL_RED_INTEGER, GL_UNSIGNED_INT);
        const std::vector<float> depth = r.read<float>(r.depth, GL_DEPTH_COMPONENT, GL_FLOAT);
        const std::vector<std::uint32_t> words_after = read_words(r.flag_buffer, patches.size());
        // Show the culled frame.
        int fb_width = 0, fb_height = 0;
        glfwGetFramebufferSize(window, &fb_width, &fb_height);
        glBlitNamedFramebuffer(r.fbo, 0, 0, 0, r.width, r.height, 0, 0, fb_width, fb_height, GL_COLOR_BUFFER_BIT,
                               GL_NEAREST);

        // ---- the reference: the same draw with selection (0, 0), every patch ----
        r.clear();
        r.draw(v, 0u, 0u);
        const std::vector<std::uint32_t> ref_ids = r.read<std::uint32_t>(r.ids, GL_RED_INTEGER, GL_UNSIGNED_INT);
        const std::vector<float> ref_depth = r.read<float>(r.depth, GL_DEPTH_COMPONENT, GL_FLOAT);
        check_gl("in a frame");

        const Comparison cmp = compare(ids, depth, ref_ids, ref_depth, words_before, words_after, options.aggressive);
        const bool ok = cmp.differing == 0;
        mismatched += ok ? 0 : 1;
        total_frustum += c[sh::kCounterFrustum];
        total_occlusion += c[sh::kCounterOcclusion];
        std::string verdict = ok ? "ids match" : "IDS DIFFER in " + std::to_string(cmp.differing) + " pixels";
        if (cmp.ties) verdict += " (" + std::to_string(cmp.ties) + " exact depth-tie pixels, both patches drawn)";
        std::printf("frame %d (camera %d): culled frustum %u, back-patch %u (not run), occlusion %u; "
                    "drawn pass 1 %u, pass 2 %u%s; %s\n",
                    f, f / options.frames, c[sh::kCounterFrustum], c[sh::kCounterBackPatch],
                    c[sh::kCounterOcclusion], c[sh::kCounterWasVisible], c[sh::kCounterNewlyVisible],
                    options.aggressive ? " (skipped: --aggressive)" : "", verdict.c_str());
        std::fflush(stdout);
        glfwSwapBuffers(window);
        glfwPollEvents();
    }

    GLuint textures[] = {r.color, r.ids, r.depth, hiz.texture};
    glDeleteTextures(4, textures);
    GLuint buffers[] = {r.patch_buffer, r.flag_buffer, counters};
    glDeleteBuffers(3, buffers);
    glDeleteFramebuffers(1, &r.fbo);
    glDeleteVertexArrays(1, &r.vao);
    glDeleteProgram(r.program);
    // The passes (destroyed at scope end) need the context: the window goes after them (main).
    if (mismatched) {
        std::printf("FAILED: %d of %d frames differ from the unculled draw\n", mismatched, frames);
        return 1;
    }
    if (total_frustum == 0 || total_occlusion == 0) {
        std::printf("FAILED: the run culled nothing by %s, so the check proved nothing\n",
                    total_frustum == 0 ? "the frustum" : "occlusion");
        return 1;
    }
    std::printf("all %d frames match the unculled draw (%zu frustum-, %zu occlusion-culled patch-frames)\n", frames,
                total_frustum, total_occlusion);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    int status = 2;
    try {
        const Options options = parse_options(argc, argv);
        status = run(options);
    } catch (const SetupError& e) {
        std::fprintf(stderr, "%s\n", pc::printable_line(e.message).c_str());
    } catch (const std::exception& e) {  // patchcull::Error from a pass: one line
        std::fprintf(stderr, "%s\n", pc::printable_line(e.what()).c_str());
    }
    glfwTerminate();  // after every GL object and pass is gone
    return status;
}
