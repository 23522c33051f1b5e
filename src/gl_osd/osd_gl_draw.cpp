// OpenSubdiv's patch table drawn with OpenSubdiv's GLSL, culled by patchcull's passes
// (patchcull/gl_osd/osd_gl_draw.h).
//
// Facts about OpenSubdiv 3.5 used here (osd/glPatchTable.cpp, osd/glslPatchShaderSource.cpp,
// osd/glslPatchCommon.glsl, glslPatchBSpline.glsl, glslPatchGregoryBasis.glsl): GLPatchTable
// loads its GL functions itself (libGL.so.1 through glXGetProcAddressARB, which glvnd resolves
// for whichever context is current, EGL's included) and holds one index buffer of int indices
// (the arrays' runs in order, PatchArray::GetIndexBase() the first of each) and an RGB32I
// texture buffer of patch params indexed by Far's patch index; the stage sources expect the
// client to define OsdModelViewMatrix(), OsdProjectionMatrix(), OsdModelViewProjectionMatrix(),
// OsdTessLevel(), OsdGregoryQuadOffsetBase(), OsdPrimitiveIdBase() and OsdBaseVertex(); the
// TCS of both patch types calls OSD_PATCH_CULL(N) in invocation 0 before its level writes, a
// macro the common source defines unconditionally (so it is redefined after it), and the TES
// ends with OSD_DISPLACEMENT_CALLBACK after writing outpt.v.position and outpt.v.normal (eye
// space, the normal through the model-view matrix with w = 0).
#include <epoxy/gl.h>  // before OpenSubdiv's osd/opengl.h (GL/gl.h)

#include "patchcull/gl_osd/osd_gl_draw.h"

#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/osd/glPatchTable.h>
#include <opensubdiv/osd/glslPatchShaderSource.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <string>
#include <utility>

#include "patchcull/core/error.h"
#include "patchcull/import/osd_patch_table.h"
#include "shared.h"

namespace patchcull::gl_osd {

namespace {

namespace Far = OpenSubdiv::Far;
namespace Osd = OpenSubdiv::Osd;
namespace sh = gl::shared;

void check_gl(const char* what) {
    const GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        char hex[16];
        std::snprintf(hex, sizeof hex, "0x%04X", static_cast<unsigned>(e));
        throw Error(std::string("GL: error ") + hex + " " + what);
    }
}

// The client header: the functions OpenSubdiv's stages call, and patchcull's hooks per stage.
std::string client_header() {
    return R"(
uniform mat4 ModelViewMatrix;
uniform mat4 ProjectionMatrix;
uniform float TessLevel;
uniform int PrimitiveIdBase;
mat4 OsdModelViewMatrix() { return ModelViewMatrix; }
mat4 OsdProjectionMatrix() { return ProjectionMatrix; }
mat4 OsdModelViewProjectionMatrix() { return ProjectionMatrix * ModelViewMatrix; }
float OsdTessLevel() { return TessLevel; }
int OsdGregoryQuadOffsetBase() { return 0; }
int OsdPrimitiveIdBase() { return PrimitiveIdBase; }
int OsdBaseVertex() { return 0; }
#if defined(PC_OSD_TESS_CONTROL) && !defined(OSD_ENABLE_PATCH_CULL)
uniform uint u_draw_mask, u_draw_value;
patch out int pc_patch;
#undef OSD_PATCH_CULL
#define OSD_PATCH_CULL(N)                          \
    pc_patch = OsdGetPatchIndex(gl_PrimitiveID);   \
    PATCHCULL_RETURN_UNLESS_DRAWN(pc_patch, u_draw_mask, u_draw_value)
#endif
#if defined(PC_OSD_TESS_CONTROL) && defined(OSD_ENABLE_PATCH_CULL)
// OpenSubdiv's OSD_PATCH_CULL(N) stays; patchcull's check runs earlier, in the per-control-point
// hook (every invocation, before OpenSubdiv's invocation-0 block; no barrier in between).
uniform uint u_draw_mask, u_draw_value;
patch out int pc_patch;
#undef OSD_USER_VARYING_PER_CONTROL_POINT
#define OSD_USER_VARYING_PER_CONTROL_POINT(ID_OUT, ID_IN)                           \
    if (gl_InvocationID == 0) {                                                     \
        pc_patch = OsdGetPatchIndex(gl_PrimitiveID);                                \
        PATCHCULL_RETURN_UNLESS_DRAWN(pc_patch, u_draw_mask, u_draw_value)          \
    }
#endif
#ifdef PC_OSD_TESS_EVAL
patch in int pc_patch;
flat out int pc_id;
out float pc_facing;
// The cosine between the normal and the direction to the eye (eye space: the eye at 0).
float pc_cosine(vec3 p, vec3 n) { return dot(n, -p) / (length(n) * length(p)); }
#ifdef PC_OSD_RECORD_TESSELLATED
layout(std430, binding = PC_OSD_RECORD_TESSELLATED) writeonly buffer PcTessellated { uint pc_tessellated[]; };
#define PC_RECORD() pc_tessellated[pc_patch] = 1u
#else
#define PC_RECORD()
#endif
#undef OSD_DISPLACEMENT_CALLBACK
#define OSD_DISPLACEMENT_CALLBACK \
    pc_id = pc_patch;             \
    pc_facing = pc_cosine(outpt.v.position.xyz, outpt.v.normal); \
    PC_RECORD()
#endif
)";
}

const char* const kFragmentMain = R"(
flat in int pc_id;
in float pc_facing;
uniform int u_one_sided;
layout(location = 0) out uint pc_out_id;
void main() {
    if (u_one_sided != 0 && !(pc_facing > kFrontFacingMinCosine)) discard;
    pc_out_id = uint(pc_id + 1);
}
)";

GLuint compile(GLenum stage, const std::string& text, const char* what) {
    const GLuint s = glCreateShader(stage);
    const char* src = text.c_str();
    glShaderSource(s, 1, &src, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        std::string log(4096, '\0');
        glGetShaderInfoLog(s, static_cast<GLsizei>(log.size()), nullptr, log.data());
        glDeleteShader(s);
        throw Error(std::string("GL: OpenSubdiv ") + what +
                    " shader rejected: " + printable_line(log.substr(0, log.find('\0'))));
    }
    return s;
}

// One program for a patch type: OpenSubdiv's stages composed as its examples compose them.
GLuint build_program(Far::PatchDescriptor::Type type, const OsdDrawOptions& options) {
    std::string version = "#version 450\n";
    if (options.opensubdiv_patch_cull) version += "#define OSD_ENABLE_PATCH_CULL\n";
    if (options.record_tessellated)
        version += "#define PC_OSD_RECORD_TESSELLATED " + std::to_string(sh::kBindingOsdTessellated) + "\n";
    const std::string common = "#define OSD_PATCH_BASIS_GLSL\n" +
                               Osd::GLSLPatchShaderSource::GetPatchBasisShaderSource() +
                               Osd::GLSLPatchShaderSource::GetCommonShaderSource();
    const std::string shared(gl::shipped_glsl("shared.h"));
    const std::string tcs_include(gl::shipped_glsl("patchcull_tcs.h"));
    const std::string header = client_header();
    const std::array<GLuint, 4> shaders = {
        compile(GL_VERTEX_SHADER, version + common + header + Osd::GLSLPatchShaderSource::GetVertexShaderSource(type),
                "vertex"),
        compile(GL_TESS_CONTROL_SHADER,
                version + "#define PC_OSD_TESS_CONTROL\n" + common + shared + tcs_include + header +
                    Osd::GLSLPatchShaderSource::GetTessControlShaderSource(type),
                "tessellation control"),
        compile(GL_TESS_EVALUATION_SHADER,
                version + "#define PC_OSD_TESS_EVAL\n" + common + header +
                    Osd::GLSLPatchShaderSource::GetTessEvalShaderSource(type),
                "tessellation evaluation"),
        compile(GL_FRAGMENT_SHADER, version + shared + kFragmentMain, "fragment")};
    const GLuint program = glCreateProgram();
    for (GLuint s : shaders) glAttachShader(program, s);
    glLinkProgram(program);
    for (GLuint s : shaders) glDeleteShader(s);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
        std::string log(4096, '\0');
        glGetProgramInfoLog(program, static_cast<GLsizei>(log.size()), nullptr, log.data());
        glDeleteProgram(program);
        throw Error("GL: OpenSubdiv patch program rejected: " + printable_line(log.substr(0, log.find('\0'))));
    }
    return program;
}

struct Program {
    GLuint name = 0;
    GLint model_view = -1, projection = -1, tess_level = -1, primitive_id_base = -1, mask = -1, value = -1,
          one_sided = -1;
};

Program make_program(Far::PatchDescriptor::Type type, const OsdDrawOptions& options) {
    Program p;
    p.name = build_program(type, options);
    p.model_view = glGetUniformLocation(p.name, "ModelViewMatrix");
    p.projection = glGetUniformLocation(p.name, "ProjectionMatrix");
    p.tess_level = glGetUniformLocation(p.name, "TessLevel");
    p.primitive_id_base = glGetUniformLocation(p.name, "PrimitiveIdBase");
    p.mask = glGetUniformLocation(p.name, "u_draw_mask");
    p.value = glGetUniformLocation(p.name, "u_draw_value");
    p.one_sided = glGetUniformLocation(p.name, "u_one_sided");
    const GLint params = glGetUniformLocation(p.name, "OsdPatchParamBuffer");
    if (params >= 0) glProgramUniform1i(p.name, params, static_cast<GLint>(sh::kTextureUnitOsdPatchParam));
    return p;
}

}  // namespace

struct OsdPatchTableDraw::Impl {
    struct Array {
        Far::PatchDescriptor::Type type;
        int control_vertices = 16;
        std::size_t patches = 0, index_base = 0, first_patch = 0;
        bool has_masks = false;
    };
    std::unique_ptr<Osd::GLPatchTable> table;
    std::vector<Array> arrays;
    GLuint masks = 0, vao = 0, tessellated = 0;
    Program bspline, gregory;
    std::size_t patch_count = 0, points_needed = 0;
    bool software = false;

    ~Impl() {
        for (GLuint p : {bspline.name, gregory.name})
            if (p) glDeleteProgram(p);
        for (GLuint b : {masks, tessellated})
            if (b) glDeleteBuffers(1, &b);
        if (vao) glDeleteVertexArrays(1, &vao);
    }
};

OsdPatchTableDraw::OsdPatchTableDraw(gl::PassContext& passes, const Far::PatchTable& table,
                                     const OsdDrawOptions& options)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.software = passes.is_software();
    const Far::PatchTable::PatchVertsTable& all_indices = table.GetPatchControlVerticesTable();
    std::vector<std::uint8_t> masks;
    bool any_bspline = false, any_gregory = false;
    std::size_t first = 0;
    for (int a = 0; a < table.GetNumPatchArrays(); ++a) {
        const Far::PatchDescriptor desc = table.GetPatchArrayDescriptor(a);
        Impl::Array array;
        array.type = desc.GetType();
        array.control_vertices = desc.GetNumControlVertices();
        array.patches = static_cast<std::size_t>(table.GetNumPatches(a));
        array.first_patch = first;
        if (array.type != Far::PatchDescriptor::REGULAR && array.type != Far::PatchDescriptor::GREGORY_BASIS)
            throw Error("OpenSubdiv patch table: array " + std::to_string(a) + " holds " +
                        osd_patch_type_name(array.type) + " patches (only REGULAR and GREGORY_BASIS are drawn)");
        const Far::ConstIndexArray cvs = table.GetPatchArrayVertices(a);
        array.index_base = static_cast<std::size_t>(&cvs[0] - &all_indices[0]);
        masks.resize(first + array.patches, 0);
        for (std::size_t i = 0; i < array.patches; ++i) {
            const Far::PatchParam param = table.GetPatchParam(a, static_cast<int>(i));
            const int boundary = array.type == Far::PatchDescriptor::REGULAR ? param.GetBoundary() : 0;
            masks[first + i] = static_cast<std::uint8_t>(boundary);
            array.has_masks |= boundary != 0;
            // The slots a patch reads (REGULAR: phantom slots beyond its boundary edges are not).
            const std::uint32_t real = array.type == Far::PatchDescriptor::REGULAR
                                           ? bspline_real_slots(static_cast<std::uint8_t>(boundary & 15))
                                           : 0xFFFFFu;
            for (int k = 0; k < array.control_vertices; ++k) {
                if (!((real >> k) & 1u)) continue;
                const int index = cvs[static_cast<int>(i) * array.control_vertices + k];
                if (index < 0)
                    throw Error("OpenSubdiv patch table: array " + std::to_string(a) + ", patch " + std::to_string(i) +
                                ": negative index in slot " + std::to_string(k));
                m.points_needed = std::max(m.points_needed, static_cast<std::size_t>(index) + 1);
            }
        }
        (array.type == Far::PatchDescriptor::REGULAR ? any_bspline : any_gregory) = true;
        first += array.patches;
        m.arrays.push_back(array);
    }
    m.patch_count = first;
    masks.resize((masks.size() + 3) / 4 * 4 + 4, 0);

    m.table.reset(Osd::GLPatchTable::Create(&table));
    if (!m.table) throw Error("GL: Osd::GLPatchTable::Create failed");
    check_gl("after Osd::GLPatchTable::Create");
    glCreateBuffers(1, &m.masks);
    glNamedBufferStorage(m.masks, static_cast<GLsizeiptr>(masks.size()), masks.data(), 0);
    glCreateVertexArrays(1, &m.vao);
    glVertexArrayElementBuffer(m.vao, m.table->GetPatchIndexBuffer());
    glVertexArrayAttribFormat(m.vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(m.vao, 0, 0);
    glEnableVertexArrayAttrib(m.vao, 0);
    if (any_bspline) m.bspline = make_program(Far::PatchDescriptor::REGULAR, options);
    if (any_gregory) m.gregory = make_program(Far::PatchDescriptor::GREGORY_BASIS, options);
    if (options.record_tessellated) {
        glCreateBuffers(1, &m.tessellated);
        glNamedBufferStorage(m.tessellated, static_cast<GLsizeiptr>(4 * std::max<std::size_t>(m.patch_count, 1)),
                             nullptr, GL_DYNAMIC_STORAGE_BIT);
        clear_tessellated();
    }
    check_gl("after building the OpenSubdiv patch programs");
}

OsdPatchTableDraw::OsdPatchTableDraw(OsdPatchTableDraw&&) noexcept = default;
OsdPatchTableDraw& OsdPatchTableDraw::operator=(OsdPatchTableDraw&&) noexcept = default;
OsdPatchTableDraw::~OsdPatchTableDraw() = default;

std::size_t OsdPatchTableDraw::patch_count() const { return impl_->patch_count; }
std::size_t OsdPatchTableDraw::points_needed() const { return impl_->points_needed; }

void OsdPatchTableDraw::clear_tessellated() const {
    if (!impl_->tessellated) throw Error("OsdPatchTableDraw: built without record_tessellated");
    const GLuint zero = 0;
    glClearNamedBufferData(impl_->tessellated, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
}

std::size_t OsdPatchTableDraw::tessellated_count() const {
    if (!impl_->tessellated) throw Error("OsdPatchTableDraw: built without record_tessellated");
    std::vector<std::uint32_t> words(impl_->patch_count);
    glGetNamedBufferSubData(impl_->tessellated, 0, static_cast<GLsizeiptr>(4 * words.size()), words.data());
    check_gl("after reading the tessellated patches");
    return static_cast<std::size_t>(std::count_if(words.begin(), words.end(), [](std::uint32_t w) { return w != 0; }));
}

namespace {

void check_view(const OsdView& view) {
    if (!(view.tess_level >= 1 && view.tess_level <= 16))
        throw Error("OsdView: tess_level " + std::to_string(view.tess_level) + " is not in [1, 16]");
}

void check_vertices(const OsdVertexBuffer& v, std::size_t needed) {
    if (v.buffer == 0) throw Error("OsdVertexBuffer: no buffer");
    if (v.stride_bytes % 4 != 0 || v.offset_bytes % 4 != 0)
        throw Error("OsdVertexBuffer: stride " + std::to_string(v.stride_bytes) + " and offset " +
                    std::to_string(v.offset_bytes) + " must be multiples of 4");
    if (v.stride_bytes < v.offset_bytes + 12)
        throw Error("OsdVertexBuffer: stride " + std::to_string(v.stride_bytes) + " leaves no room for x, y, z at " +
                    std::to_string(v.offset_bytes));
    if (v.point_count < needed)
        throw Error("OsdVertexBuffer: " + std::to_string(v.point_count) + " points, the table reads " +
                    std::to_string(needed));
}

}  // namespace

std::vector<gl::GpuPatchSource> OsdPatchTableDraw::sources(const OsdVertexBuffer& vertices, std::uint32_t flags) const {
    const Impl& m = *impl_;
    check_vertices(vertices, m.points_needed);
    std::vector<gl::GpuPatchSource> out;
    for (const Impl::Array& a : m.arrays) {
        gl::GpuPatchSource s;
        s.vertices = vertices.buffer;
        s.stride_bytes = vertices.stride_bytes;
        s.offset_bytes = vertices.offset_bytes;
        s.components = 3;
        s.point_count = vertices.point_count;
        s.basis = a.type == Far::PatchDescriptor::REGULAR ? PatchBasis::bspline : PatchBasis::gregory;
        s.indices = m.table->GetPatchIndexBuffer();
        s.indices_offset_bytes = 4 * a.index_base;
        if (a.has_masks) {
            s.boundary_masks = m.masks;
            s.masks_offset_bytes = a.first_patch;
        }
        s.flags = flags;
        s.first = a.first_patch;
        s.count = a.patches;
        s.source_first = 0;
        out.push_back(s);
    }
    return out;
}

void OsdPatchTableDraw::draw(const OsdVertexBuffer& vertices, std::uint32_t flags, std::uint32_t mask,
                             std::uint32_t value, const OsdView& view) const {
    const Impl& m = *impl_;
    check_vertices(vertices, m.points_needed);
    check_view(view);
    glVertexArrayVertexBuffer(m.vao, 0, vertices.buffer, static_cast<GLintptr>(vertices.offset_bytes),
                              static_cast<GLsizei>(vertices.stride_bytes));
    glBindVertexArray(m.vao);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingCullFlags, flags);
    glBindTextureUnit(sh::kTextureUnitOsdPatchParam, m.table->GetPatchParamTextureBuffer());
    if (m.tessellated) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingOsdTessellated, m.tessellated);
    for (const Impl::Array& a : m.arrays) {
        if (a.patches == 0) continue;
        const Program& p = a.type == Far::PatchDescriptor::REGULAR ? m.bspline : m.gregory;
        glUseProgram(p.name);
        glUniformMatrix4fv(p.model_view, 1, GL_FALSE, view.model_view.m);
        glUniformMatrix4fv(p.projection, 1, GL_FALSE, view.projection.m);
        glUniform1f(p.tess_level, view.tess_level);
        glUniform1ui(p.mask, mask);
        glUniform1ui(p.value, value);
        glUniform1i(p.one_sided, view.one_sided ? 1 : 0);
        glPatchParameteri(GL_PATCH_VERTICES, a.control_vertices);
        // llvmpipe restarts gl_PrimitiveID every 1024 / n patches of an indexed draw.
        const std::size_t n = static_cast<std::size_t>(a.control_vertices);
        const std::size_t step = m.software ? 1024 / n : a.patches;
        for (std::size_t at = 0; at < a.patches; at += step) {
            const std::size_t count = std::min(step, a.patches - at);
            glUniform1i(p.primitive_id_base, static_cast<GLint>(a.first_patch + at));
            glDrawElements(GL_PATCHES, static_cast<GLsizei>(count * n), GL_UNSIGNED_INT,
                           reinterpret_cast<const void*>(4 * (a.index_base + at * n)));
        }
    }
    glUseProgram(0);
    glBindVertexArray(0);
    check_gl("after drawing the OpenSubdiv patch table");
}

// ---- The frame ----------------------------------------------------------------------------------

struct OsdCullFrame::Impl {
    const OsdPatchTableDraw* draw = nullptr;
    int width = 0, height = 0;
    GLuint fbo = 0, ids = 0, depth = 0, flags = 0, counters = 0;
    gl::HiZTexture hiz;
    gl::CullStatusPass status;
    gl::FrustumPass frustum;
    gl::BackpatchConePass cones;
    gl::BackpatchPtpPass ptp;
    gl::OcclusionPass occlusion;
    gl::HiZBuildPass hiz_build;

    explicit Impl(gl::PassContext& passes)
        : status(passes), frustum(passes), cones(passes), ptp(passes), occlusion(passes), hiz_build(passes) {}
    ~Impl() {
        if (fbo) glDeleteFramebuffers(1, &fbo);
        for (GLuint t : {ids, depth, hiz.texture})
            if (t) glDeleteTextures(1, &t);
        for (GLuint b : {flags, counters})
            if (b) glDeleteBuffers(1, &b);
    }

    // Binds the framebuffer with the view's depth convention and clears it.
    void begin_targets(ClipDepth convention) const {
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glViewport(0, 0, width, height);
        glClipControl(GL_LOWER_LEFT,
                      convention == ClipDepth::minus_one_to_one ? GL_NEGATIVE_ONE_TO_ONE : GL_ZERO_TO_ONE);
        const bool reversed = is_reversed(convention);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(reversed ? GL_GREATER : GL_LESS);
        glDepthMask(GL_TRUE);
        const GLuint zero = 0;
        const float far_depth = reversed ? 0.0f : 1.0f;
        glClearNamedFramebufferuiv(fbo, GL_COLOR, 0, &zero);
        glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &far_depth);
    }
    void end_targets() const {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
        glDepthFunc(GL_LESS);
        glDisable(GL_DEPTH_TEST);
    }
};

OsdCullFrame::OsdCullFrame(gl::PassContext& passes, const OsdPatchTableDraw& draw, int width, int height)
    : impl_(std::make_unique<Impl>(passes)) {
    if (width < 1 || width > 8192 || height < 1 || height > 8192)
        throw Error("OsdCullFrame: size " + std::to_string(width) + "x" + std::to_string(height) +
                    " is not in 1..8192 each");
    Impl& m = *impl_;
    m.draw = &draw;
    m.width = width;
    m.height = height;
    glCreateTextures(GL_TEXTURE_2D, 1, &m.ids);
    glTextureStorage2D(m.ids, 1, GL_R32UI, width, height);
    glCreateTextures(GL_TEXTURE_2D, 1, &m.depth);
    glTextureStorage2D(m.depth, 1, GL_DEPTH_COMPONENT32F, width, height);
    glCreateFramebuffers(1, &m.fbo);
    glNamedFramebufferTexture(m.fbo, GL_COLOR_ATTACHMENT0, m.ids, 0);
    glNamedFramebufferTexture(m.fbo, GL_DEPTH_ATTACHMENT, m.depth, 0);
    if (glCheckNamedFramebufferStatus(m.fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw Error("GL: the OpenSubdiv frame's framebuffer is incomplete");
    glCreateBuffers(1, &m.flags);
    glNamedBufferStorage(m.flags, static_cast<GLsizeiptr>(4 * std::max<std::size_t>(draw.patch_count(), 1)), nullptr,
                         GL_DYNAMIC_STORAGE_BIT);
    glCreateBuffers(1, &m.counters);
    glNamedBufferStorage(m.counters, 4 * sh::kCounterCount, nullptr, GL_DYNAMIC_STORAGE_BIT);
    m.hiz = gl::create_hiz_texture(width, height);
    reset();
    check_gl("after creating the OpenSubdiv frame");
}

OsdCullFrame::OsdCullFrame(OsdCullFrame&&) noexcept = default;
OsdCullFrame& OsdCullFrame::operator=(OsdCullFrame&&) noexcept = default;
OsdCullFrame::~OsdCullFrame() = default;

void OsdCullFrame::reset() {
    const Impl& m = *impl_;
    std::vector<std::uint32_t> words(std::max<std::size_t>(m.draw->patch_count(), 1), 0);
    for (std::size_t p = 0; p < words.size(); p += 2) words[p] = sh::kStatusVisible;
    glNamedBufferSubData(m.flags, 0, static_cast<GLsizeiptr>(4 * words.size()), words.data());
}

OsdFrameStats OsdCullFrame::render(const OsdVertexBuffer& vertices, const OsdView& view,
                                   const OsdCullSettings& settings) {
    Impl& m = *impl_;
    check_view(view);  // every check before any GL work
    const std::vector<gl::GpuPatchSource> sources = m.draw->sources(vertices, m.flags);
    const gl::PatchBuffers range{0, m.flags, 0, 0, m.draw->patch_count()};
    const CullView cv = view.cull_view();
    const GLuint zero = 0;
    glClearNamedBufferData(m.counters, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    const auto chain = [&] {
        m.status.begin(range);
        if (settings.frustum)
            for (const gl::GpuPatchSource& s : sources) m.frustum.run(s, cv);
        if (settings.backpatch)
            for (const gl::GpuPatchSource& s : sources) {
                if (*settings.backpatch == BackpatchMethod::ptp) {
                    m.ptp.run(s, cv.object_to_clip, cv.alpha, settings.ptp_rule);
                } else {
                    m.cones.run(s, *settings.backpatch, cv.eye);
                }
            }
        if (settings.occlusion)
            for (const gl::GpuPatchSource& s : sources) m.occlusion.run(s, cv, m.hiz, /*with_frustum=*/false);
        m.status.end(range, m.counters);
    };
    if (!settings.occlusion) {
        chain();
        m.begin_targets(view.depth);
        m.draw->draw(vertices, m.flags, sh::kDrawMaskUnculled, sh::kDrawValueUnculled, view);
        m.end_targets();
    } else {
        m.begin_targets(view.depth);
        m.draw->draw(vertices, m.flags, sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass, view);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);  // the depth texture is sampled next
        m.hiz_build.run(m.depth, m.hiz, view.depth);
        chain();
        glBindFramebuffer(GL_FRAMEBUFFER, m.fbo);
        m.draw->draw(vertices, m.flags, sh::kDrawMaskSecondPass, sh::kDrawValueSecondPass, view);
        m.end_targets();
    }
    std::uint32_t c[sh::kCounterCount] = {};
    glGetNamedBufferSubData(m.counters, 0, sizeof c, c);
    check_gl("after the OpenSubdiv frame");
    OsdFrameStats stats;
    stats.frustum = c[sh::kCounterFrustum];
    stats.backpatch = c[sh::kCounterBackPatch];
    stats.occlusion = c[sh::kCounterOcclusion];
    stats.drawn_pass1 = settings.occlusion ? c[sh::kCounterWasVisible] : c[sh::kCounterVisible];
    stats.drawn_pass2 = settings.occlusion ? c[sh::kCounterNewlyVisible] : 0;
    return stats;
}

void OsdCullFrame::render_unculled(const OsdVertexBuffer& vertices, const OsdView& view) {
    Impl& m = *impl_;
    check_view(view);
    (void)m.draw->sources(vertices, m.flags);  // checks the vertices
    m.begin_targets(view.depth);
    m.draw->draw(vertices, m.flags, 0, 0, view);
    m.end_targets();
}

std::vector<std::uint32_t> OsdCullFrame::read_ids() const {
    const Impl& m = *impl_;
    std::vector<std::uint32_t> out(static_cast<std::size_t>(m.width) * static_cast<std::size_t>(m.height));
    glGetTextureImage(m.ids, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, static_cast<GLsizei>(4 * out.size()), out.data());
    return out;
}

std::vector<float> OsdCullFrame::read_depth() const {
    const Impl& m = *impl_;
    std::vector<float> out(static_cast<std::size_t>(m.width) * static_cast<std::size_t>(m.height));
    glGetTextureImage(m.depth, 0, GL_DEPTH_COMPONENT, GL_FLOAT, static_cast<GLsizei>(4 * out.size()), out.data());
    return out;
}

std::uint32_t OsdCullFrame::flag_buffer() const { return impl_->flags; }
int OsdCullFrame::width() const { return impl_->width; }
int OsdCullFrame::height() const { return impl_->height; }

}  // namespace patchcull::gl_osd
