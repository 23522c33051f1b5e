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
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>

#include "patchcull/core/error.h"
#include "patchcull/core/render_params.h"
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
int OsdBaseVertex() { return 0; }
#ifndef PC_OSD_PULL
int OsdPrimitiveIdBase() { return PrimitiveIdBase; }
#endif
#if defined(PC_OSD_PULL) && defined(PC_OSD_VERTEX)
// The compacted draw: vertex gl_VertexID is slot gl_VertexID % n of list entry gl_VertexID / n;
// the table's index buffer names the slot's point, read from the vertex buffer as storage.
layout(std430, binding = PC_OSD_BINDING_LIST) readonly buffer PcList { uint pc_list[]; };
layout(std430, binding = PC_OSD_BINDING_INDICES) readonly buffer PcIndices { int pc_indices[]; };
layout(std430, binding = PC_OSD_BINDING_VERTICES) readonly buffer PcVertices { float pc_vertices[]; };
uniform int u_pull_first_patch, u_pull_index_base, u_pull_stride, u_pull_offset, u_pull_points;
out int pc_vs_patch;
int OsdPrimitiveIdBase() { return 0; }
vec4 pc_pull_point() {
    const int patch_index = int(pc_list[uint(gl_VertexID) / uint(PC_OSD_PULL)]);
    pc_vs_patch = patch_index;
    const int slot = int(uint(gl_VertexID) % uint(PC_OSD_PULL));
    const int point = pc_indices[u_pull_index_base + (patch_index - u_pull_first_patch) * PC_OSD_PULL + slot];
    if (point < 0 || point >= u_pull_points) return vec4(0.0, 0.0, 0.0, 1.0);
    const int at = point * u_pull_stride + u_pull_offset;
    return vec4(pc_vertices[at], pc_vertices[at + 1], pc_vertices[at + 2], 1.0);
}
// Called right after OpenSubdiv's vertex shader copies its (unbound) attribute.
#undef OSD_USER_VARYING_PER_VERTEX
#define OSD_USER_VARYING_PER_VERTEX()        \
    outpt.v.position = pc_pull_point();      \
    { OSD_PATCH_CULL_COMPUTE_CLIPFLAGS(outpt.v.position); }
#endif
#if defined(PC_OSD_PULL) && defined(PC_OSD_TESS_CONTROL)
// OsdGetPatchIndex(gl_PrimitiveID) is the listed patch, whatever gl_PrimitiveID is.
in int pc_vs_patch[];
int OsdPrimitiveIdBase() { return pc_vs_patch[0] - gl_PrimitiveID; }
#endif
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
#ifdef PC_OSD_PULL
int OsdPrimitiveIdBase() { return pc_patch - gl_PrimitiveID; }
#endif
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
// pull: the compacted draw's program (the client header's PC_OSD_PULL parts).
GLuint build_program(Far::PatchDescriptor::Type type, const OsdDrawOptions& options, bool pull) {
    std::string version = "#version 450\n";
    if (options.opensubdiv_patch_cull) version += "#define OSD_ENABLE_PATCH_CULL\n";
    if (pull)
        version += "#define PC_OSD_PULL " + std::to_string(type == Far::PatchDescriptor::REGULAR ? 16 : 20) +
                   "\n#define PC_OSD_BINDING_LIST " + std::to_string(sh::kBindingDrawList) +
                   "\n#define PC_OSD_BINDING_INDICES " + std::to_string(sh::kBindingSourceIndices) +
                   "\n#define PC_OSD_BINDING_VERTICES " + std::to_string(sh::kBindingSourceVertices) + "\n";
    if (options.record_tessellated)
        version += "#define PC_OSD_RECORD_TESSELLATED " + std::to_string(sh::kBindingOsdTessellated) + "\n";
    const std::string common = "#define OSD_PATCH_BASIS_GLSL\n" +
                               Osd::GLSLPatchShaderSource::GetPatchBasisShaderSource() +
                               Osd::GLSLPatchShaderSource::GetCommonShaderSource();
    const std::string shared(gl::shipped_glsl("shared.h"));
    const std::string tcs_include(gl::shipped_glsl("patchcull_tcs.h"));
    const std::string header = client_header();
    const std::array<GLuint, 4> shaders = {
        compile(GL_VERTEX_SHADER,
                version + "#define PC_OSD_VERTEX\n" + common + header +
                    Osd::GLSLPatchShaderSource::GetVertexShaderSource(type),
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
    GLint pull_first_patch = -1, pull_index_base = -1, pull_stride = -1, pull_offset = -1, pull_points = -1;
};

Program make_program(Far::PatchDescriptor::Type type, const OsdDrawOptions& options, bool pull = false) {
    Program p;
    p.name = build_program(type, options, pull);
    p.pull_first_patch = glGetUniformLocation(p.name, "u_pull_first_patch");
    p.pull_index_base = glGetUniformLocation(p.name, "u_pull_index_base");
    p.pull_stride = glGetUniformLocation(p.name, "u_pull_stride");
    p.pull_offset = glGetUniformLocation(p.name, "u_pull_offset");
    p.pull_points = glGetUniformLocation(p.name, "u_pull_points");
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

// Rescales CompactPass's commands, written for 16 points a patch, to u_n: count and first.
const char* const kRescaleCommands = R"(#version 450
layout(local_size_x = 64) in;
layout(std430, binding = PC_OSD_BINDING_COMMANDS) buffer PcCommands { uint pc_commands[]; };
uniform uint u_first_word, u_count, u_n;
void main() {
    const uint c = gl_GlobalInvocationID.x;
    if (c >= u_count) return;
    const uint w = u_first_word + 4u * c;
    pc_commands[w] = pc_commands[w] / 16u * u_n;
    pc_commands[w + 2u] = pc_commands[w + 2u] / 16u * u_n;
}
)";

GLuint build_rescale_program() {
    const std::string text =
        std::string(kRescaleCommands)
            .insert(13, "#define PC_OSD_BINDING_COMMANDS " + std::to_string(sh::kBindingDrawCommands) + "\n");
    const GLuint shader = compile(GL_COMPUTE_SHADER, text, "command rescale");
    const GLuint program = glCreateProgram();
    glAttachShader(program, shader);
    glLinkProgram(program);
    glDeleteShader(shader);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
        glDeleteProgram(program);
        throw Error("GL: the OpenSubdiv command rescale program was rejected");
    }
    return program;
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
    // The compacted draw's: programs built at its first draw, a VAO without attributes, the
    // Gregory-basis commands' rescale (built with the table when it has Gregory-basis patches).
    Program bspline_pull, gregory_pull;
    GLuint pull_vao = 0, rescale = 0;
    GLint rescale_first = -1, rescale_count = -1, rescale_n = -1;
    OsdDrawOptions options;
    bool any_bspline = false, any_gregory = false, pulled = false;
    bool indirect_count = false, indirect_count_arb = false;
    std::size_t patch_count = 0, points_needed = 0;
    bool software = false;

    ~Impl() {
        for (GLuint p : {bspline.name, gregory.name, bspline_pull.name, gregory_pull.name, rescale})
            if (p) glDeleteProgram(p);
        for (GLuint b : {masks, tessellated})
            if (b) glDeleteBuffers(1, &b);
        for (GLuint v : {vao, pull_vao})
            if (v) glDeleteVertexArrays(1, &v);
    }
    void build_pull_programs() {
        if (pulled) return;
        GLint blocks = 0;
        glGetIntegerv(GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS, &blocks);
        if (blocks < 3)
            throw Error(
                "GL: the compacted OpenSubdiv draw reads 3 storage blocks in the vertex shader, the driver allows " +
                std::to_string(blocks));
        if (any_bspline) bspline_pull = make_program(Far::PatchDescriptor::REGULAR, options, true);
        if (any_gregory) gregory_pull = make_program(Far::PatchDescriptor::GREGORY_BASIS, options, true);
        glCreateVertexArrays(1, &pull_vao);
        pulled = true;
        check_gl("after building the OpenSubdiv compacted-draw programs");
    }
    std::size_t commands_of(const Array& a, std::size_t k) const { return gl::compact_command_count(a.patches, k); }
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
    m.options = options;
    m.any_bspline = any_bspline;
    m.any_gregory = any_gregory;
    m.indirect_count_arb = epoxy_has_gl_extension("GL_ARB_indirect_parameters");
    m.indirect_count = m.indirect_count_arb || epoxy_gl_version() >= 46;
    if (any_gregory) {
        m.rescale = build_rescale_program();
        m.rescale_first = glGetUniformLocation(m.rescale, "u_first_word");
        m.rescale_count = glGetUniformLocation(m.rescale, "u_count");
        m.rescale_n = glGetUniformLocation(m.rescale, "u_n");
    }
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

// llvmpipe's limit (core/render_params.h) at OpenSubdiv's largest level L = 2 OsdTessLevel()
// (OpenSubdiv's uniform level doubles on patches of refinement level 0), at most 64.
std::size_t osd_patches_per_draw(float tess_level) {
    return max_patches_per_draw(std::min(64, static_cast<int>(std::ceil(2.0f * tess_level))));
}

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
        // llvmpipe restarts gl_PrimitiveID every 1024 / n patches of an indexed draw, and gets a
        // draw of more than 65536 / (L + 1)^2 patches at level L wrong (docs/ENGINE.md): L is
        // OpenSubdiv's largest level, 2 OsdTessLevel() (refinement level 0).
        const std::size_t n = static_cast<std::size_t>(a.control_vertices);
        const std::size_t step = m.software ? std::min(1024 / n, osd_patches_per_draw(view.tess_level)) : a.patches;
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

// ---- The compacted draw --------------------------------------------------------------------------

std::size_t OsdPatchTableDraw::array_count() const { return impl_->arrays.size(); }

std::size_t OsdPatchTableDraw::command_first(std::size_t array, std::size_t patches_per_command) const {
    const Impl& m = *impl_;
    std::size_t first = 0;
    for (std::size_t a = 0; a < array && a < m.arrays.size(); ++a)
        first += m.commands_of(m.arrays[a], patches_per_command);
    return first;
}

std::size_t OsdPatchTableDraw::command_count(std::size_t patches_per_command) const {
    return command_first(impl_->arrays.size(), patches_per_command);
}

void OsdPatchTableDraw::compact(gl::CompactPass& pass, std::uint32_t flags, std::uint32_t mask, std::uint32_t value,
                                const OsdDrawList& out, gl::CompactMethod method) const {
    const Impl& m = *impl_;
    if (!out.list || !out.commands)
        throw Error("OsdPatchTableDraw::compact: the list and the command buffer are required");
    // 20 vertices a Gregory-basis patch: 20 (list_first + count) must fit 32 bits.
    if (m.patch_count > 0xFFFFFFFFu / 20)
        throw Error("OsdPatchTableDraw::compact: " + std::to_string(m.patch_count) + " patches, at most 2^32 / 20");
    std::size_t command = 0;
    for (std::size_t a = 0; a < m.arrays.size(); ++a) {
        const Impl::Array& array = m.arrays[a];
        const gl::PatchBuffers range{0, flags, 0, array.first_patch, array.patches};
        pass.run(
            range, mask, value,
            {out.list, array.first_patch, out.commands, 16 * command, out.draw_count, 4 * a, out.patches_per_command},
            method);
        const std::size_t commands = m.commands_of(array, out.patches_per_command);
        if (array.control_vertices != 16) {
            // CompactPass's commands count 16 vertices a patch: rescale count and first to n.
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
            glUseProgram(m.rescale);
            glUniform1ui(m.rescale_first, static_cast<GLuint>(4 * command));
            glUniform1ui(m.rescale_count, static_cast<GLuint>(commands));
            glUniform1ui(m.rescale_n, static_cast<GLuint>(array.control_vertices));
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingDrawCommands, out.commands);
            glDispatchCompute(static_cast<GLuint>((commands + 63) / 64), 1, 1);
            glMemoryBarrier(GL_COMMAND_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
            glUseProgram(0);
        }
        command += commands;
    }
    check_gl("after compacting the OpenSubdiv patch arrays");
}

void OsdPatchTableDraw::draw_indirect(const OsdVertexBuffer& vertices, std::uint32_t flags, const OsdDrawList& list,
                                      const OsdView& view) const {
    Impl& m = *impl_;
    check_vertices(vertices, m.points_needed);
    check_view(view);
    if (!list.list || !list.commands)
        throw Error("OsdPatchTableDraw::draw_indirect: the list and the command buffer are required");
    GLint64 bytes = 0;
    glGetNamedBufferParameteri64v(list.commands, GL_BUFFER_SIZE, &bytes);
    const std::size_t total = command_count(list.patches_per_command);
    if (static_cast<GLint64>(16 * total) > bytes)
        throw Error("OsdPatchTableDraw::draw_indirect: " + std::to_string(total) + " commands need " +
                    std::to_string(16 * total) + " bytes, the buffer has " + std::to_string(bytes));
    m.build_pull_programs();
    glBindVertexArray(m.pull_vao);  // no attributes: OpenSubdiv's vertex shader gets its point pulled
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingCullFlags, flags);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingDrawList, list.list);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingSourceIndices, m.table->GetPatchIndexBuffer());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingSourceVertices, vertices.buffer);
    glBindTextureUnit(sh::kTextureUnitOsdPatchParam, m.table->GetPatchParamTextureBuffer());
    if (m.tessellated) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, sh::kBindingOsdTessellated, m.tessellated);
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, list.commands);
    const bool counted = list.draw_count && m.indirect_count;
    if (counted) glBindBuffer(GL_PARAMETER_BUFFER_ARB, list.draw_count);
    std::size_t command = 0;
    for (std::size_t a = 0; a < m.arrays.size(); ++a) {
        const Impl::Array& array = m.arrays[a];
        const std::size_t commands = m.commands_of(array, list.patches_per_command);
        const std::size_t first_command = command;
        command += commands;
        if (array.patches == 0) continue;
        const Program& p = array.type == Far::PatchDescriptor::REGULAR ? m.bspline_pull : m.gregory_pull;
        glUseProgram(p.name);
        glUniformMatrix4fv(p.model_view, 1, GL_FALSE, view.model_view.m);
        glUniformMatrix4fv(p.projection, 1, GL_FALSE, view.projection.m);
        glUniform1f(p.tess_level, view.tess_level);
        glUniform1ui(p.mask, 0u);  // every listed patch passed the selection
        glUniform1ui(p.value, 0u);
        glUniform1i(p.one_sided, view.one_sided ? 1 : 0);
        glUniform1i(p.pull_first_patch, static_cast<GLint>(array.first_patch));
        glUniform1i(p.pull_index_base, static_cast<GLint>(array.index_base));
        glUniform1i(p.pull_stride, static_cast<GLint>(vertices.stride_bytes / 4));
        glUniform1i(p.pull_offset, static_cast<GLint>(vertices.offset_bytes / 4));
        glUniform1i(p.pull_points, static_cast<GLint>(std::min<std::size_t>(vertices.point_count, 0x7FFFFFFF)));
        glPatchParameteri(GL_PATCH_VERTICES, array.control_vertices);
        // GL takes the byte offset into the bound indirect buffer as a pointer.
        // NOLINTNEXTLINE(performance-no-int-to-ptr)
        const auto* offset = reinterpret_cast<const void*>(static_cast<std::uintptr_t>(16 * first_command));
        const auto max_draws = static_cast<GLsizei>(commands);
        if (counted) {
            if (m.indirect_count_arb)
                glMultiDrawArraysIndirectCountARB(GL_PATCHES, offset, static_cast<GLintptr>(4 * a), max_draws, 0);
            else
                glMultiDrawArraysIndirectCount(GL_PATCHES, offset, static_cast<GLintptr>(4 * a), max_draws, 0);
        } else {
            glMultiDrawArraysIndirect(GL_PATCHES, offset, max_draws, 0);
        }
    }
    if (counted) glBindBuffer(GL_PARAMETER_BUFFER_ARB, 0);
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
    glUseProgram(0);
    glBindVertexArray(0);
    check_gl("after the compacted draw of the OpenSubdiv patch table");
}

std::size_t OsdPatchTableDraw::listed_count(const OsdDrawList& list) const {
    const Impl& m = *impl_;
    const std::size_t total = command_count(list.patches_per_command);
    std::vector<gl::DrawArraysIndirectCommand> commands(total);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(list.commands, 0, static_cast<GLsizeiptr>(total * sizeof(gl::DrawArraysIndirectCommand)),
                            commands.data());
    check_gl("after reading the OpenSubdiv draw commands");
    std::size_t n = 0, c = 0;
    for (const Impl::Array& array : m.arrays)
        for (std::size_t k = 0; k < m.commands_of(array, list.patches_per_command); ++k, ++c)
            n += commands[c].count / static_cast<std::uint32_t>(array.control_vertices);
    return n;
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
    gl::CompactPass compact;
    // The compacted draw's buffers per draw pass (made at the first indirect frame, the commands
    // grown with the patches per command).
    std::array<GLuint, 2> lists{}, commands{}, counts{};
    std::size_t command_capacity = 0;
    bool software = false;

    explicit Impl(gl::PassContext& passes)
        : status(passes),
          frustum(passes),
          cones(passes),
          ptp(passes),
          occlusion(passes),
          hiz_build(passes),
          compact(passes),
          software(passes.is_software()) {}
    ~Impl() {
        if (fbo) glDeleteFramebuffers(1, &fbo);
        for (GLuint t : {ids, depth, hiz.texture})
            if (t) glDeleteTextures(1, &t);
        for (GLuint b : {flags, counters, lists[0], lists[1], commands[0], commands[1], counts[0], counts[1]})
            if (b) glDeleteBuffers(1, &b);
    }

    // K: no limit on a GPU; on llvmpipe a command's tessellated vertices stay about 4096 (as
    // CullPipeline's indirect draw): 65536 / (L + 1)^2 / 16 patches at OpenSubdiv's largest level
    // L = 2 OsdTessLevel() (a patch of refinement level 0 gets twice the uniform level).
    std::size_t patches_per_command(float tess_level) const {
        return software ? patches_per_indirect_command(osd_patches_per_draw(tess_level), true) : 0;
    }

    gl_osd::OsdDrawList draw_list(int pass, std::size_t k) {
        const std::size_t needed = std::max<std::size_t>(draw->command_count(k), 1);
        if (!lists[0]) {
            for (int i = 0; i < 2; ++i) {
                glCreateBuffers(1, &lists[static_cast<std::size_t>(i)]);
                glNamedBufferStorage(lists[static_cast<std::size_t>(i)],
                                     static_cast<GLsizeiptr>(4 * std::max<std::size_t>(draw->patch_count(), 1)),
                                     nullptr, 0);
                glCreateBuffers(1, &counts[static_cast<std::size_t>(i)]);
                glNamedBufferStorage(counts[static_cast<std::size_t>(i)],
                                     static_cast<GLsizeiptr>(4 * std::max<std::size_t>(draw->array_count(), 1)),
                                     nullptr, 0);
            }
        }
        if (needed > command_capacity) {
            for (GLuint& c : commands) {
                if (c) glDeleteBuffers(1, &c);
                glCreateBuffers(1, &c);
                glNamedBufferStorage(c, static_cast<GLsizeiptr>(16 * needed), nullptr, 0);
            }
            command_capacity = needed;
        }
        const auto i = static_cast<std::size_t>(pass);
        return {lists[i], commands[i], counts[i], k};
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
    const bool indirect = settings.draw == OsdDrawMode::indirect;
    const std::size_t k = m.patches_per_command(view.tess_level);
    std::array<OsdDrawList, 2> lists{};
    if (indirect)
        for (int i = 0; i < 2; ++i) lists[static_cast<std::size_t>(i)] = m.draw_list(i, k);
    // One draw pass: with the flags every patch goes and the TCS keeps the selection; indirect,
    // CompactPass lists the selection per array (after the flags' last writes) and only those go.
    const auto draw_pass = [&](int pass, std::uint32_t mask, std::uint32_t value) {
        if (!indirect) {
            m.draw->draw(vertices, m.flags, mask, value, view);
            return;
        }
        const OsdDrawList& list = lists[static_cast<std::size_t>(pass)];
        m.draw->compact(m.compact, m.flags, mask, value, list, settings.compact);
        m.draw->draw_indirect(vertices, m.flags, list, view);
    };
    if (!settings.occlusion) {
        chain();
        m.begin_targets(view.depth);
        draw_pass(0, sh::kDrawMaskUnculled, sh::kDrawValueUnculled);
        m.end_targets();
    } else {
        m.begin_targets(view.depth);
        draw_pass(0, sh::kDrawMaskFirstPass, sh::kDrawValueFirstPass);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);  // the depth texture is sampled next
        m.hiz_build.run(m.depth, m.hiz, view.depth);
        chain();
        glBindFramebuffer(GL_FRAMEBUFFER, m.fbo);
        draw_pass(1, sh::kDrawMaskSecondPass, sh::kDrawValueSecondPass);
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
    if (indirect) {
        stats.submitted_pass1 = m.draw->listed_count(lists[0]);
        stats.submitted_pass2 = settings.occlusion ? m.draw->listed_count(lists[1]) : 0;
    } else {
        stats.submitted_pass1 = m.draw->patch_count();
        stats.submitted_pass2 = settings.occlusion ? m.draw->patch_count() : 0;
    }
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
