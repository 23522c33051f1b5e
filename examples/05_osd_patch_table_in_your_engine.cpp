// examples/05_osd_patch_table_in_your_engine.cpp: patchcull's GPU cull passes added to an engine
// that already draws OpenSubdiv's feature-adaptive patch tables (Osd::GLPatchTable with OpenSubdiv's
// own GLSL patch shaders, as OpenSubdiv's viewers and Hydra Storm do). Like 03, it opens its own
// window and OpenGL 4.5 core context with GLFW and loads GL through libepoxy; it builds its own
// Far::TopologyRefiner from the mesh below, refines it adaptively, and culls the table IN PLACE:
// the passes read the engine's vertex buffer and the table's own index buffer, nothing is copied.
//
// The mesh: an open box, 33 quads (a 3x3 floor, four walls two quads high), with
//   - a semi-sharp crease (sharpness 2) along the seam of the floor and the walls,
//   - an infinitely sharp crease up one vertical edge,
//   - a sharp corner on one corner of the rim,
//   - the rim itself: an open boundary (EDGE_AND_CORNER interpolation).
// The floor's corners are extraordinary (valence 3): Far closes them with Gregory-basis end caps,
// which OpenSubdiv's Gregory-basis shaders draw and the passes cull as Gregory sources.
//
// What the engine adds to its OpenSubdiv draw (docs/ENGINE.md, "OpenSubdiv's own patch shaders"):
//   1. five lines in the client header of OpenSubdiv's TCS (shared.h, patchcull_tcs.h, and
//      OSD_PATCH_CULL(N) redefined to skip a culled patch). gl_osd::OsdPatchTableDraw composes
//      OpenSubdiv's programs with them and draws Osd::GLPatchTable: it stands for the engine's own
//      OpenSubdiv draw here;
//   2. a flag buffer (a uint per patch, in Far's patch order) and a counter buffer;
//   3. one gl::GpuPatchSource per patch array (OsdPatchTableDraw::sources);
//   4. the passes around the draw, Niessner & Loop's two-pass frame ("Patch-Based Occlusion
//      Culling for Hardware Tessellation", §3):
//        pass 1    draw the patches the previous frame found visible
//        Hi-Z      build the pyramid from pass 1's depth                        (HiZBuildPass)
//        chain     CullStatusPass::begin, FrustumPass, OcclusionPass, CullStatusPass::end
//        pass 2    draw the patches found newly visible
//   gl_osd::OsdCullFrame does 2-4 in one call; they are spelled out here.
//
// Back-patch culling is OFF: the box is open and drawn two-sided, and through its open top the
// inside of a wall facing away from the eye shows. A back-patch test (Loop, Niessner & Eisenacher,
// "Effective Back-Patch Culling for Hardware Tessellation") holds only for a closed surface drawn
// one-sided; --backpatch-open runs one anyway, and the check must catch it.
//
// The check: after each culled frame the same view is drawn unculled, and the two patch-id images
// (Far's patch index + 1, 0 = background) must be equal pixel for pixel.
//
// Usage: 05_osd_patch_table_in_your_engine [--frames N] [--size WxH] [--level L] [--aggressive]
//            [--backpatch-open]
//   --frames N        frames per camera position (3 positions, orbiting), 1..1000, default 2
//   --size WxH        the framebuffer size, each in 1..8192, default 320x240
//   --level L         Far's adaptive isolation level, 1..6, default 3
//   --aggressive      skip pass 2 (NOT conservative: newly visible patches are missing)
//   --backpatch-open  back-patch test (tcone) on the open box (NOT conservative)
// Prints one line per frame. Exit status: 0 every frame matched and FrustumPass and OcclusionPass
// each culled something; 1 a frame differed, or a pass culled nothing (the check proved nothing
// about it); 2 a setup error (bad option, no X display, no GL 4.5 core context), one line on
// stderr. Without a screen: xvfb-run -a -s "-screen 0 1280x1024x24".

#include <epoxy/gl.h>  // GL through libepoxy, as patchcull_gl loads it; before GLFW
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "patchcull/core/error.h"
#include "patchcull/gl/gl_passes.h"
#include "patchcull/gl_osd/osd_gl_draw.h"
#include "shared.h"  // shaders/shared.h: flag bits, draw selections, counter indices

namespace pc = patchcull;
namespace sh = patchcull::gl::shared;
namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

namespace {

// ---- setup errors: one line, exit status 2 ---------------------------------------------------

struct SetupError {
    std::string message;
};

[[noreturn]] void setup_error(const std::string& message) { throw SetupError{message}; }

std::string g_glfw_error = "no details";
void remember_glfw_error(int, const char* description) { g_glfw_error = description ? description : "?"; }

bool parse_int(const std::string& text, int lo, int hi, int& out) {
    if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) return false;
    int value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc() || end != text.data() + text.size() || value < lo || value > hi) return false;
    out = value;
    return true;
}

struct Options {
    int frames = 2, width = 320, height = 240, level = 3;
    bool aggressive = false, backpatch_open = false;
};

Options parse_options(int argc, char** argv) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "--aggressive" || flag == "--backpatch-open") {
            (flag == "--aggressive" ? o.aggressive : o.backpatch_open) = true;
            continue;
        }
        if (flag != "--frames" && flag != "--size" && flag != "--level")
            setup_error("unknown option " + pc::quote_input(flag) +
                        " (usage: [--frames N] [--size WxH] [--level L] [--aggressive] [--backpatch-open])");
        if (i + 1 >= argc) setup_error(flag + ": missing value");
        const std::string value = argv[++i];
        if (flag == "--frames" && !parse_int(value, 1, 1000, o.frames))
            setup_error("--frames: expected an integer in 1..1000, got " + pc::quote_input(value));
        if (flag == "--level" && !parse_int(value, 1, 6, o.level))
            setup_error("--level: expected an integer in 1..6, got " + pc::quote_input(value));
        if (flag == "--size") {
            const std::size_t x = value.find('x');
            if (x == std::string::npos || !parse_int(value.substr(0, x), 1, 8192, o.width) ||
                !parse_int(value.substr(x + 1), 1, 8192, o.height))
                setup_error("--size: expected WIDTHxHEIGHT, each in 1..8192, got " + pc::quote_input(value));
        }
    }
    return o;
}

// ---- the engine's OpenSubdiv side (no patchcull here) -------------------------------------------

// A vertex as Far's PrimvarRefiner and StencilTable interpolate it; also the GL vertex layout.
struct Point {
    float x = 0, y = 0, z = 0;
    void Clear(void* = nullptr) { x = y = z = 0; }
    void AddWithWeight(const Point& p, float w) {
        x += w * p.x;
        y += w * p.y;
        z += w * p.z;
    }
};

struct Mesh {
    std::vector<Point> points;  // y up: floor at y = 0, rim at y = 2, x and z in [-1.5, 1.5]
    std::vector<int> face_sizes, face_vertices, crease_pairs, corners;
    std::vector<float> crease_weights, corner_weights;
};

// The open box, faces counter-clockwise seen from outside. Rings r = 0, 1, 2 (y = r) of 12 points
// around the square walk its perimeter (ring point k is vertex 12 r + k); 4 more points fill the floor.
Mesh make_open_box() {
    Mesh m;
    const float side[12][2] = {{-1.5f, -1.5f}, {-0.5f, -1.5f}, {0.5f, -1.5f}, {1.5f, -1.5f},
                               {1.5f, -0.5f},  {1.5f, 0.5f},   {1.5f, 1.5f},  {0.5f, 1.5f},
                               {-0.5f, 1.5f},  {-1.5f, 1.5f},  {-1.5f, 0.5f}, {-1.5f, -0.5f}};
    for (int r = 0; r < 3; ++r)
        for (const auto& s : side) m.points.push_back({s[0], static_cast<float>(r), s[1]});
    for (float z : {-0.5f, 0.5f})
        for (float x : {-0.5f, 0.5f}) m.points.push_back({x, 0, z});
    const auto quad = [&m](int a, int b, int c, int d) {
        m.face_sizes.push_back(4);
        m.face_vertices.insert(m.face_vertices.end(), {a, b, c, d});
    };
    for (int r = 0; r < 2; ++r)  // walls
        for (int k = 0; k < 12; ++k)
            quad(12 * r + (k + 1) % 12, 12 * r + k, 12 * r + 12 + k, 12 * r + 12 + (k + 1) % 12);
    const auto floor_point = [&m](int i, int j) {  // the y = 0 vertex at x = i - 1.5, z = j - 1.5
        for (int v = 0; v < static_cast<int>(m.points.size()); ++v)
            if (m.points[v].y == 0 && m.points[v].x == i - 1.5f && m.points[v].z == j - 1.5f) return v;
        return -1;
    };
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i)
            quad(floor_point(i, j), floor_point(i + 1, j), floor_point(i + 1, j + 1), floor_point(i, j + 1));
    for (int k = 0; k < 12; ++k) {  // the floor seam: semi-sharp
        m.crease_pairs.insert(m.crease_pairs.end(), {k, (k + 1) % 12});
        m.crease_weights.push_back(2.0f);
    }
    for (int r = 0; r < 2; ++r) {  // the vertical edge at x = z = 1.5: infinitely sharp
        m.crease_pairs.insert(m.crease_pairs.end(), {12 * r + 3, 12 * r + 15});
        m.crease_weights.push_back(Sdc::Crease::SHARPNESS_INFINITE);
    }
    m.corners.push_back(24 + 9);  // the rim's corner at x = -1.5, z = 1.5: sharp
    m.corner_weights.push_back(Sdc::Crease::SHARPNESS_INFINITE);
    return m;
}

// What the engine keeps: Far's adaptive table and every point its indices name (every refined
// level's vertices, then the table's local points, e.g. the Gregory end caps' points).
struct OsdMesh {
    std::unique_ptr<Far::PatchTable> table;
    std::vector<Point> points;
};

OsdMesh refine_adaptively(const Mesh& mesh, int level) {
    Far::TopologyDescriptor d;
    d.numVertices = static_cast<int>(mesh.points.size());
    d.numFaces = static_cast<int>(mesh.face_sizes.size());
    d.numVertsPerFace = mesh.face_sizes.data();
    d.vertIndicesPerFace = mesh.face_vertices.data();
    d.numCreases = static_cast<int>(mesh.crease_weights.size());
    d.creaseVertexIndexPairs = mesh.crease_pairs.data();
    d.creaseWeights = mesh.crease_weights.data();
    d.numCorners = static_cast<int>(mesh.corner_weights.size());
    d.cornerVertexIndices = mesh.corners.data();
    d.cornerWeights = mesh.corner_weights.data();
    Sdc::Options sdc;
    sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
    using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
    std::unique_ptr<Far::TopologyRefiner> refiner(Factory::Create(d, Factory::Options(Sdc::SCHEME_CATMARK, sdc)));
    if (!refiner) setup_error("OpenSubdiv: the box's topology was rejected");
    // REGULAR B-spline patches and Gregory-basis end caps (the two types the gl_osd draw takes),
    // no single-crease patches (Far's default).
    Far::PatchTableFactory::Options options(static_cast<unsigned>(level));
    options.SetEndCapType(Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
    refiner->RefineAdaptive(options.GetRefineAdaptiveOptions());
    OsdMesh out;
    out.table.reset(Far::PatchTableFactory::Create(*refiner, options));
    const int refined = refiner->GetNumVerticesTotal();
    out.points.resize(static_cast<std::size_t>(refined + out.table->GetNumLocalPoints()));
    std::copy(mesh.points.begin(), mesh.points.end(), out.points.begin());
    Far::PrimvarRefiner primvar(*refiner);
    Point* src = out.points.data();
    for (int l = 1; l <= refiner->GetMaxLevel(); ++l) {
        Point* dst = src + refiner->GetLevel(l - 1).GetNumVertices();
        primvar.Interpolate(l, src, dst);
        src = dst;
    }
    if (const Far::StencilTable* local = out.table->GetLocalPointStencilTable())
        local->UpdateValues(out.points.data(), out.points.data() + refined);
    return out;
}

// ---- the camera ---------------------------------------------------------------------------------

// Three positions, orbiting 5 degrees a frame: low at the side (the near wall hides the floor and
// the far wall: occlusion), high above one corner looking in (the far side outside the frustum; the
// insides of the far walls face the eye, which --backpatch-open gets wrong), and from below.
pc::gl_osd::OsdView camera(int frame, int frames_per_position, float aspect) {
    struct Position {
        float azimuth, elevation, distance;
        pc::Vec3 target;
    };
    const Position positions[] = {
        {20, 4, 7, {0, 1.0f, 0}}, {60, 60, 3.5f, {0.9f, 0.5f, 0.9f}}, {-70, -35, 7, {0, 1, 0}}};
    const Position& p = positions[frame / frames_per_position];
    const float deg = 3.14159265f / 180;
    const float azimuth = (p.azimuth + 5.0f * static_cast<float>(frame % frames_per_position)) * deg;
    const float elevation = p.elevation * deg;
    pc::gl_osd::OsdView v;
    v.eye = p.target + pc::Vec3{std::cos(elevation) * std::cos(azimuth), std::sin(elevation),
                                std::cos(elevation) * std::sin(azimuth)} *
                           p.distance;
    v.model_view = pc::look_at(v.eye, p.target, {0, 1, 0});  // the box is in world space
    v.depth = pc::ClipDepth::zero_to_one;                    // glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE)
    v.projection = pc::perspective(0.9f, aspect, 0.1f, 50.0f, v.depth);
    v.tess_level = 4;     // OpenSubdiv's uniform tessellation level
    v.one_sided = false;  // open: two-sided
    return v;
}

// ---- the engine's frame -------------------------------------------------------------------------

void check_gl(const char* where) {
    if (const GLenum e = glGetError(); e != GL_NO_ERROR) setup_error("GL: error " + std::to_string(e) + " " + where);
}

int run(const Options& options) {
    // 1. The engine's mesh and its OpenSubdiv table (on the CPU, before any window opens).
    const OsdMesh osd = refine_adaptively(make_open_box(), options.level);

    // 2. The engine's window and context: GLFW, OpenGL 4.5 core. The window only carries the
    //    context: OpenSubdiv's programs here write patch ids, which the program reads back.
    glfwSetErrorCallback(remember_glfw_error);
    if (!glfwInit()) setup_error("GLFW: cannot start: " + g_glfw_error + " (no X display? run under xvfb-run)");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
    GLFWwindow* window = glfwCreateWindow(64, 64, "OpenSubdiv patch table in your engine", nullptr, nullptr);
    if (!window) setup_error("GLFW: no OpenGL 4.5 core context: " + g_glfw_error);
    glfwMakeContextCurrent(window);
    if (epoxy_gl_version() < 45) setup_error("GL: the context is not OpenGL 4.5");

    // 3. The engine's GL objects: the points in a vertex buffer (float3, stride 12), and the table
    //    on the GPU with OpenSubdiv's programs (Osd::GLPatchTable: index buffer, patch-param
    //    texture buffer, patch arrays; the TCS with patchcull's five lines).
    pc::gl::PassContext passes;  // patchcull's program cache on this context
    const pc::gl_osd::OsdPatchTableDraw draw(passes, *osd.table);
    GLuint vertex_buffer = 0;
    glCreateBuffers(1, &vertex_buffer);
    glNamedBufferStorage(vertex_buffer, static_cast<GLsizeiptr>(osd.points.size() * sizeof(Point)), osd.points.data(),
                         0);
    const pc::gl_osd::OsdVertexBuffer vertices{vertex_buffer, sizeof(Point), 0, osd.points.size()};
    //    Framebuffer: patch ids (R32UI, output 0 of the draw) and DEPTH32F (what HiZBuildPass reads).
    const int w = options.width, h = options.height;
    GLuint ids = 0, depth = 0, fbo = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &ids);
    glTextureStorage2D(ids, 1, GL_R32UI, w, h);
    glCreateTextures(GL_TEXTURE_2D, 1, &depth);
    glTextureStorage2D(depth, 1, GL_DEPTH_COMPONENT32F, w, h);
    glCreateFramebuffers(1, &fbo);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, ids, 0);
    glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, depth, 0);
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);  // the views' depth convention
    glViewport(0, 0, w, h);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);

    // 4. What patchcull adds: the flag buffer (a uint per patch in Far's order; the first frame
    //    has no previous one, so the even patches start tagged visible, Niessner & Loop §3), the
    //    counters, the Hi-Z pyramid, the passes, and one GpuPatchSource per patch array over the
    //    engine's vertex buffer and the table's index buffer (B-spline arrays with their boundary
    //    masks, Gregory-basis arrays with their 20 points).
    const std::size_t n = draw.patch_count();
    std::vector<std::uint32_t> words(n, 0);
    for (std::size_t p = 0; p < n; p += 2) words[p] = sh::kStatusVisible;
    GLuint flags = 0, counters = 0;
    glCreateBuffers(1, &flags);
    glNamedBufferStorage(flags, static_cast<GLsizeiptr>(n * sizeof(std::uint32_t)), words.data(), 0);
    glCreateBuffers(1, &counters);
    glNamedBufferStorage(counters, sh::kCounterCount * sizeof(std::uint32_t), nullptr, GL_DYNAMIC_STORAGE_BIT);
    pc::gl::HiZTexture hiz = pc::gl::create_hiz_texture(w, h);
    pc::gl::HiZBuildPass hiz_build(passes);
    pc::gl::CullStatusPass status(passes);
    pc::gl::FrustumPass frustum(passes);
    pc::gl::OcclusionPass occlusion(passes);
    pc::gl::BackpatchConePass backpatch(passes);  // --backpatch-open only
    const std::vector<pc::gl::GpuPatchSource> sources = draw.sources(vertices, flags);
    const pc::gl::PatchBuffers all{0, flags, 0, 0, n};  // every array's flags: one range
    check_gl("while setting up");

    std::size_t gregory = 0;
    for (const pc::gl::GpuPatchSource& s : sources) gregory += s.basis == pc::PatchBasis::gregory ? s.count : 0;
    std::printf(
        "%s: %zu patches (%zu B-spline, %zu Gregory-basis end caps) at isolation level %d, %dx%d, %d frames at 3 "
        "camera positions%s%s\n",
        reinterpret_cast<const char*>(glGetString(GL_RENDERER)), n, n - gregory, gregory, options.level, w, h,
        3 * options.frames, options.aggressive ? ", pass 2 skipped" : "",
        options.backpatch_open ? ", back-patch tcone on the open box" : "");
    const auto clear = [&] {
        const GLuint background = 0;
        const float far_depth = 1;
        glClearNamedFramebufferuiv(fbo, GL_COLOR, 0, &background);
        glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &far_depth);
    };
    const auto read_ids = [&] {
        std::vector<std::uint32_t> out(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
        glGetTextureImage(ids, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, static_cast<GLsizei>(4 * out.size()), out.data());
        return out;
    };
    const int frames = 3 * options.frames;
    int mismatched = 0;
    std::size_t total_frustum = 0, total_occlusion = 0;
    for (int f = 0; f < frames; ++f) {
        const pc::gl_osd::OsdView view = camera(f, options.frames, static_cast<float>(w) / static_cast<float>(h));
        const pc::CullView cv = view.cull_view();
        glClearNamedBufferData(counters, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);

        // Pass 1: the engine's draw, restricted to the patches the previous frame tagged visible.
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        clear();
        draw.draw(vertices, flags, sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass, view);
        // Hi-Z pyramid of pass 1's depth (not bound to the framebuffer while it is read).
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        hiz_build.run(depth, hiz, view.depth);
        // The flag chain over every patch array: each pass skips what an earlier one culled.
        status.begin(all);
        for (const pc::gl::GpuPatchSource& s : sources) frustum.run(s, cv);
        if (options.backpatch_open)  // NOT conservative on an open surface (see the top)
            for (const pc::gl::GpuPatchSource& s : sources) backpatch.run(s, pc::gl::BackpatchMethod::tcone, cv.eye);
        for (const pc::gl::GpuPatchSource& s : sources) occlusion.run(s, cv, hiz, /*with_frustum=*/false);
        status.end(all, counters);
        // Pass 2: the patches that passed and were not drawn in pass 1, into the same targets.
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        if (!options.aggressive) draw.draw(vertices, flags, sh::kDrawMaskSecondPass, sh::kDrawValueSecondPass, view);
        const std::vector<std::uint32_t> culled_ids = read_ids();
        std::uint32_t c[sh::kCounterCount] = {};
        glGetNamedBufferSubData(counters, 0, sizeof c, c);

        // The check: the same view, every patch (selection 0, 0), must give the same ids.
        clear();
        draw.draw(vertices, flags, 0, 0, view);
        const std::vector<std::uint32_t> reference_ids = read_ids();
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        check_gl("in a frame");
        std::size_t differing = 0;
        for (std::size_t i = 0; i < reference_ids.size(); ++i) differing += culled_ids[i] != reference_ids[i];
        mismatched += differing != 0;
        total_frustum += c[sh::kCounterFrustum];
        total_occlusion += c[sh::kCounterOcclusion];
        const std::string verdict = differing ? "IDS DIFFER in " + std::to_string(differing) + " pixels" : "ids match";
        std::printf(
            "frame %d (camera %d): culled frustum %u, back-patch %u, occlusion %u; drawn pass 1 %u, pass 2 %u%s; %s\n",
            f, f / options.frames, c[sh::kCounterFrustum], c[sh::kCounterBackPatch], c[sh::kCounterOcclusion],
            c[sh::kCounterWasVisible], c[sh::kCounterNewlyVisible], options.aggressive ? " (skipped)" : "",
            verdict.c_str());
        std::fflush(stdout);
    }

    glDeleteTextures(1, &hiz.texture);
    const GLuint textures[] = {ids, depth};
    glDeleteTextures(2, textures);
    const GLuint buffers[] = {vertex_buffer, flags, counters};
    glDeleteBuffers(3, buffers);
    glDeleteFramebuffers(1, &fbo);
    // The passes and the draw (destroyed at scope end) need the context: the window goes after them.
    if (mismatched) {
        std::printf("FAILED: %d of %d frames differ from the unculled draw\n", mismatched, frames);
        return 1;
    }
    if (total_frustum == 0 || total_occlusion == 0) {
        std::printf("FAILED: %s culled nothing over the run, so the check proved nothing about it\n",
                    total_frustum == 0 ? "FrustumPass" : "OcclusionPass");
        return 1;
    }
    std::printf("all %d frames match the unculled draw (patch-frames culled: %zu frustum, %zu occlusion)\n", frames,
                total_frustum, total_occlusion);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    int status = 2;
    try {
        status = run(parse_options(argc, argv));
    } catch (const SetupError& e) {
        std::fprintf(stderr, "%s\n", pc::printable_line(e.message).c_str());
    } catch (const std::exception& e) {  // patchcull::Error from the gl_osd layer or a pass: one line
        std::fprintf(stderr, "%s\n", pc::printable_line(e.what()).c_str());
    }
    glfwTerminate();  // after every GL object and pass is gone
    return status;
}
