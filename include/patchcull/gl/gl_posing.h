// patchcull/gl/gl_posing.h: posing animated objects on the GPU (library patchcull_gl).
//
// Both subdivision schemes make every Bezier control point (and every ACC tangent vector) a fixed
// linear combination of control-mesh vertices: a stencil row (subdivision.h's PointStencils).
// StencilPoser uploads those tables once, and per frame only the posed control meshes (12 bytes
// per vertex; nothing when they are already in a GL buffer: GpuVertices) and each instance's
// transform (80 bytes); one compute pass
// (shaders/pose_stencils.comp.glsl) then writes the control points and the tangent vectors
// straight into the caller's buffers (PatchRenderer::patch_buffer() and tangent_buffer()), in
// gl_passes.h's layouts. What changes per frame on the CPU is the animation of the control
// meshes (animation.h), not the patches: no patch is evaluated or uploaded.
//
// Exactness: the output is BIT-IDENTICAL to ScenePoser::pose() (scene_poser.h) for the same
// control meshes and transforms, on any conforming GL 4.5 implementation with IEEE double
// addition and round-to-nearest double-to-float conversion (the shader's head comment gives the
// argument: each stencil product is exact in double, the sum is taken in the CPU's order and
// rounded once, the transform repeats the CPU's float operations under `precise`).
// tests/gl/gpu_posing_test.cpp reads the buffers back and compares bit for bit (llvmpipe here,
// NVIDIA through the device script).
//
// The layer stays below the import layer: the tables come as plain arrays (no subdivision.h or
// scene_poser.h here); ScenePoser::gpu_tables / gpu_meshes (scene_poser.h) produce them for a Scene.
//
// Threads and lifetime as gl_renderer.h: create, use and destroy on the context's thread.
// Vertices come either from a CPU array (uploaded into the poser's own buffer) or straight from a
// GL buffer of the caller's (GpuVertices: float3 or float4 positions at any byte stride and
// offset, e.g. an engine's skinning output), read in place: no copy, no CPU round trip, and the
// output is bit-identical to the CPU-array path for the same positions.
// State contract of pose(): it binds its program and, at shader storage bindings, the outputs at 0
// and 10 (shared.h's kBindingControlPoints and kBindingPatchTangents; without tangents a buffer of
// its own at 10), the vertices at 17 (kBindingPoseVertices: its own buffer, or the caller's
// GpuVertices::buffer whole, glBindBufferBase) and its own inputs at 18-22 (kBindingPoseInstances,
// kBindingPosePatchTable, kBindingPoseOffsets, kBindingPoseTerms, kBindingPoseTangentTable). It
// leaves those bindings as it set them and no program in use, and changes no other state (no
// vertex array, framebuffer or uniform buffer binding). The GpuVertices overload issues
// glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT) before its dispatch, so a compute shader's storage
// writes to the vertex buffer just before pose() are seen without a barrier of the caller's
// (writes through glBufferSubData, copies or transform feedback need none). Every pose() ends with
// glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT |
// GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT) so the following cull passes, draws and read-backs see its
// writes. It does not wait for the GPU. After set_tables it allocates no GL storage while the
// per-frame sizes stay the same (buffers grow, never shrink; the GpuVertices overload uploads only
// the instances).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "patchcull/core/math.h"

namespace patchcull::gl {

class GlContext;

/// A stencil table in PointStencils' layout: row r is sum_k weights[k] * vertex[indices[k]],
/// k in [offsets[r], offsets[r+1]); offsets has rows + 1 entries, offsets[0] == 0.
struct StencilTableView {
    const std::uint32_t* offsets = nullptr;
    std::size_t rows = 0;
    const std::uint32_t* indices = nullptr;
    const float* weights = nullptr;
};

/// One model's tables: 16 patch rows per patch (control point 4j + i, patch.h order), and 24
/// tangent rows per tangent block (12 du rows, then 12 dv rows: SubdivisionModel::tangent_points).
struct PosingModel {
    StencilTableView patch_points;
    StencilTableView tangent_points;
    /// Per patch: its tangent block, or -1 (PatchInfo::tangent_index). Its size is the model's
    /// patch count (patch_points.rows / 16).
    std::vector<std::int32_t> tangent_index;
    /// Vertices of the model's control mesh: every stencil index must be below it.
    std::uint32_t vertex_count = 0;
};

/// One instance in a frame: where its posed control mesh starts in pose()'s vertex array, its
/// affine transform (ScenePoser: instance_to_world), and whether it mirrors (its patches are then
/// transposed, as ScenePoser does: scene_poser.h).
struct PosingInstance {
    std::size_t first_vertex = 0;
    Mat4 to_world;
    bool mirrored = false;
};

/// Posed control-mesh vertices already in a GL buffer of the caller's (an engine's skinning
/// output): vertex v's position is the first 3 floats at byte offset_bytes + v * stride_bytes of
/// buffer (x, y, z; with components == 4 the fourth float, w, is not read: positions, not
/// homogeneous points). pose() reads them in place. Requirements (else pose() throws
/// patchcull::Error): buffer is a buffer object of the current context, not one of pose()'s output
/// buffers; components is 3 or 4; offset_bytes and stride_bytes are multiples of 4 and
/// stride_bytes >= 4 * components; the buffer holds offset_bytes + (count - 1) * stride_bytes +
/// 4 * components bytes (count > 0), and those end within GL_MAX_SHADER_STORAGE_BLOCK_SIZE (the
/// pass reads the buffer as one storage block from byte 0). The buffer must not be mapped (unless persistently) while
/// the pass runs.
struct GpuVertices {
    std::uint32_t buffer = 0;
    std::size_t offset_bytes = 0;
    std::size_t stride_bytes = 12;
    int components = 3;
    std::size_t count = 0;  // vertices in the buffer: instances index [0, count)
};

/// The posing pass and its tables (caller-owned GL objects, made once; nothing per frame but the
/// vertex and instance uploads).
class StencilPoser {
public:
    /// Makes ctx current and compiles shaders/pose_stencils.comp.glsl. Throws patchcull::Error
    /// ("GL: shader pose_stencils.comp.glsl: ...") when the driver rejects it (it needs double
    /// precision, core since GL 4.0).
    explicit StencilPoser(const GlContext& ctx);
    /// The same on the OpenGL 4.5 context current on the calling thread (the caller's own: GLFW,
    /// SDL, EGL, an engine's), as the passes (gl_passes.h) take it; the caller owns the buffers
    /// pose() writes. Throws Error when no 4.5 context is current.
    struct CurrentContext {};
    explicit StencilPoser(CurrentContext);
    StencilPoser(StencilPoser&&) noexcept;
    StencilPoser& operator=(StencilPoser&&) noexcept;
    StencilPoser(const StencilPoser&) = delete;
    StencilPoser& operator=(const StencilPoser&) = delete;
    ~StencilPoser();

    /// Uploads the models' tables and the instance layout: instance i poses model
    /// instance_models[i]; the output patches are instance by instance, each instance's in its
    /// model's order (ScenePoser::pose()'s order), patch_count() in all, and the tangent vectors
    /// of output patch p go to block p of the tangent buffer (PatchRenderer's layout: 24 vec4 per
    /// patch, (x, y, z, 0), w of the first = 1 where the patch has tangents; patches without
    /// tangents are not written). Throws patchcull::Error when a table is malformed (offsets not
    /// ascending from 0, a stencil index >= vertex_count, patch rows not a multiple of 16, tangent
    /// rows not a multiple of 24, a tangent_index of the wrong size or past the blocks) or a
    /// model index is out of range.
    void set_tables(const std::vector<PosingModel>& models, const std::vector<std::uint32_t>& instance_models);
    std::size_t patch_count() const;
    /// True when some output patch has tangent vectors (pose() then needs a tangent buffer).
    bool has_tangents() const;

    /// Poses one frame: vertices are the posed control meshes of every instance (instance i's at
    /// instances[i].first_vertex, its model's vertex_count of them), instances one per instance
    /// of set_tables. Writes 16 vec4 per patch into patch_buffer and, when has_tangents(), the
    /// tangent vectors into tangent_buffer. Throws patchcull::Error when the instance count
    /// differs from set_tables', an instance's vertices run past the array, or a buffer is too
    /// small (patch_buffer: 256 bytes per patch; tangent_buffer: 384 bytes per patch).
    void pose(const std::vector<Vec3>& vertices, const std::vector<PosingInstance>& instances,
              std::uint32_t patch_buffer, std::uint32_t tangent_buffer);
    /// The same with the vertices read from the caller's GL buffer (GpuVertices; instance i's at
    /// vertices instances[i].first_vertex on), no copy: the written buffers are bit-identical to
    /// the vector overload's for the same positions. Throws patchcull::Error as that overload, and
    /// when `vertices` breaks GpuVertices' requirements (one line naming the requirement).
    void pose(const GpuVertices& vertices, const std::vector<PosingInstance>& instances, std::uint32_t patch_buffer,
              std::uint32_t tangent_buffer);
    /// Bytes the last pose() uploaded (vertices and instances; the instances alone for
    /// GpuVertices), and the bytes set_tables uploaded.
    std::size_t last_upload_bytes() const;
    std::size_t table_bytes() const;

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace patchcull::gl
