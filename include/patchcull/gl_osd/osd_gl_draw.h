// patchcull/gl_osd/osd_gl_draw.h: OpenSubdiv's own patch table drawn with OpenSubdiv's own GLSL
// patch shaders, culled in place by patchcull's GPU passes (library patchcull_gl_osd: the gl
// layer plus OpenSubdiv's osdGPU; the gl layer itself never sees OpenSubdiv).
//
// What is drawn is what an engine built on OpenSubdiv draws: Osd::GLPatchTable (the table's
// control-vertex index buffer, its patch-param texture buffer and its PatchArrays) over the
// engine's vertex buffer, every REGULAR array with Osd::GLSLPatchShaderSource's B-spline
// shaders and every GREGORY_BASIS array with its Gregory-basis shaders, each program composed as
// OpenSubdiv's examples compose theirs (version, stage defines, OSD_PATCH_BASIS_GLSL with
// GetPatchBasisShaderSource, GetCommonShaderSource, a client header, the stage's patch source) with a small main
// fragment shader that writes the patch's id. The client header includes shared.h and
// patchcull_tcs.h in the TCS and redefines OpenSubdiv's OSD_PATCH_CULL(N) hook as
// PATCHCULL_RETURN_UNLESS_DRAWN(OsdGetPatchIndex(gl_PrimitiveID), mask, value): the flag index is
// Far's patch index (PatchArray::GetPrimitiveIdBase() + gl_PrimitiveID).
//
// Culling: each patch array is one GpuPatchSource (gl_passes.h) over the same vertex buffer, the
// table's index buffer and a buffer of boundary masks, all writing one flag buffer in Far's patch
// order, so FrustumPass, BackpatchConePass, BackpatchPtpPass and OcclusionPass run on the table
// in place. OsdCullFrame runs Niessner & Loop's two-pass frame ("Patch-Based Occlusion Culling
// for Hardware Tessellation"): pass 1 draws the patches the previous frame found visible, the
// Hi-Z pyramid is built from its depth, the chain tests every patch, pass 2 draws the newly
// visible ones.
//
// What contributes a pixel (as README's rule): a shape drawn one-sided (closed, outward oriented:
// the only shapes to give a back-patch pass) keeps a fragment only where the cosine between
// OpenSubdiv's evaluated normal and the direction to the eye, computed at the tessellated
// vertices and interpolated, exceeds shared.h's kFrontFacingMinCosine; open shapes are two-sided.
//
// llvmpipe: gl_PrimitiveID restarts within indexed draws there (patchcull_tcs.h), so on a software
// rasterizer each array is drawn as sub-draws of at most 1024 / n patches (n = 16 or 20), each
// with its PrimitiveIdBase, and at most 65536 / (L + 1)^2 at OpenSubdiv's largest level L = 2
// OsdTessLevel() (llvmpipe gets larger draws wrong: docs/ENGINE.md); on a GPU one draw per array.
//
// Drawing only the survivors (OsdDrawMode::indirect), as OpenSubdiv's Metal path draws a patch
// index buffer (OSD_USE_PATCH_INDEX_BUFFER: the surviving patches appended to a list, drawn
// indirectly; OpenSubdiv's GLSL has no such hook, so the client header adds one): CompactPass
// (gl_compaction.h) lists each array's surviving patches (Far's patch indices, ascending with the
// prefix scan) at the array's own first entry of a list, with indirect commands whose vertex
// gl_VertexID is point gl_VertexID % n of list entry gl_VertexID / n (a Gregory-basis array's
// commands, written for 16 points, are rescaled to 20 on the GPU). The draw is non-indexed and
// has no vertex attributes: a second program per patch type (compiled at the first compacted
// draw) is OpenSubdiv's same stage sources with a client header that pulls each control point in
// OpenSubdiv's vertex shader (its OSD_USER_VARYING_PER_VERTEX hook overwrites the attribute
// position with the point the table's index buffer names for that slot of that patch, read from
// the vertex buffer as storage) and passes the patch's Far index on; OsdPrimitiveIdBase() returns
// that index minus gl_PrimitiveID, so OpenSubdiv's OsdGetPatchIndex(gl_PrimitiveID) is the listed
// patch whatever gl_PrimitiveID a multi-draw or llvmpipe gives. Its TCS checks no flag (every
// listed patch passed the selection). Its vertex shader reads 3 storage blocks (the list, the index
// buffer, the vertices): GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS >= 3, which GL 4.5 does not promise
// (an Error at the first compacted draw otherwise).
//
// Threads and lifetime: as gl_passes.h (the context current at construction, on its thread).
// Errors: patchcull::Error with one line (a table with other patch types, a vertex layout the
// draw cannot read, a shader the driver rejects, a GL error).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <opensubdiv/far/patchTable.h>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/clip_space.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/math.h"
#include "patchcull/gl/gl_compaction.h"
#include "patchcull/gl/gl_passes.h"

namespace patchcull::gl_osd {

/// The caller's vertex buffer: float3 positions (OpenSubdiv's shaders read x, y, z), every
/// refined level's vertices then the table's local points (import/osd_patch_table.h's "Points").
struct OsdVertexBuffer {
    std::uint32_t buffer = 0;
    std::size_t stride_bytes = 12;  ///< a multiple of 4, >= offset_bytes + 12
    std::size_t offset_bytes = 0;   ///< of x; a multiple of 4
    std::size_t point_count = 0;    ///< points the buffer holds
};

/// One view as both the draw and the passes see it: the object-to-view matrix (the TES's
/// OsdModelViewMatrix, a rigid transform), the projection written in `depth`, the eye in
/// object space.
struct OsdView {
    Mat4 model_view;
    Mat4 projection;
    ClipDepth depth = ClipDepth::zero_to_one;
    Vec3 eye{0, 0, 0};
    float tess_level = 4;    ///< OsdTessLevel(): OpenSubdiv's uniform level (1..16)
    bool one_sided = false;  ///< the one-sided rule above (closed shapes)
    CullView cull_view() const { return make_cull_view(model_view, projection, depth, eye); }
};

/// How OsdPatchTableDraw compiles OpenSubdiv's programs (both off: the programs described above).
struct OsdDrawOptions {
    /// OpenSubdiv's own TCS frustum culling as well: every stage is compiled with
    /// OSD_ENABLE_PATCH_CULL, so OpenSubdiv's vertex shader computes clip flags from
    /// OsdModelViewProjectionMatrix() and its OSD_PATCH_CULL(N) (kept as OpenSubdiv 3.5 defines it)
    /// gives a patch levels 0 unless, for each of x, y, z, some control point has c < w and some
    /// c > -w (a patch is skipped when all its points lie beyond one plane; the near plane is z = -w
    /// whatever view.depth says, looser than z = 0 for zero_to_one). The patch index comes from
    /// OpenSubdiv's OSD_USER_VARYING_PER_CONTROL_POINT hook instead, and patchcull's flags are
    /// checked there (invocation 0), before OpenSubdiv's test: a patch is drawn when both keep it.
    bool opensubdiv_patch_cull = false;
    /// Records the patches tessellated (levels non-zero): the TES writes 1 to the patch's word of
    /// a per-patch buffer, bound at SSBO binding 30 during a draw (an instrumented program: time
    /// draws without it). clear_tessellated()
    /// and tessellated_count() read it.
    bool record_tessellated = false;
};

/// Where OsdPatchTableDraw::compact writes and draw_indirect reads (GL buffer names; see there).
struct OsdDrawList {
    std::uint32_t list = 0;               ///< uint per patch of the table
    std::uint32_t commands = 0;           ///< command_count(patches_per_command) DrawArraysIndirectCommands
    std::uint32_t draw_count = 0;         ///< uint per array (0: none; then every command is drawn)
    std::size_t patches_per_command = 0;  ///< K (0: one command per array)
};

/// A feature-adaptive Far::PatchTable on the GPU with OpenSubdiv's programs for its arrays.
class OsdPatchTableDraw {
public:
    /// Uploads table (Osd::GLPatchTable, plus a byte per patch of boundary masks) and compiles
    /// OpenSubdiv's programs for the array types present. table: REGULAR and GREGORY_BASIS arrays
    /// only (Error naming the array and type otherwise); it need not outlive this object.
    OsdPatchTableDraw(gl::PassContext& passes, const OpenSubdiv::Far::PatchTable& table,
                      const OsdDrawOptions& options = {});
    OsdPatchTableDraw(OsdPatchTableDraw&&) noexcept;
    OsdPatchTableDraw& operator=(OsdPatchTableDraw&&) noexcept;
    ~OsdPatchTableDraw();

    /// Patches in the table: the size of the flag buffer (uint per patch, Far's order).
    std::size_t patch_count() const;
    /// 1 + the largest index a patch reads: OsdVertexBuffer::point_count must be at least this.
    std::size_t points_needed() const;
    /// The table's arrays as GpuPatchSources over vertices and flags (array a's flags are Far's
    /// patches [first, first + count)). Error for a bad vertex layout.
    std::vector<gl::GpuPatchSource> sources(const OsdVertexBuffer& vertices, std::uint32_t flags) const;
    /// Draws every array into the bound framebuffer (its viewport, depth test and clip control as
    /// the caller set them), keeping patch p when (flags[p] & mask) == value (patchcull_tcs.h);
    /// the fragment output 0 (R32UI) gets p + 1. Binds flags at kBindingCullFlags and the
    /// patch-param texture buffer at texture unit 4, sets GL_PATCH_VERTICES; leaves no program or
    /// VAO bound.
    void draw(const OsdVertexBuffer& vertices, std::uint32_t flags, std::uint32_t mask, std::uint32_t value,
              const OsdView& view) const;
    /// The compacted draw's buffers (OsdDrawList): the list holds patch_count() entries (array a's
    /// survivors from its first patch's entry on), the commands command_count(K) (array a's from
    /// command_first(a, K) on), the draw counts one uint per array.
    std::size_t array_count() const;
    std::size_t command_count(std::size_t patches_per_command) const;
    std::size_t command_first(std::size_t array, std::size_t patches_per_command) const;
    /// Lists, per array, the patches p with (flags[p] & mask) == value into out (CompactPass::run
    /// per array, then the Gregory-basis commands rescaled to 20 points a patch). Error for buffers
    /// too small.
    void compact(gl::CompactPass& pass, std::uint32_t flags, std::uint32_t mask, std::uint32_t value,
                 const OsdDrawList& out, gl::CompactMethod method = gl::CompactMethod::prefix_scan) const;
    /// Draws the listed patches only (as draw() with the selection done by compact()): per array
    /// glMultiDrawArraysIndirectCount over its commands with its draw count (GL 4.6 or
    /// GL_ARB_indirect_parameters; else glMultiDrawArraysIndirect over all its commands), the
    /// pulling programs. Binds the list at kBindingDrawList, the vertex buffer and the table's index
    /// buffer at kBindingSourceVertices / kBindingSourceIndices; otherwise as draw().
    void draw_indirect(const OsdVertexBuffer& vertices, std::uint32_t flags, const OsdDrawList& list,
                       const OsdView& view) const;
    /// The patches the commands of the last compact() into list issue (reads the commands back: a
    /// GL sync).
    std::size_t listed_count(const OsdDrawList& list) const;
    /// record_tessellated only (Error otherwise): zeroes the record; the patches tessellated by
    /// the draws since (each counted once), read back (a GL sync).
    void clear_tessellated() const;
    std::size_t tessellated_count() const;

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

/// How OsdCullFrame's draw passes issue patches (render --draw flags|indirect).
enum class OsdDrawMode { flags, indirect };

/// Which tests a frame runs (each off by default).
struct OsdCullSettings {
    bool frustum = false;
    std::optional<BackpatchMethod> backpatch;  ///< tcone, ncone or ptp: one-sided closed shapes only
    PtpRule ptp_rule = PtpRule::ncnt;
    bool occlusion = false;  ///< two-pass Hi-Z occlusion culling
    /// How each draw pass issues patches: flags (every patch; the TCS gives the culled ones
    /// levels 0) or indirect (CompactPass lists the pass's survivors per array, only those are
    /// issued; see the top of this header).
    OsdDrawMode draw = OsdDrawMode::flags;
    gl::CompactMethod compact = gl::CompactMethod::prefix_scan;  ///< indirect's list order
};

/// What one culled frame did (CullStatusPass's counters).
struct OsdFrameStats {
    std::size_t frustum = 0, backpatch = 0, occlusion = 0;  ///< patches culled per reason
    std::size_t drawn_pass1 = 0, drawn_pass2 = 0;           ///< drawn in pass 1 / pass 2 (or the one pass)
    /// Issued by each draw pass: flags every patch (pass 2 0 in one pass), indirect the listed
    /// patches (read back from the commands).
    std::size_t submitted_pass1 = 0, submitted_pass2 = 0;
};

/// The frame's targets (an R32UI id texture, a DEPTH32F depth texture, width x height), the flag
/// buffer and the Hi-Z pyramid, for one table. The flag buffer keeps the statuses from frame to
/// frame (temporal coherence); reset() primes it as Niessner & Loop §3 do (even patches visible).
class OsdCullFrame {
public:
    /// width, height in [1, 8192]. draw must outlive the frame (it is kept by reference).
    OsdCullFrame(gl::PassContext& passes, const OsdPatchTableDraw& draw, int width, int height);
    OsdCullFrame(OsdCullFrame&&) noexcept;
    OsdCullFrame& operator=(OsdCullFrame&&) noexcept;
    ~OsdCullFrame();

    /// kStatusVisible on the even patches, 0 on the others.
    void reset();
    /// One culled frame: without occlusion, the chain (frustum, back-patch) then one draw of the
    /// unculled patches; with occlusion, the two-pass frame. Sets glClipControl, the viewport and
    /// the depth test for view.depth; leaves framebuffer 0 bound, the default clip control (lower
    /// left, -1..1), GL_LESS and the depth test off. Checks view and vertices before any GL work.
    OsdFrameStats render(const OsdVertexBuffer& vertices, const OsdView& view, const OsdCullSettings& settings);
    /// Every patch drawn (the reference); the flags are left as they were.
    void render_unculled(const OsdVertexBuffer& vertices, const OsdView& view);
    /// The last frame's ids (row 0 = bottom; 0 background, p + 1 for Far's patch p) and window
    /// depths.
    std::vector<std::uint32_t> read_ids() const;
    std::vector<float> read_depth() const;
    std::uint32_t flag_buffer() const;
    int width() const;
    int height() const;

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace patchcull::gl_osd
