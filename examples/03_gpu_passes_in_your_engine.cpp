// examples/03_gpu_passes_in_your_engine.cpp: patchcull's GPU cull passes (patchcull/gl/gl_passes.h)
// in a program that is NOT patchcull's renderer: it opens its own window and OpenGL 4.5 core
// context with GLFW, loads GL through libepoxy, owns every buffer, texture, framebuffer and shader
// program, draws with its own tessellation shaders, and calls only the passes. This is what an
// engine does to adopt them (docs/ENGINE.md explains each piece).
//
// The scene has three objects in one patch buffer, each a range [first, first + count) that the
// passes are given separately (PatchBuffers::first/count), each drawn under its own rule:
//   teapot   the Utah teapot split twice (512 patches): an OPEN surface (the lid sits loose in the
//            rim), drawn two-sided, never back-patch tested;
//   bigguy   BigGuy (data/models, ACC patches through patchcull's import layer): a CLOSED,
//            outward-oriented surface, drawn ONE-SIDED by the exact surface (below) and
//            back-patch tested (Loop, Niessner & Eisenacher, "Effective Back-Patch Culling for
//            Hardware Tessellation": tcone, ncone or ptp);
//   frog     MonsterFrog, DISPLACED by a height map in our TES along the unit normal of the
//            patch's own derivatives, drawn two-sided, tested by its displaced bound (Niessner &
//            Loop, "Patch-Based Occlusion Culling for Hardware Tessellation", §4.2: caf or oobb,
//            cone full, acon or con) instead of its control points.
//
// Per frame it runs Niessner & Loop's two-pass occlusion-culling frame (§3, the order of gl_pipeline.h):
//   1. draw the patches tagged visible by the previous frame     (kDrawMaskFirstPass)
//   2. build the Hi-Z pyramid from that depth buffer             (HiZBuildPass)
//   3. the flag chain on one flag buffer: CullStatusPass::begin; FrustumPass (all, with the
//      displacement margins); BackpatchConePass or BackpatchPtpPass (bigguy); OcclusionPass (all;
//      it skips displaced patches); DisplacedPass (frog, against the same pyramid);
//      CullStatusPass::end per object (its own counter slot)
//   4. draw the patches that became visible in step 3            (kDrawMaskSecondPass)
// and then checks the result: the final id buffer must equal the id buffer of its own unculled
// draw (every patch, selection (0, 0)) of the same camera.
//
// The one-sided rule (the lesson for an engine): back-patch culling is conservative only when a
// closed surface contributes exactly the points whose EXACT tangent plane faces the eye. Hardware
// back-face culling of the tessellated triangles is not that: a secant triangle can face the eye
// where the surface does not, and a crack between patches shows the inside. So our fragment
// shader re-evaluates the patch at the fragment's (u, v) and discards it unless
// cos(du x dv, eye - p) > kFrontFacingMinCosine (shared.h), as patchcull's own
// shaders/patch.frag.glsl does (README.md, "What contributes a pixel"). Open and displaced
// surfaces are drawn two-sided and must never be given to a back-patch pass.
//
// Usage: 03_gpu_passes_in_your_engine [--frames N] [--size WxH] [--aggressive]
//            [--backpatch tcone|ncone|ptp] [--bound caf|oobb] [--cone full|acon|con] [--backpatch-open]
//            [--draw flags|indirect]
//   --frames N    frames per camera position (3 positions, the camera moving), N in 1..1000, default 4
//   --size WxH    framebuffer (and window) size, each in 1..8192, default 320x240
//   --aggressive  skip pass 2 (Niessner & Loop §3.1's aggressive variant: newly visible patches appear a
//                 frame late). NOT conservative: shows that the check catches missing patches.
//   --backpatch   the back-patch test of bigguy (default tcone; ptp with the ncnt rule)
//   --bound, --cone  the displaced bound of the frog and its cone of normals (default caf, acon)
//   --draw        flags (default): each pass issues every patch, our TCS drops the ones it does not
//                 keep (patchcull_tcs.h); indirect: CompactPass (gl_compaction.h) lists the patches
//                 each pass keeps into OUR list and indirect-command buffers, and one
//                 glMultiDrawArraysIndirectCount draws them with our own shaders (a vertex shader
//                 that pulls each point by the list, patchcull_draw_list.h): a culled patch is
//                 never issued (docs/ENGINE.md, "Draw only what survives").
//   --backpatch-open  give the open teapot to the back-patch pass too. NOT conservative (from
//                 above, the inside of its far side shows through the lid gap): shows that the
//                 check catches a back-patch test on a surface it does not hold for.
// Prints one line per frame (patches culled per reason and pass, from the counters; whether the
// ids match). Exit status: 0 every frame matched; 1 a frame did not, or a cull pass culled nothing
// over the run (the check would prove nothing about it); 2 a setup error (bad option, no X
// display, no GL 4.5 core context, a model file missing), with one line on stderr. Without a
// screen: xvfb-run -a -s "-screen 0 1280x1024x24".
//
// GLSL headers: our shaders include shared.h, and the TCS patchcull_tcs.h. The library ships
// their text (gl::shipped_glsl, the files of shaders/ embedded at build time), and this program
// pastes it where a shader says #include, as an engine's own include system would (with one
// header of its own, the patch evaluation shared by the TES and the fragment shader). The same
// shared.h is also valid C++ (shaders/ is on patchcull_gl's public include path): included here
// for the binding points, flag bits, draw selections and counter indices.

#include <epoxy/gl.h>  // GL through libepoxy, as patchcull_gl loads it; before GLFW
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <sstream>
#include <string>
#include <vector>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/displacement.h"
#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"
#include "patchcull/core/teapot.h"
#include "patchcull/gl/gl_compaction.h"
#include "patchcull/gl/gl_passes.h"
#include "patchcull/import/model_loader.h"
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
    bool backpatch_open = false;
    pc::gl::BackpatchMethod backpatch = pc::gl::BackpatchMethod::tcone;
    pc::DisplacedBoundKind bound = pc::DisplacedBoundKind::caf;
    pc::NormalConeKind cone = pc::NormalConeKind::acon;
    bool indirect = false;  // --draw indirect
};

Options parse_options(int argc, char** argv) {
    const std::string usage =
        "(usage: [--frames N] [--size WxH] [--aggressive] [--backpatch tcone|ncone|ptp] [--bound caf|oobb] "
        "[--cone full|acon|con] [--backpatch-open] [--draw flags|indirect])";
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "--aggressive") {
            o.aggressive = true;
            continue;
        }
        if (flag == "--backpatch-open") {
            o.backpatch_open = true;
            continue;
        }
        if (flag != "--frames" && flag != "--size" && flag != "--backpatch" && flag != "--bound" && flag != "--cone" &&
            flag != "--draw")
            setup_error("unknown option " + pc::quote_input(flag) + " " + usage);
        if (i + 1 >= argc) setup_error(flag + ": missing value");
        const std::string value = argv[++i];
        if (flag == "--frames") {
            if (!parse_int(value, 1, 1000, o.frames))
                setup_error("--frames: expected an integer in 1..1000, got " + pc::quote_input(value));
        } else if (flag == "--size") {
            const std::size_t x = value.find('x');
            if (x == std::string::npos || !parse_int(value.substr(0, x), 1, 8192, o.width) ||
                !parse_int(value.substr(x + 1), 1, 8192, o.height))
                setup_error("--size: expected WIDTHxHEIGHT, each in 1..8192, got " + pc::quote_input(value));
        } else if (flag == "--backpatch") {
            if (value == "tcone")
                o.backpatch = pc::gl::BackpatchMethod::tcone;
            else if (value == "ncone")
                o.backpatch = pc::gl::BackpatchMethod::ncone;
            else if (value == "ptp")
                o.backpatch = pc::gl::BackpatchMethod::ptp;
            else
                setup_error("--backpatch: expected tcone, ncone or ptp, got " + pc::quote_input(value));
        } else if (flag == "--draw") {
            if (value != "flags" && value != "indirect")
                setup_error("--draw: expected flags or indirect, got " + pc::quote_input(value));
            o.indirect = value == "indirect";
        } else if (flag == "--bound") {
            if (!pc::parse_displaced_bound(value.c_str(), o.bound))
                setup_error("--bound: expected caf or oobb, got " + pc::quote_input(value));
        } else if (!pc::parse_normal_cone(value.c_str(), o.cone)) {
            setup_error("--cone: expected full, acon or con, got " + pc::quote_input(value));
        }
    }
    return o;
}

// ---- the engine's shaders ---------------------------------------------------------------------

// Our own header, shared by the TES and the fragment shader: the bicubic rational Bezier patch at
// (u, v), control point (i, j) (i along u) at cp[4 j + i], its point p and derivatives pu, pv.
// du x dv of THIS evaluation is the normal that both the displacement (Niessner & Loop §4.2's bounds
// assume it) and the one-sided test (the back-patch tests decide on it) use.
const char* const kPatchEvalGlsl = R"(
void bernstein(float t, out vec4 b, out vec4 db) {
    float s = 1.0 - t;
    b = vec4(s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t);
    db = vec4(-3.0 * s * s, 3.0 * s * s - 6.0 * t * s, 6.0 * t * s - 3.0 * t * t, 3.0 * t * t);
}
void evaluate_patch(vec4 cp[16], vec2 uv, out vec3 p, out vec3 pu, out vec3 pv) {
    vec4 bu, dbu, bv, dbv;
    bernstein(uv.x, bu, dbu);
    bernstein(uv.y, bv, dbv);
    vec4 h = vec4(0.0), hu = vec4(0.0), hv = vec4(0.0);
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            vec4 c = cp[4 * j + i];
            h += bu[i] * bv[j] * c;
            hu += dbu[i] * bv[j] * c;
            hv += bu[i] * dbv[j] * c;
        }
    p = h.xyz / h.w;
    pu = (hu.xyz - p * hu.w) / h.w;
    pv = (hv.xyz - p * hv.w) / h.w;
}
)";

// The engine's include system: each line `#include "NAME"` becomes our own header or the text
// patchcull ships for NAME (gl::shipped_glsl).
std::string expand_includes(const std::string& source) {
    std::istringstream in(source);
    std::string out, line;
    while (std::getline(in, line)) {
        const std::string directive = "#include \"";
        if (line.rfind(directive, 0) == 0 && line.size() > directive.size() + 1 && line.back() == '"') {
            const std::string name = line.substr(directive.size(), line.size() - directive.size() - 1);
            const std::string_view text =
                name == "example_patch_eval.glsl" ? kPatchEvalGlsl : pc::gl::shipped_glsl(name);
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

// --draw indirect: the vertex shader of a compacted draw (gl_compaction.h's CompactPass wrote the
// list). No vertex attributes: vertex gl_VertexID is point gl_VertexID % 16 of patch
// list[gl_VertexID / 16], pulled from the patch buffer (patchcull_draw_list.h); the patch index
// passed on is the flag buffer's, as above, so the rest of the program is the same.
const char* const kListVertexShader = R"(#version 450 core
#include "shared.h"
#include "patchcull_draw_list.h"
layout(std430, binding = kBindingControlPoints) readonly buffer ControlPoints { vec4 control_points[]; };
out vec4 vs_point;
flat out uint vs_patch;
void main() {
    vs_patch = patchcull_draw_list_patch(gl_VertexID);
    vs_point = control_points[16u * vs_patch + patchcull_draw_list_point(gl_VertexID)];
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

// Evaluation and displacement. A patch with margin > 0 (the frog's) is displaced by
// D(s, t) = scale * (h(s, t) - midlevel) along the UNIT normal of its own derivatives, (s, t)
// bilinear in its corner texcoords (patchcull/core/displacement.h): what DisplacedPass bounds, with
// |D| <= margin and D in its range. The height map is sampled as DisplacementMap::sample is
// defined: bilinear, GL_REPEAT, no mipmaps (a mip level averages texels the range never saw).
// Where du x dv = 0 the point stays on the base patch, as the bounds assume.
const char* const kEvaluationShader = R"(#version 450 core
#include "shared.h"
#include "example_patch_eval.glsl"
layout(quads, equal_spacing, ccw) in;
layout(std430, binding = kBindingMaxDisplacement) readonly buffer Margins { float margins[]; };
layout(std430, binding = kBindingPatchTexcoords) readonly buffer Texcoords { vec2 texcoords[]; };  // 4 per patch
layout(binding = kTextureUnitDisplacement) uniform sampler2D u_height;
uniform mat4 u_object_to_clip;
uniform float u_displacement_scale;
uniform float u_displacement_midlevel;
in vec4 tcs_point[];
patch in uint tcs_patch;
out vec3 tes_position;
out vec3 tes_normal;
out vec2 tes_uv;
flat out uint tes_patch;
void main() {
    vec4 cp[16];
    for (int k = 0; k < 16; ++k) cp[k] = tcs_point[k];
    vec3 p, pu, pv;
    evaluate_patch(cp, gl_TessCoord.xy, p, pu, pv);
    vec3 n = cross(pu, pv);  // zero where degenerate
    float len = length(n);
    if (margins[tcs_patch] > 0.0 && len > 0.0) {
        uint b = 4u * tcs_patch;
        vec2 st = mix(mix(texcoords[b], texcoords[b + 1u], gl_TessCoord.x),
                      mix(texcoords[b + 2u], texcoords[b + 3u], gl_TessCoord.x), gl_TessCoord.y);
        float d = u_displacement_scale * (textureLod(u_height, st, 0.0).r - u_displacement_midlevel);
        p += (d / len) * n;
    }
    tes_position = p;
    tes_normal = n;
    tes_uv = gl_TessCoord.xy;
    tes_patch = tcs_patch;
    gl_Position = u_object_to_clip * vec4(p, 1.0);
}
)";

// Colour and the patch id, p + 1 (0 = background). The patches in u_one_sided (the closed,
// back-patch-tested object) follow the one-sided rule: the fragment re-evaluates the EXACT patch at
// its (u, v) and is discarded unless the tangent plane there faces the eye by more than
// kFrontFacingMinCosine. This is the visibility the back-patch tests decide on, independent of the
// tessellation (README.md, "What contributes a pixel"; patchcull's shaders/patch.frag.glsl). The
// others (the open teapot, the displaced frog) are drawn two-sided.
const char* const kFragmentShader = R"(#version 450 core
#include "shared.h"
#include "example_patch_eval.glsl"
layout(std430, binding = kBindingControlPoints) readonly buffer ControlPoints { vec4 control_points[]; };
uniform vec3 u_eye;
uniform uvec2 u_one_sided;  // patches [x, y) are one-sided
in vec3 tes_position;
in vec3 tes_normal;
in vec2 tes_uv;
flat in uint tes_patch;
layout(location = 0) out vec4 out_color;
layout(location = 1) out uint out_id;
void main() {
    if (tes_patch >= u_one_sided.x && tes_patch < u_one_sided.y) {
        vec4 cp[16];
        for (int k = 0; k < 16; ++k) cp[k] = control_points[16u * tes_patch + uint(k)];
        vec3 p, pu, pv;
        evaluate_patch(cp, clamp(tes_uv, 0.0, 1.0), p, pu, pv);  // interpolation may leave [0, 1] by an ulp
        vec3 n = cross(pu, pv), to_eye = u_eye - p;
        if (!(dot(n, to_eye) > kFrontFacingMinCosine * length(n) * length(to_eye))) discard;
    }
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

GLuint link_patch_program(bool draw_list = false) {
    const GLuint program = glCreateProgram();
    const GLuint stages[] = {draw_list ? compile(GL_VERTEX_SHADER, expand_includes(kListVertexShader), "list vertex")
                                       : compile(GL_VERTEX_SHADER, kVertexShader, "vertex"),
                             compile(GL_TESS_CONTROL_SHADER, expand_includes(kControlShader), "control"),
                             compile(GL_TESS_EVALUATION_SHADER, expand_includes(kEvaluationShader), "evaluation"),
                             compile(GL_FRAGMENT_SHADER, expand_includes(kFragmentShader), "fragment")};
    for (GLuint s : stages) glAttachShader(program, s);
    glLinkProgram(program);
    for (GLuint s : stages) glDeleteShader(s);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) setup_error("GL: the patch program does not link");
    return program;
}

// ---- the engine's scene ------------------------------------------------------------------------

// One object: its range of the patch buffer and how it is drawn and culled.
struct Object {
    const char* name;
    std::size_t first = 0, count = 0;
    pc::gl::PatchBuffers range(const pc::gl::PatchBuffers& all) const {
        pc::gl::PatchBuffers r = all;
        r.first = first;
        r.count = count;
        return r;
    }
};

// The scene in world space (z up): patches (patch.h's layout), 4 corner texcoords per patch, and
// per patch the margin max |D| (0 = not displaced) and the range (d_min, d_max) of DisplacedPass.
struct Scene {
    std::vector<pc::BezierPatch> patches;
    std::vector<pc::Vec2> texcoords;
    std::vector<float> margins;
    std::vector<pc::Vec2> ranges;
    pc::DisplacementMap height_map;
    Object teapot{"teapot"}, bigguy{"bigguy"}, frog{"frog"};
};

// Appends patches moved by p -> scale * R (p - base) + position, R a PROPER rotation (y up -> z
// up, then a turn of yaw degrees about z): a reflection would turn a closed surface inside out,
// and its back-patch tests and one-sided drawing with it. Homogeneous points (w x, w y, w z, w)
// move as w (scale * R (x - base) + position).
void add_patches(Scene& s, const std::vector<pc::BezierPatch>& patches, bool y_up, pc::Vec3 base, float scale,
                 float yaw_degrees, pc::Vec3 position) {
    const float a = yaw_degrees * 3.14159265f / 180, c = std::cos(a), sn = std::sin(a);
    for (pc::BezierPatch patch : patches) {
        for (pc::Vec4& q : patch.cp) {
            const pc::Vec3 p = (pc::Vec3{q.x, q.y, q.z} * (1 / q.w) - base) * scale;
            const pc::Vec3 up = y_up ? pc::Vec3{p.x, -p.z, p.y} : p;
            const pc::Vec3 w = pc::Vec3{c * up.x - sn * up.y, sn * up.x + c * up.y, up.z} + position;
            q = {w.x * q.w, w.y * q.w, w.z * q.w, q.w};
        }
        s.patches.push_back(patch);
    }
}

// A shipped OBJ model (ACC patches: patchcull's import layer), standing on z = 0 at position,
// height units tall.
pc::LoadedModel add_model(Scene& s, Object& o, const char* file, float height, float yaw, pc::Vec3 position) {
    pc::LoadedModel model = pc::load_model(pc::shipped_model_path(file), pc::Scheme::acc, 0);
    const pc::Bounds b = pc::patch_bounds(model.rest);  // y up
    const pc::Vec3 base{0.5f * (b.min.x + b.max.x), b.min.y, 0.5f * (b.min.z + b.max.z)};
    o.first = s.patches.size();
    o.count = model.rest.patches.size();
    add_patches(s, model.rest.patches, true, base, height / (b.max.y - b.min.y), yaw, position);
    return model;
}

Scene make_scene() {
    Scene s;
    // The teapot's 32 patches, each split twice (4^2 children), in its own z-up frame.
    std::vector<pc::BezierPatch> teapot = pc::teapot_patches();
    for (int level = 0; level < 2; ++level) {
        std::vector<pc::BezierPatch> children(teapot.size() * 4);
        for (std::size_t i = 0; i < teapot.size(); ++i) pc::split_patch(teapot[i], &children[4 * i]);
        teapot.swap(children);
    }
    s.teapot.count = teapot.size();
    add_patches(s, teapot, false, {0, 0, 0}, 1, 0, {0, 0, 0});
    // BigGuy beside the teapot. Back-patch culling needs a closed, outward-oriented surface:
    // load_model reports it (LoadedModel::closed) after orienting it outward.
    const pc::LoadedModel bigguy = add_model(s, s.bigguy, "bigguy.obj", 4.0f, 200, {0.5f, -5.0f, 0});
    if (!bigguy.closed) setup_error("bigguy.obj: not a closed surface (the back-patch tests need one)");
    // MonsterFrog behind the teapot (seen from the first camera), displaced.
    const pc::LoadedModel frog = add_model(s, s.frog, "monsterfrog.obj", 2.6f, 30, {-5.5f, 2.2f, 0});
    const std::size_t n = s.patches.size();
    s.texcoords.assign(4 * n, pc::Vec2{});
    s.margins.assign(n, 0.0f);
    s.ranges.assign(n, pc::Vec2{});
    // The height map: patchcull's procedural one; D = scale (h - 1/2), |D| <= 3% of the frog's height.
    s.height_map = pc::make_procedural_displacement(256, 0.16f);
    for (std::size_t i = 0; i < s.frog.count; ++i) {
        const pc::PatchInfo& info = frog.rest.info[i];
        const std::size_t p = s.frog.first + i;
        for (int k = 0; k < 4; ++k) s.texcoords[4 * p + k] = info.uv[k];
        // Sathe's per-patch bound of D over every texel the patch can sample (displacement.h).
        const pc::DisplacementRange r = s.height_map.patch_range(info.uv);
        s.margins[p] = r.max_abs();
        s.ranges[p] = {r.d_min, r.d_max};
    }
    return s;
}

struct View {
    pc::Mat4 view, projection;
    pc::Vec3 eye;
};

// Three camera positions, each orbiting 4 degrees per frame: the whole scene from the side (the
// teapot hides part of the frog, every object hides its own far half); close to the teapot's
// spout (most of the scene leaves the frustum); steep from above, behind BigGuy.
View camera(int frame, int frames_per_position, float aspect) {
    struct Position {
        float azimuth, elevation, distance;
        pc::Vec3 target;
    };
    const Position positions[] = {
        {15, 12, 13, {-1.5f, -1.2f, 1.3f}}, {-10, 10, 3.5f, {0.2f, 0, 1.5f}}, {-120, 55, 12, {-1.5f, -2.0f, 1.0f}}};
    const Position& p = positions[frame / frames_per_position];
    const float deg = 3.14159265f / 180;
    const float azimuth = (p.azimuth + 4.0f * static_cast<float>(frame % frames_per_position)) * deg;
    const float elevation = p.elevation * deg;
    const pc::Vec3 eye = p.target + pc::Vec3{std::cos(elevation) * std::cos(azimuth),
                                             std::cos(elevation) * std::sin(azimuth), std::sin(elevation)} *
                                        p.distance;
    // patchcull's perspective() is a zero-to-one depth projection (clip_space.h), matching
    // glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE) below.
    return {pc::look_at(eye, p.target, {0, 0, 1}), pc::perspective(0.9f, aspect, 0.1f, 60.0f), eye};
}

// ---- the engine's renderer ---------------------------------------------------------------------

struct Renderer {
    int width = 0, height = 0;
    GLuint fbo = 0, color = 0, ids = 0, depth = 0;
    GLuint vao = 0, program = 0;
    GLuint patch_buffer = 0, flag_buffer = 0, texcoord_buffer = 0, margin_buffer = 0, height_texture = 0;
    std::size_t patch_count = 0;
    // --draw indirect: the list program (kListVertexShader) and CompactPass's outputs, ours too.
    GLuint list_program = 0, draw_list = 0, draw_commands = 0, draw_count = 0;
    bool indirect_count = false;  // glMultiDrawArraysIndirectCount: GL 4.6 or GL_ARB_indirect_parameters
    Object one_sided{"none"};
    float level = 6, displacement_scale = 0, displacement_midlevel = 0.5f;

    // Clears the framebuffer: depth 1 (the far plane of zero-to-one depth), id 0, a grey colour.
    void clear() const {
        const float grey[4] = {0.15f, 0.15f, 0.18f, 1}, far_depth = 1;
        const GLuint background = sh::kIdBackground;
        glClearNamedFramebufferfv(fbo, GL_COLOR, 0, grey);
        glClearNamedFramebufferuiv(fbo, GL_COLOR, 1, &background);
        glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &far_depth);
    }

    // llvmpipe garbles a 4096-vertex chunk that yields more than 65536 tessellated vertices
    // (gl_renderer.h): sub-draws of at most 65536 / (level + 1)^2 patches avoid it.
    std::size_t per_draw() const {
        return std::max<std::size_t>(1, 65536 / static_cast<std::size_t>((level + 1) * (level + 1)));
    }

    // The state and uniforms of a patch draw with program prog; the TCS keeps the patches whose
    // flag word w has (w & mask) == value.
    void begin_draw(GLuint prog, const View& v, std::uint32_t mask, std::uint32_t value) const {
        // The passes leave their own program, buffers and textures bound (gl_passes.h's state
        // contract): a draw sets everything it needs itself.
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
        glViewport(0, 0, width, height);
        glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
        // No hardware face culling: the open and displaced objects are two-sided, and the closed
        // one is made one-sided by its exact surface in the fragment shader, not by its triangles.
        glDisable(GL_CULL_FACE);
        glUseProgram(prog);
        const pc::Mat4 object_to_clip = v.projection * v.view;
        glUniformMatrix4fv(glGetUniformLocation(prog, "u_object_to_clip"), 1, GL_FALSE, object_to_clip.m);
        glUniform3f(glGetUniformLocation(prog, "u_eye"), v.eye.x, v.eye.y, v.eye.z);
        glUniform1f(glGetUniformLocation(prog, "u_level"), level);
        glUniform1ui(glGetUniformLocation(prog, "u_draw_mask"), mask);
        glUniform1ui(glGetUniformLocation(prog, "u_draw_value"), value);
        glUniform2ui(glGetUniformLocation(prog, "u_one_sided"), static_cast<GLuint>(one_sided.first),
                     static_cast<GLuint>(one_sided.first + one_sided.count));
        glUniform1f(glGetUniformLocation(prog, "u_displacement_scale"), displacement_scale);
        glUniform1f(glGetUniformLocation(prog, "u_displacement_midlevel"), displacement_midlevel);
        glBindVertexArray(vao);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingCullFlags, flag_buffer);           // read by the TCS
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingControlPoints, patch_buffer);      // fragment shader
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingMaxDisplacement, margin_buffer);   // TES
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingPatchTexcoords, texcoord_buffer);  // TES
        glBindTextureUnit(sh::kTextureUnitDisplacement, height_texture);
        glPatchParameteri(GL_PATCH_VERTICES, 16);
    }

    void end_draw() const {
        glBindVertexArray(0);
        glUseProgram(0);
        // Unbind: the depth texture is sampled next (HiZBuildPass), never while it is attached to
        // the draw framebuffer. Framebuffer writes are visible to later texture fetches without
        // a barrier (only shader stores need glMemoryBarrier).
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    }

    // One draw of every patch; the TCS keeps those whose flag word w has (w & mask) == value.
    void draw(const View& v, std::uint32_t mask, std::uint32_t value) const {
        begin_draw(program, v, mask, value);
        const std::size_t k = per_draw();
        for (std::size_t first = 0; first < patch_count; first += k)
            glDrawArrays(GL_PATCHES, static_cast<GLint>(16 * first),
                         static_cast<GLsizei>(16 * std::min(k, patch_count - first)));
        end_draw();
    }

    // --draw indirect: the same selection, but only the patches it keeps are issued. CompactPass
    // lists them (their flag-buffer indices, in ascending order) into our list, with commands of
    // at most per_draw() patches each (the llvmpipe limit above) and their draw count, on the
    // GPU; one multi-draw then draws the list with the list program (its TCS given the selection
    // (0, 0): every listed patch is drawn). Nothing is read back. Returns nothing; the commands
    // hold how many patches were issued (issued() reads them, for the printout only).
    void draw_compacted(pc::gl::CompactPass& compact, const pc::gl::PatchBuffers& all, const View& v,
                        std::uint32_t mask, std::uint32_t value) const {
        const std::size_t k = per_draw();
        compact.run(all, mask, value, {draw_list, 0, draw_commands, 0, draw_count, 0, k});
        begin_draw(list_program, v, 0u, 0u);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingDrawList, draw_list);  // read by the vertex shader
        glBindBuffer(GL_DRAW_INDIRECT_BUFFER, draw_commands);
        const auto commands = static_cast<GLsizei>(pc::gl::compact_command_count(patch_count, k));
        if (indirect_count) {
            glBindBuffer(GL_PARAMETER_BUFFER_ARB, draw_count);
            glMultiDrawArraysIndirectCountARB(GL_PATCHES, nullptr, 0, commands, 0);
            glBindBuffer(GL_PARAMETER_BUFFER_ARB, 0);
        } else {
            glMultiDrawArraysIndirect(GL_PATCHES, nullptr, commands, 0);  // the empty commands draw nothing
        }
        glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
        end_draw();
    }

    // The patches the last draw_compacted issued (a read-back, for the printout).
    std::size_t issued() const {
        std::vector<pc::gl::DrawArraysIndirectCommand> c(pc::gl::compact_command_count(patch_count, per_draw()));
        glGetNamedBufferSubData(draw_commands, 0, static_cast<GLsizeiptr>(c.size() * sizeof c[0]), c.data());
        std::size_t n = 0;
        for (const pc::gl::DrawArraysIndirectCommand& command : c) n += command.count / 16;
        return n;
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

template <class T>
GLuint make_buffer(const std::vector<T>& data, GLbitfield flags = 0) {
    GLuint buffer = 0;
    glCreateBuffers(1, &buffer);
    glNamedBufferStorage(buffer, static_cast<GLsizeiptr>(data.size() * sizeof(T)), data.data(), flags);
    return buffer;
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
        if (tie)
            ++c.ties;
        else
            ++c.differing;
    }
    return c;
}

std::vector<std::uint32_t> read_words(GLuint buffer, std::size_t count) {
    std::vector<std::uint32_t> words(count);
    glGetNamedBufferSubData(buffer, 0, static_cast<GLsizeiptr>(count * sizeof(std::uint32_t)), words.data());
    return words;
}

// What the counters of one frame say, per object slot (CullStatusPass::end adds each object's
// counts to its own slot of kCounterCount uints).
struct Counts {
    std::uint32_t slot[3][sh::kCounterCount] = {};
    std::uint32_t total(std::uint32_t counter) const { return slot[0][counter] + slot[1][counter] + slot[2][counter]; }
};

int run(const Options& options) {
    // 0. The engine's scene (a model file missing is a setup error before any window opens).
    const Scene scene = make_scene();

    // 1. The engine's window and context: GLFW, OpenGL 4.5 core (no patchcull GlContext).
    glfwSetErrorCallback(remember_glfw_error);
    if (!glfwInit()) setup_error("GLFW: cannot start: " + g_glfw_error + " (no X display? run under xvfb-run)");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
    GLFWwindow* window =
        glfwCreateWindow(options.width, options.height, "patchcull passes in your engine", nullptr, nullptr);
    if (!window) setup_error("GLFW: no OpenGL 4.5 core context: " + g_glfw_error);
    glfwMakeContextCurrent(window);
    glfwSwapInterval(0);
    if (epoxy_gl_version() < 45) setup_error("GL: the context is not OpenGL 4.5");

    // 2. The engine's buffers. Patch buffer: 16 vec4 per patch, patch p's point k at 16 p + k
    //    (BezierPatch's memory layout). Flag buffer: one uint per patch. Margins (float) and
    //    displacement ranges (vec2) per patch, for the passes and our TES; corner texcoords (4
    //    vec2 per patch) for our TES. Counters: one slot of kCounterCount uints per object, at
    //    offsets that are multiples of GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, cleared by the
    //    engine before each frame, added to by CullStatusPass::end.
    const std::size_t n = scene.patches.size();
    Renderer r;
    r.width = options.width;
    r.height = options.height;
    r.patch_count = n;
    r.one_sided = scene.bigguy;
    r.displacement_scale = scene.height_map.scale;
    r.displacement_midlevel = scene.height_map.midlevel;
    r.patch_buffer = make_buffer(scene.patches);
    r.texcoord_buffer = make_buffer(scene.texcoords);
    r.margin_buffer = make_buffer(scene.margins);
    const GLuint range_buffer = make_buffer(scene.ranges);
    // First frame: no previous frame tagged anything, so tag the even-indexed patches visible
    // (as CullPipeline does; Niessner & Loop §3): pass 1 draws half, pass 2 the rest of what shows.
    std::vector<std::uint32_t> words(n, 0);
    for (std::size_t p = 0; p < n; p += 2) words[p] = sh::kStatusVisible;
    r.flag_buffer = make_buffer(words, GL_DYNAMIC_STORAGE_BIT);
    GLint alignment = 1;
    glGetIntegerv(GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, &alignment);
    const std::size_t slot_bytes = sh::kCounterCount * sizeof(std::uint32_t);
    const std::size_t stride = (slot_bytes + alignment - 1) / alignment * alignment;
    GLuint counters = 0;
    glCreateBuffers(1, &counters);
    glNamedBufferStorage(counters, static_cast<GLsizeiptr>(3 * stride), nullptr, GL_DYNAMIC_STORAGE_BIT);
    // The draw reads control points as vertex attribute 0 from the patch buffer.
    glCreateVertexArrays(1, &r.vao);
    glVertexArrayVertexBuffer(r.vao, 0, r.patch_buffer, 0, sizeof(pc::Vec4));
    glEnableVertexArrayAttrib(r.vao, 0);
    glVertexArrayAttribFormat(r.vao, 0, 4, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(r.vao, 0, 0);
    // The height map: R32F, bilinear, GL_REPEAT, row 0 at t = 0 (displacement.h), one level.
    const pc::DisplacementMap& map = scene.height_map;
    glCreateTextures(GL_TEXTURE_2D, 1, &r.height_texture);
    glTextureStorage2D(r.height_texture, 1, GL_R32F, map.width, map.height);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureSubImage2D(r.height_texture, 0, 0, 0, map.width, map.height, GL_RED, GL_FLOAT, map.texels.data());
    glTextureParameteri(r.height_texture, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTextureParameteri(r.height_texture, GL_TEXTURE_WRAP_T, GL_REPEAT);
    glTextureParameteri(r.height_texture, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(r.height_texture, GL_TEXTURE_MAG_FILTER, GL_LINEAR);

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
    // --draw indirect: the list program and CompactPass's outputs (a list entry per patch, the
    // commands of the whole set, one draw count).
    if (options.indirect) {
        r.list_program = link_patch_program(true);
        r.indirect_count = epoxy_gl_version() >= 46 || epoxy_has_gl_extension("GL_ARB_indirect_parameters");
        glCreateBuffers(1, &r.draw_list);
        glNamedBufferStorage(r.draw_list, static_cast<GLsizeiptr>(4 * std::max<std::size_t>(n, 1)), nullptr, 0);
        glCreateBuffers(1, &r.draw_commands);
        glNamedBufferStorage(r.draw_commands,
                             static_cast<GLsizeiptr>(sizeof(pc::gl::DrawArraysIndirectCommand) *
                                                     pc::gl::compact_command_count(n, r.per_draw())),
                             nullptr, 0);
        glCreateBuffers(1, &r.draw_count);
        glNamedBufferStorage(r.draw_count, 4, nullptr, 0);
    }
    check_gl("in setup");

    // 5. The passes, on the context current now. The Hi-Z pyramid texture is ours too.
    pc::gl::PassContext passes;
    pc::gl::CullStatusPass status(passes);
    pc::gl::FrustumPass frustum(passes);
    pc::gl::BackpatchConePass cones(passes);
    pc::gl::BackpatchPtpPass ptp(passes);
    pc::gl::OcclusionPass occlusion(passes);
    pc::gl::DisplacedPass displaced(passes);
    pc::gl::HiZBuildPass hiz_build(passes);
    pc::gl::CompactPass compact(passes);  // --draw indirect
    const pc::gl::HiZTexture hiz = pc::gl::create_hiz_texture(r.width, r.height);
    // All patches, with the margin buffer: the passes then know the displaced ones (margin > 0):
    // FrustumPass moves their control points out by the margin, OcclusionPass and the back-patch
    // passes skip them. Each object is a range of these buffers.
    const pc::gl::PatchBuffers all{r.patch_buffer, r.flag_buffer, r.margin_buffer, 0, n};
    const Object* const objects[3] = {&scene.teapot, &scene.bigguy, &scene.frog};

    const char* const backpatch_name = pc::gl::backpatch_method_name(options.backpatch);
    char bound_name[32];
    std::snprintf(bound_name, sizeof bound_name, "%s/%s", pc::displaced_bound_name(options.bound),
                  pc::normal_cone_name(options.cone));
    std::printf(
        "%s, %zu patches (teapot %zu two-sided, bigguy %zu one-sided, frog %zu displaced), %dx%d, "
        "tessellation level %g, back-patch %s, displaced bound %s, %d frames at 3 camera positions, draw %s\n",
        reinterpret_cast<const char*>(glGetString(GL_RENDERER)), n, scene.teapot.count, scene.bigguy.count,
        scene.frog.count, r.width, r.height, static_cast<double>(r.level), backpatch_name, bound_name,
        3 * options.frames,
        options.indirect ? (r.indirect_count ? "indirect (glMultiDrawArraysIndirectCount)" : "indirect") : "flags");
    const float aspect = static_cast<float>(r.width) / static_cast<float>(r.height);
    int mismatched = 0;
    std::size_t total_frustum = 0, total_backpatch = 0, total_occlusion = 0, total_displaced = 0;
    const int frames = 3 * options.frames;
    for (int f = 0; f < frames && !glfwWindowShouldClose(window); ++f) {
        const View v = camera(f, options.frames, aspect);
        const pc::Mat4 object_to_clip = v.projection * v.view;  // the scene is in world space: model = I
        // For the check only: which patches pass 1 draws (the statuses of the previous frame).
        const std::vector<std::uint32_t> words_before = read_words(r.flag_buffer, n);
        glClearNamedBufferData(counters, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);

        // ---- the culled frame: Niessner & Loop §3's two passes ----
        // Pass 1: the patches the previous frame tagged visible.
        r.clear();
        std::size_t issued[2] = {n, options.aggressive ? 0 : n};  // patches issued per pass (the flags: all)
        if (options.indirect) {
            r.draw_compacted(compact, all, v, sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass);
            issued[0] = r.issued();  // a read-back for the printout only
        } else {
            r.draw(v, sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass);
        }
        // Hi-Z pyramid of pass 1's depth (max per texel: a conservative occluder depth).
        hiz_build.run(r.depth, hiz);
        // The flag chain. Each pass skips the patches an earlier one culled and writes its own
        // reason into those it culls. State contract (gl_passes.h): each run() binds its program,
        // its parameter block (a uniform buffer at kUniformPassParams = 0), our buffers at
        // their bindings (control points 0, flags 1, margins 2, counters 6, ranges 8), the
        // textures at kTextureUnitDepth (1) / kTextureUnitHiZ (2) and the image unit
        // kImageUnitHiZOut (0); it leaves those bindings as it set them and glUseProgram(0),
        // touches no framebuffer, viewport, depth or VAO state, and ends with
        // glMemoryBarrier(SSBO | texture fetch | image | buffer update), so the next pass, the
        // TCS of pass 2 and our read-backs see its writes: no barrier of ours is needed.
        status.begin(all);
        frustum.run(all, pc::make_frustum_planes(object_to_clip, pc::ClipDepth::zero_to_one));
        // Back-patch: ONLY the closed, one-sided object (on the open teapot the inside of a patch
        // that faces away shows through the lid gap; a displaced patch's normals are not the
        // base patch's). The eye is in the patches' space (world here).
        for (const Object* o : {&scene.bigguy, options.backpatch_open ? &scene.teapot : nullptr}) {
            if (!o) continue;
            if (options.backpatch == pc::gl::BackpatchMethod::ptp)
                ptp.run(o->range(all), object_to_clip, pc::clip_space_eye_alpha(v.projection), pc::PtpRule::ncnt);
            else
                cones.run(o->range(all), options.backpatch, v.eye);
        }
        // Hi-Z test of the control-point boxes (the frustum already done: with_frustum = false).
        occlusion.run(all, object_to_clip, pc::ClipDepth::zero_to_one, hiz, false);
        // The frog's displaced bounds against the frustum and the same pyramid (only_displaced:
        // a patch whose range is (0, 0) was left to the passes above).
        const pc::DisplacedCullView cull_view =
            pc::make_displaced_cull_view(v.view, v.projection, pc::ClipDepth::zero_to_one);
        displaced.run(scene.frog.range(all), range_buffer, options.bound, options.cone, cull_view, &hiz, true);
        // Reasons -> statuses, counted per object.
        for (std::size_t o = 0; o < 3; ++o) status.end(objects[o]->range(all), counters, o * stride);
        // Pass 2: the patches newly visible (passed now, not drawn in pass 1), into the same
        // colour, id and depth.
        if (!options.aggressive && options.indirect) {
            r.draw_compacted(compact, all, v, sh::kDrawMaskSecondPass, sh::kDrawValueSecondPass);
            issued[1] = r.issued();
        } else if (!options.aggressive) {
            r.draw(v, sh::kDrawMaskSecondPass, sh::kDrawValueSecondPass);
        }

        Counts c;
        for (std::size_t o = 0; o < 3; ++o)
            glGetNamedBufferSubData(counters, static_cast<GLintptr>(o * stride), slot_bytes, c.slot[o]);
        const std::vector<std::uint32_t> ids = r.read<std::uint32_t>(r.ids, GL_RED_INTEGER, GL_UNSIGNED_INT);
        const std::vector<float> depth = r.read<float>(r.depth, GL_DEPTH_COMPONENT, GL_FLOAT);
        const std::vector<std::uint32_t> words_after = read_words(r.flag_buffer, n);
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
        // Who culled what: back-patch reasons come only from the back-patch pass (bigguy);
        // kCounterDisplacedOcclusion counts the displaced patches culled by Hi-Z, which only
        // DisplacedPass tests (OcclusionPass skips them); the rest of the occlusion count is
        // OcclusionPass's. A displaced patch's frustum cull is FrustumPass's (with its margin) or
        // DisplacedPass's (its bound).
        const std::uint32_t displaced_hiz = c.total(sh::kCounterDisplacedOcclusion);
        const std::uint32_t occlusion_hiz = c.total(sh::kCounterOcclusion) - displaced_hiz;
        total_frustum += c.total(sh::kCounterFrustum);
        total_backpatch += c.total(sh::kCounterBackPatch);
        total_occlusion += occlusion_hiz;
        total_displaced += displaced_hiz;
        std::string verdict = ok ? "ids match" : "IDS DIFFER in " + std::to_string(cmp.differing) + " pixels";
        if (cmp.ties) verdict += " (" + std::to_string(cmp.ties) + " exact depth-tie pixels, both patches drawn)";
        std::printf(
            "frame %d (camera %d): culled frustum %u (teapot %u, bigguy %u, frog %u), back-patch %u "
            "(bigguy %u), occlusion %u (teapot %u, bigguy %u), displaced occlusion %u (frog); "
            "drawn pass 1 %u, pass 2 %u%s; issued %zu + %zu (%s); %s\n",
            f, f / options.frames, c.total(sh::kCounterFrustum), c.slot[0][sh::kCounterFrustum],
            c.slot[1][sh::kCounterFrustum], c.slot[2][sh::kCounterFrustum], c.total(sh::kCounterBackPatch),
            c.slot[1][sh::kCounterBackPatch], occlusion_hiz, c.slot[0][sh::kCounterOcclusion],
            c.slot[1][sh::kCounterOcclusion], displaced_hiz, c.total(sh::kCounterWasVisible),
            c.total(sh::kCounterNewlyVisible), options.aggressive ? " (skipped: --aggressive)" : "", issued[0],
            issued[1], options.indirect ? "indirect" : "flags", verdict.c_str());
        std::fflush(stdout);
        glfwSwapBuffers(window);
        glfwPollEvents();
    }

    GLuint textures[] = {r.color, r.ids, r.depth, r.height_texture, hiz.texture};
    glDeleteTextures(5, textures);
    GLuint buffers[] = {r.patch_buffer, r.flag_buffer, r.texcoord_buffer, r.margin_buffer, range_buffer, counters};
    glDeleteBuffers(6, buffers);
    glDeleteFramebuffers(1, &r.fbo);
    glDeleteVertexArrays(1, &r.vao);
    glDeleteProgram(r.program);
    glDeleteProgram(r.list_program);
    const GLuint list_buffers[] = {r.draw_list, r.draw_commands, r.draw_count};
    glDeleteBuffers(3, list_buffers);
    // The passes (destroyed at scope end) need the context: the window goes after them (main).
    if (mismatched) {
        std::printf("FAILED: %d of %d frames differ from the unculled draw\n", mismatched, frames);
        return 1;
    }
    // Each cull pass must have culled something, or the check says nothing about it.
    const struct {
        std::size_t count;
        std::string pass;
    } culled[] = {{total_frustum, "FrustumPass"},
                  {total_backpatch, std::string("the back-patch pass (") + backpatch_name + ")"},
                  {total_occlusion, "OcclusionPass"},
                  {total_displaced, std::string("DisplacedPass (") + bound_name + ")"}};
    for (const auto& pass : culled)
        if (pass.count == 0) {
            std::printf("FAILED: %s culled nothing over the run, so the check proved nothing about it\n",
                        pass.pass.c_str());
            return 1;
        }
    std::printf(
        "all %d frames match the unculled draw (patch-frames culled: %zu frustum, %zu back-patch %s, "
        "%zu occlusion, %zu displaced occlusion %s)\n",
        frames, total_frustum, total_backpatch, backpatch_name, total_occlusion, total_displaced, bound_name);
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
    } catch (const std::exception& e) {  // patchcull::Error from the import layer or a pass: one line
        std::fprintf(stderr, "%s\n", pc::printable_line(e.what()).c_str());
    }
    glfwTerminate();  // after every GL object and pass is gone
    return status;
}
