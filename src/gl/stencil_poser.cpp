// StencilPoser (patchcull/gl/gl_posing.h): stencil tables uploaded once, posed control meshes per
// frame, shaders/pose_stencils.comp.glsl writing the renderer's control points and tangents.
#include <epoxy/gl.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "gl_util.h"
#include "patchcull/core/error.h"
#include "patchcull/gl/gl_posing.h"
#include "patchcull/gl/gl_renderer.h"
#include "shared.h"

namespace patchcull::gl {

namespace {

// Binding points of pose_stencils.comp.glsl (shared.h).
constexpr GLuint kOutPoints = shared::kBindingControlPoints, kOutTangents = shared::kBindingPatchTangents,
                 kVertices = shared::kBindingPoseVertices, kInstances = shared::kBindingPoseInstances,
                 kPatchTable = shared::kBindingPosePatchTable, kOffsets = shared::kBindingPoseOffsets,
                 kTerms = shared::kBindingPoseTerms, kTangentTable = shared::kBindingPoseTangentTable;
constexpr GLuint kGroupSize = 256;                           // local_size_x of the shader
constexpr std::uint64_t kPointRows = 16, kTangentRows = 24;  // invocations per patch, per tangent block

struct GpuInstance {
    float to_world[16];
    std::uint32_t first_vertex, first_patch, mirrored, first_row;
};
static_assert(sizeof(GpuInstance) == 80, "std430 struct {mat4; uvec4;}");

std::size_t buffer_size(GLuint buffer) {
    GLint64 size = 0;
    glGetNamedBufferParameteri64v(buffer, GL_BUFFER_SIZE, &size);
    return static_cast<std::size_t>(size);
}

// Appends a table's rows (offsets rebased onto terms.size()/2) and terms; throws when malformed.
void append_table(const StencilTableView& t, std::uint32_t vertex_count, std::size_t model, const char* what,
                  std::vector<std::uint32_t>& offsets, std::vector<std::uint32_t>& terms) {
    if (t.rows == 0) return;
    if (!t.offsets || (t.offsets[t.rows] > 0 && (!t.indices || !t.weights)))
        throw Error("GL: StencilPoser: model " + std::to_string(model) + ": " + what + " table without data");
    if (t.offsets[0] != 0)
        throw Error("GL: StencilPoser: model " + std::to_string(model) + ": " + what + " offsets do not start at 0");
    const std::uint32_t base = static_cast<std::uint32_t>(terms.size() / 2);
    for (std::size_t r = 0; r < t.rows; ++r) {
        if (t.offsets[r + 1] < t.offsets[r])
            throw Error("GL: StencilPoser: model " + std::to_string(model) + ": " + what + " offsets descend at row " +
                        std::to_string(r));
        offsets.push_back(base + t.offsets[r + 1]);
    }
    for (std::uint32_t k = 0; k < t.offsets[t.rows]; ++k) {
        if (t.indices[k] >= vertex_count)
            throw Error("GL: StencilPoser: model " + std::to_string(model) + ": " + what + " stencil index " +
                        std::to_string(t.indices[k]) + " is past its " + std::to_string(vertex_count) + " vertices");
        std::uint32_t bits;
        static_assert(sizeof(bits) == sizeof(float));
        std::memcpy(&bits, &t.weights[k], sizeof bits);
        terms.push_back(t.indices[k]);
        terms.push_back(bits);
    }
}

}  // namespace

struct StencilPoser::Impl {
    GLuint program = 0;
    GLint count_location = -1, tangent_count_location = -1, vertex_base_location = -1, vertex_stride_location = -1;
    GLuint offsets = 0, terms = 0, patch_table = 0, vertices = 0, instances = 0, tangent_table = 0;
    std::size_t tangent_count = 0;                              // entries of tangent_table
    std::size_t vertices_capacity = 0, instances_capacity = 0;  // bytes of the per-frame buffers
    std::vector<std::uint32_t> instance_models;
    std::vector<std::uint32_t> model_vertex_counts;
    std::vector<std::uint32_t> model_first_row;  // first patch row of each model in offsets
    std::vector<std::uint32_t> instance_first_patch;
    std::vector<GpuInstance> staging;
    std::size_t count = 0;
    bool tangents = false;
    std::size_t last_bytes = 0, table_bytes = 0;

    ~Impl() {
        glDeleteProgram(program);
        const GLuint buffers[] = {offsets, terms, patch_table, vertices, instances, tangent_table};
        glDeleteBuffers(6, buffers);
    }

    struct Dispatch {
        GLuint vertex_buffer;
        GLuint vertex_base, vertex_stride;  // in floats
    };
    void run(const Dispatch& d, GLuint patch_buffer, GLuint tangent_buffer);

    // Makes buffer hold at least size bytes (grows by doubling; never shrinks).
    void reserve(GLuint buffer, std::size_t& capacity, std::size_t size) {
        if (size <= capacity && capacity > 0) return;
        capacity = std::max<std::size_t>({size, 2 * capacity, 256});
        glNamedBufferData(buffer, static_cast<GLsizeiptr>(capacity), nullptr, GL_DYNAMIC_DRAW);
    }
};

StencilPoser::StencilPoser(const GlContext& ctx) : StencilPoser((ctx.make_current(), CurrentContext{})) {}

StencilPoser::StencilPoser(CurrentContext) : impl_(std::make_unique<Impl>()) {
    if (glGetString(GL_VERSION) == nullptr || epoxy_gl_version() < 45)
        throw Error("GL: StencilPoser needs a current OpenGL 4.5 core context");
    Impl& m = *impl_;
    m.program = detail::link_program({{"pose_stencils.comp.glsl", GL_COMPUTE_SHADER}}, "pose_stencils");
    m.count_location = glGetUniformLocation(m.program, "u_patch_count");
    m.tangent_count_location = glGetUniformLocation(m.program, "u_tangent_count");
    m.vertex_base_location = glGetUniformLocation(m.program, "u_vertex_base");
    m.vertex_stride_location = glGetUniformLocation(m.program, "u_vertex_stride");
    GLuint buffers[6];
    glCreateBuffers(6, buffers);
    m.offsets = buffers[0];
    m.terms = buffers[1];
    m.patch_table = buffers[2];
    m.vertices = buffers[3];
    m.instances = buffers[4];
    m.tangent_table = buffers[5];
    for (GLuint b : buffers) detail::upload(b, 0, nullptr);
    detail::check_gl("StencilPoser setup");
}

StencilPoser::StencilPoser(StencilPoser&&) noexcept = default;
StencilPoser& StencilPoser::operator=(StencilPoser&&) noexcept = default;
StencilPoser::~StencilPoser() = default;

std::size_t StencilPoser::patch_count() const { return impl_->count; }
bool StencilPoser::has_tangents() const { return impl_->tangents; }
std::size_t StencilPoser::last_upload_bytes() const { return impl_->last_bytes; }
std::size_t StencilPoser::table_bytes() const { return impl_->table_bytes; }

void StencilPoser::set_tables(const std::vector<PosingModel>& models,
                              const std::vector<std::uint32_t>& instance_models) {
    Impl& m = *impl_;
    // One offsets table: every model's patch rows, then every model's tangent rows.
    std::vector<std::uint32_t> offsets{0}, terms;
    std::vector<std::uint32_t> first_row(models.size()), first_tangent_row(models.size());
    for (std::size_t i = 0; i < models.size(); ++i) {
        const PosingModel& model = models[i];
        if (model.patch_points.rows % 16 != 0)
            throw Error("GL: StencilPoser: model " + std::to_string(i) + ": " +
                        std::to_string(model.patch_points.rows) + " patch rows is not 16 per patch");
        if (model.tangent_index.size() != model.patch_points.rows / 16)
            throw Error("GL: StencilPoser: model " + std::to_string(i) + ": tangent_index has " +
                        std::to_string(model.tangent_index.size()) + " entries for " +
                        std::to_string(model.patch_points.rows / 16) + " patches");
        first_row[i] = static_cast<std::uint32_t>(offsets.size() - 1);
        append_table(model.patch_points, model.vertex_count, i, "patch", offsets, terms);
    }
    for (std::size_t i = 0; i < models.size(); ++i) {
        const PosingModel& model = models[i];
        if (model.tangent_points.rows % 24 != 0)
            throw Error("GL: StencilPoser: model " + std::to_string(i) + ": " +
                        std::to_string(model.tangent_points.rows) + " tangent rows is not 24 per block");
        for (std::int32_t t : model.tangent_index)
            if (t >= 0 && static_cast<std::size_t>(t) >= model.tangent_points.rows / 24)
                throw Error("GL: StencilPoser: model " + std::to_string(i) + ": tangent_index " + std::to_string(t) +
                            " is past its " + std::to_string(model.tangent_points.rows / 24) + " tangent blocks");
        first_tangent_row[i] = static_cast<std::uint32_t>(offsets.size() - 1);
        append_table(model.tangent_points, model.vertex_count, i, "tangent", offsets, terms);
    }
    if (terms.size() / 2 > 0xFFFFFFFFu) throw Error("GL: StencilPoser: more than 2^32 stencil terms");
    // Per output patch its instance; per output patch with tangents (patch, its block's first row).
    std::vector<std::uint32_t> table, tangent_table;
    std::vector<std::uint32_t> first_patch;
    for (std::size_t i = 0; i < instance_models.size(); ++i) {
        const std::uint32_t mi = instance_models[i];
        if (mi >= models.size())
            throw Error("GL: StencilPoser: instance " + std::to_string(i) + " names model " + std::to_string(mi) +
                        " of " + std::to_string(models.size()));
        first_patch.push_back(static_cast<std::uint32_t>(table.size()));
        for (std::int32_t t : models[mi].tangent_index) {
            if (t >= 0) {
                tangent_table.push_back(static_cast<std::uint32_t>(table.size()));
                tangent_table.push_back(first_tangent_row[mi] + 24u * static_cast<std::uint32_t>(t));
            }
            table.push_back(static_cast<std::uint32_t>(i));
        }
        // Invocation indices are uint in the shader.
        if (table.size() * kPointRows + tangent_table.size() / 2 * kTangentRows >= 0xFFFFFFFFull)
            throw Error("GL: StencilPoser: too many patches for one pass (" + std::to_string(table.size()) + ")");
    }
    detail::upload(m.offsets, offsets.size() * 4, offsets.data());
    detail::upload(m.terms, terms.size() * 4, terms.data());
    detail::upload(m.patch_table, table.size() * 4, table.data());
    detail::upload(m.tangent_table, tangent_table.size() * 4, tangent_table.data());
    m.table_bytes = (offsets.size() + terms.size() + table.size() + tangent_table.size()) * 4;
    m.count = table.size();
    m.tangent_count = tangent_table.size() / 2;
    m.tangents = m.tangent_count > 0;
    m.instance_models = instance_models;
    m.instance_first_patch = std::move(first_patch);
    m.model_first_row = std::move(first_row);
    m.model_vertex_counts.clear();
    for (const PosingModel& model : models) m.model_vertex_counts.push_back(model.vertex_count);
    detail::check_gl("StencilPoser::set_tables");
}

namespace {

// Checks the instance count and the output buffers, and fills m.staging (throws when an instance's
// vertices run past vertex_count).
void prepare(StencilPoser::Impl& m, std::size_t vertex_count, const std::vector<PosingInstance>& instances,
             GLuint patch_buffer, GLuint tangent_buffer) {
    if (instances.size() != m.instance_models.size())
        throw Error("GL: StencilPoser::pose: " + std::to_string(instances.size()) + " instances for tables of " +
                    std::to_string(m.instance_models.size()));
    if (!glIsBuffer(patch_buffer) || buffer_size(patch_buffer) < m.count * sizeof(BezierPatch))
        throw Error("GL: StencilPoser::pose: patch buffer " + std::to_string(patch_buffer) + " does not hold " +
                    std::to_string(m.count) + " patches");
    if (m.tangents && (!glIsBuffer(tangent_buffer) || buffer_size(tangent_buffer) < m.count * 24 * 16))
        throw Error("GL: StencilPoser::pose: tangent buffer " + std::to_string(tangent_buffer) + " does not hold " +
                    std::to_string(m.count) + " patches' tangents");
    m.staging.resize(instances.size());
    for (std::size_t i = 0; i < instances.size(); ++i) {
        const PosingInstance& in = instances[i];
        const std::uint32_t model = m.instance_models[i];
        if (in.first_vertex > vertex_count || m.model_vertex_counts[model] > vertex_count - in.first_vertex)
            throw Error("GL: StencilPoser::pose: instance " + std::to_string(i) + "'s vertices run past the " +
                        std::to_string(vertex_count) + " given");
        GpuInstance& out = m.staging[i];
        std::copy_n(in.to_world.m, 16, out.to_world);
        out.first_vertex = static_cast<std::uint32_t>(in.first_vertex);
        out.first_patch = m.instance_first_patch[i];
        out.mirrored = in.mirrored ? 1u : 0u;
        out.first_row = m.model_first_row[model];
    }
}

}  // namespace

// Uploads the instances and runs the pass over the vertices at d.
void StencilPoser::Impl::run(const Dispatch& d, GLuint patch_buffer, GLuint tangent_buffer) {
    const std::size_t instance_bytes = staging.size() * sizeof(GpuInstance);
    reserve(instances, instances_capacity, instance_bytes);
    if (instance_bytes) glNamedBufferSubData(instances, 0, static_cast<GLsizeiptr>(instance_bytes), staging.data());
    last_bytes += instance_bytes;
    if (count == 0) return;
    glUseProgram(program);
    glUniform1ui(count_location, static_cast<GLuint>(count));
    glUniform1ui(tangent_count_location, static_cast<GLuint>(tangent_count));
    glUniform1ui(vertex_base_location, d.vertex_base);
    glUniform1ui(vertex_stride_location, d.vertex_stride);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kOutPoints, patch_buffer);
    // Without tangents nothing is written at kOutTangents; a buffer of ours keeps the binding valid.
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kOutTangents, tangents ? tangent_buffer : instances);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kVertices, d.vertex_buffer);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kInstances, instances);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kPatchTable, patch_table);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kOffsets, offsets);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kTerms, terms);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kTangentTable, tangent_table);
    // 16 invocations per patch and 24 per tangent block; more than 65535 groups go into a second
    // dimension (the shader flattens gl_GlobalInvocationID).
    const std::uint64_t rows = count * kPointRows + tangent_count * kTangentRows;
    const std::uint64_t groups = (rows + kGroupSize - 1) / kGroupSize;
    const std::uint64_t x = std::min<std::uint64_t>(groups, 65535);
    const std::uint64_t y = (groups + x - 1) / x;
    glDispatchCompute(static_cast<GLuint>(x), static_cast<GLuint>(y), 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT | GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT);
    glUseProgram(0);
}

void StencilPoser::pose(const std::vector<Vec3>& vertices, const std::vector<PosingInstance>& instances,
                        std::uint32_t patch_buffer, std::uint32_t tangent_buffer) {
    Impl& m = *impl_;
    prepare(m, vertices.size(), instances, patch_buffer, tangent_buffer);
    detail::check_gl("(pending before StencilPoser::pose)");
    const std::size_t vertex_bytes = vertices.size() * sizeof(Vec3);
    m.reserve(m.vertices, m.vertices_capacity, vertex_bytes);
    if (vertex_bytes) glNamedBufferSubData(m.vertices, 0, static_cast<GLsizeiptr>(vertex_bytes), vertices.data());
    m.last_bytes = vertex_bytes;
    static_assert(sizeof(Vec3) == 12, "packed x y z");
    m.run({m.vertices, 0, 3}, patch_buffer, tangent_buffer);
    detail::check_gl("StencilPoser::pose");
}

void StencilPoser::pose(const GpuVertices& vertices, const std::vector<PosingInstance>& instances,
                        std::uint32_t patch_buffer, std::uint32_t tangent_buffer) {
    Impl& m = *impl_;
    const auto fail = [&](const std::string& why) {
        throw Error("GL: StencilPoser::pose: vertex buffer " + std::to_string(vertices.buffer) + ": " + why);
    };
    const std::size_t components =
        vertices.components == 3 || vertices.components == 4 ? static_cast<std::size_t>(vertices.components) : 0;
    if (components == 0) fail(std::to_string(vertices.components) + " components (3 or 4 floats a vertex)");
    if (vertices.offset_bytes % 4 != 0)
        fail("offset " + std::to_string(vertices.offset_bytes) + " bytes is not a multiple of 4");
    if (vertices.stride_bytes % 4 != 0)
        fail("stride " + std::to_string(vertices.stride_bytes) + " bytes is not a multiple of 4");
    if (vertices.stride_bytes < 4 * components)
        fail("stride " + std::to_string(vertices.stride_bytes) + " bytes is smaller than its " +
             std::to_string(components) + " floats");
    if (vertices.buffer != 0 && (vertices.buffer == patch_buffer || (m.tangents && vertices.buffer == tangent_buffer)))
        fail("is also an output buffer of the pass");
    // The shader indexes floats with uint: every float read must lie below 2^32 floats (16 GiB).
    constexpr std::size_t kMaxFloats = 0xFFFFFFFFu;
    if (vertices.count > 0) {
        if (!glIsBuffer(vertices.buffer)) fail("is not a buffer object of the current context");
        const std::size_t size = buffer_size(vertices.buffer);
        const std::size_t first = vertices.offset_bytes, last = 4 * components;
        if (first > size || last > size - first || vertices.count - 1 > (size - first - last) / vertices.stride_bytes)
            fail(std::to_string(size) + " bytes do not hold " + std::to_string(vertices.count) + " vertices of " +
                 std::to_string(components) + " floats at offset " + std::to_string(vertices.offset_bytes) +
                 ", stride " + std::to_string(vertices.stride_bytes));
        if ((first + (vertices.count - 1) * vertices.stride_bytes + last) / 4 > kMaxFloats ||
            vertices.stride_bytes / 4 > kMaxFloats)
            fail("reads past 16 GiB (the pass indexes 32-bit floats with 32-bit indices)");
        // The pass reads a storage block: the driver bounds its size.
        GLint64 max_block = 0;
        glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);
        const std::size_t end = first + (vertices.count - 1) * vertices.stride_bytes + last;
        if (max_block > 0 && end > static_cast<std::size_t>(max_block))
            fail("the vertices end at byte " + std::to_string(end) + ", past GL_MAX_SHADER_STORAGE_BLOCK_SIZE (" +
                 std::to_string(max_block) + ")");
    }
    prepare(m, vertices.count, instances, patch_buffer, tangent_buffer);
    detail::check_gl("(pending before StencilPoser::pose)");
    // A compute shader's storage writes to the vertices (skinning) just before are seen.
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    m.last_bytes = 0;
    // No vertices: nothing reads them, and a buffer of ours keeps the binding valid.
    const GLuint buffer = vertices.count > 0 ? vertices.buffer : m.vertices;
    m.run({buffer, static_cast<GLuint>(vertices.offset_bytes / 4), static_cast<GLuint>(vertices.stride_bytes / 4)},
          patch_buffer, tangent_buffer);
    detail::check_gl("StencilPoser::pose");
}

}  // namespace patchcull::gl
