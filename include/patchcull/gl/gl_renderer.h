// patchcull/gl/gl_renderer.h: the OpenGL 4.5 renderer (library patchcull_gl): bicubic patches
// drawn through hardware tessellation (TCS/TES) into an off-screen framebuffer, with per-patch cull
// flags read by the TCS and triangle-mesh occluders, on a GlContext (gl_context.h: headless EGL or
// a window). The flag word, spans and cull modes are gl_cull_flags.h's; comparing a culled frame
// with its reference is gl_verification.h's. This header includes gl_context.h and gl_cull_flags.h.
// The renderer only draws: the cull passes are gl_passes.h's (they run on any context and any
// buffers), and gl_pipeline.h's CullPipeline chains them with this renderer into Niessner & Loop §3's
// two-pass temporal-coherence frame.
//
// Conventions (as math.h, frustum.h, hiz.h and displacement.h):
// - Patches are in object space = world space (no model matrix); render parameters give view and
//   projection, object_to_clip = projection * view. Clip space is GL's with
//   glClipControl(GL_LOWER_LEFT, ...) in the depth convention RenderParams::depth names
//   (clip_space.h): zero_to_one (the default: depth cleared to 1, GL_LESS), minus_one_to_one (GL's
//   own, drawn with GL_NEGATIVE_ONE_TO_ONE), reversed and reversed_infinite (cleared to 0,
//   GL_GREATER). RenderParams::projection must be written in it. An object far from the origin
//   stays in its local frame (ControlMesh::origin) and the camera comes into it in double
//   (WorldCamera::local, camera.h): every GL float then holds object-sized numbers.
// - Framebuffer: RGBA8 colour, R32UI patch id, DEPTH32F; all read-backs of it are width*height
//   values in image order: row 0 is the TOP row (GL window row height-1), pixel (x, row) at
//   [row*width + x]. (Hi-Z read-backs, read_hiz_texture, keep hiz.h's order instead: row 0 = bottom.)
// - Patch id buffer: 0 = background, patch index p (its position in the uploaded set) writes p + 1.
//   Triangle t of the occluder mesh (set_occluders) writes kIdOccluderBit | t.
// - Flag word: one uint per patch (flag_buffer()), read by the TCS: bits 0-7 the cull reason
//   (kCullFrustum, kCullBackPatch, kCullOcclusion), bits 8-9 the temporal status (kStatusVisible,
//   kStatusNewlyVisible), as gl_cull_flags.h states. A culled patch is not tessellated.
// - Tessellation: uniform integer level L (equal_spacing) on every edge and the interior, L in
//   [1, 64], scaled by 2^(D - depth) per patch for sets of mixed refinement depth
//   (PatchAttributes::depth), or adaptive by distance (RenderParams::adaptive_tess, Niessner & Loop
//   §6.3); the surface is evaluated exactly (rational Bezier) at the tessellator points.
// - Shading normal: du x dv of the patch's ACC tangent patches where it has them
//   (PatchAttributes::tangents; continuous across extraordinary vertices), else of the patch's own
//   derivatives. The geometry never depends on it.
// - Displacement (optional, the rendered surface): S = B + D(s,t) n as in displacement.h, D from a
//   DisplacementMap uploaded as an R32F GL_REPEAT bilinear texture, (s,t) from per-patch corner
//   texcoords. Points where du x dv = 0 (degenerate patch corners) are not displaced. The cull
//   margin (per-patch max |D|, PatchAttributes::max_displacement or the ranges' max_abs) is given
//   separately, so tests can check that it bounds the surface. With margins, a patch whose margin
//   is 0 is drawn undisplaced (D = 0 there anyway; shaders/patch_displaced.h), so one map can
//   serve a scene of displaced and plain objects. Displaced patches are drawn two-sided and culled
//   by the frustum pass (with their margin) and the displaced pass (Niessner & Loop §4.2's bounds, from
//   PatchAttributes::displacement_ranges); never by the back-patch or control-point Hi-Z tests.
//
// Workarounds for Mesa llvmpipe (22.3.6 and still in 25.0.7), applied ALWAYS (they cost nothing
// measurable on a GPU and keep one code path):
// 1. gl_PrimitiveID restarts every 4096 input vertices on llvmpipe: the patch index is derived as
//    gl_VertexID / 16 in the vertex shader and passed on; gl_PrimitiveID is never used (occluder
//    triangle ids likewise come from gl_VertexID / 3).
// 2. llvmpipe emits garbage when one 4096-vertex chunk yields more than 65536 tessellated vertices:
//    every draw is split with glMultiDrawArrays into sub-draws of at most
//    max(1, 65536 / (L+1)^2) patches (809 at L = 8, 226 at L = 16, 15 at L = 64), L the uniform
//    level or the adaptive maximum (patches_per_draw(); the indirect draws of compacted lists are
//    split by their commands: CompactPass's patches_per_command).
//
// Threads, lifetime and errors as gl_context.h: renderers are created, used and destroyed on their
// context's thread while it lives (destroy them before it), are move-only, and throw
// patchcull::Error with a one-line message ("GL: shader patch.tesc.glsl: <first log line>", "GL:
// error 0x0502 after render").
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "patchcull/core/clip_space.h"
#include "patchcull/core/displacement.h"
#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"
#include "patchcull/core/render_params.h"
#include "patchcull/gl/gl_context.h"
#include "patchcull/gl/gl_cull_flags.h"
#include "patchcull/gl/gl_passes.h"

namespace patchcull::gl {

/// PatchAttributes and RenderParams are core/render_params.h's (the Vulkan renderer takes them too).
using patchcull::PatchAttributes;
using patchcull::RenderParams;

/// A compacted draw (PatchRenderer::draw_indirect): GL buffer names of a list and the indirect
/// commands CompactPass (gl_compaction.h) wrote.
struct IndirectDraw {
    std::uint32_t list = 0;             ///< the draw list (uint patch indices)
    std::uint32_t commands = 0;         ///< DrawArraysIndirectCommands over the list
    std::size_t first_command = 0;      ///< the first command drawn (an index, 16 bytes each)
    std::size_t command_count = 0;      ///< commands drawn (the maxdrawcount with a draw count)
    std::uint32_t draw_count = 0;       ///< optional (0: none): the draw count's buffer
    std::size_t draw_count_offset = 0;  ///< bytes, a multiple of 4
};

/// Draws one uploaded set of patches with hardware tessellation into its own framebuffer.
class PatchRenderer {
public:
    /// Makes ctx current and compiles the embedded drawing shaders (shaders/*.glsl). Throws
    /// patchcull::Error("GL: shader NAME: <log>") when the driver rejects one, or when ctx lacks
    /// GL 4.5 core. Weights must be positive: set_patches and update_patches throw Error naming the
    /// patch and point otherwise (patch.h).
    explicit PatchRenderer(const GlContext& ctx);
    PatchRenderer(PatchRenderer&&) noexcept;
    PatchRenderer& operator=(PatchRenderer&&) noexcept;
    PatchRenderer(const PatchRenderer&) = delete;
    PatchRenderer& operator=(const PatchRenderer&) = delete;
    ~PatchRenderer();

    /// Uploads the patches (16 control points each, patch.h order) and their attributes, replacing
    /// the previous set; all cull flags become 0 (draw). attributes' vectors must be empty or hold
    /// patches.size() entries (else throws patchcull::Error). Patch index p is patches[p].
    void set_patches(const std::vector<BezierPatch>& patches, const PatchAttributes& attributes = {});
    /// Same from a structure-of-arrays batch (patches.count patches).
    void set_patches(const PatchBatchView& patches, const PatchAttributes& attributes = {});
    /// Animation: replaces the control points (and attributes) of the uploaded set by those of
    /// the same patches in a new pose, KEEPING the flag words, so the pipeline's temporal status
    /// carries over to the next frame (Niessner & Loop §3 with animated patches). Throws
    /// patchcull::Error when patches.size() != patch_count() or an attribute vector has the
    /// wrong size.
    void update_patches(const std::vector<BezierPatch>& patches, const PatchAttributes& attributes = {});
    std::size_t patch_count() const;
    /// The renderer's GL objects, in gl_passes.h's layouts, for the cull passes (CullPipeline, or
    /// a caller's own chain). Their names stay the same for the renderer's lifetime
    /// (set_patches/update_patches re-specify the buffers' storage, not their names).
    /// patch_buffer: vec4 cp[16 * patch_count()]; flag_buffer: uint per patch (the TCS reads it);
    /// margin_buffer: float per patch, 0 when the set has no margins; range_buffer: vec2
    /// DisplacementRange per patch, 0 when the set has no ranges; depth_texture: the framebuffer's
    /// DEPTH32F attachment (width() x height(): the Hi-Z build's input).
    std::uint32_t patch_buffer() const;
    std::uint32_t flag_buffer() const;
    std::uint32_t margin_buffer() const;
    std::uint32_t range_buffer() const;
    std::uint32_t depth_texture() const;
    /// The ACC tangent vectors the TES shades with: 24 vec4 per patch (shaders/shared.h's
    /// kBindingPatchTangents layout) when the set was given tangents (PatchAttributes::tangent_index
    /// not empty), else a 16-byte placeholder. For writers that pose on the GPU (gl_posing.h).
    std::uint32_t tangent_buffer() const;
    /// Bytes the last set_patches / update_patches copied to GL (control points and every
    /// attribute buffer): what re-posing on the CPU uploads per frame.
    std::size_t last_upload_bytes() const;
    /// The ascending runs of patches a pass that skips displaced patches needs: undisplaced_runs
    /// holds every patch whose margin is not > 0 (the back-patch tests and the Hi-Z test of
    /// OcclusionPass skip the others), displaced_runs every patch with a displacement range other
    /// than (0, 0) (what DisplacedPass tests with only_displaced): core/patch_runs.h's
    /// displacement_runs of the last set_patches / update_patches. CullPipeline dispatches those
    /// passes on them alone (on llvmpipe a patch a pass returns from at once costs as much as one
    /// it tests).
    const std::vector<PatchSpan>& undisplaced_runs() const;
    const std::vector<PatchSpan>& displaced_runs() const;
    /// {patch_buffer, flag_buffer, margin_buffer, 0, patch_count()}: the whole set for a pass.
    PatchBuffers patch_buffers() const;
    /// True while a displacement map is set (set_displacement_map with a non-empty map).
    bool displaces() const;

    /// Sets the height map the TES samples (a copy goes to the GPU); an empty map (the initial
    /// state) turns displacement off. Throws patchcull::Error when texels.size() != width*height.
    void set_displacement_map(const DisplacementMap& map);

    // ---- cull flags --------------------------------------------------------------------------
    /// Sets every flag word to 0 (draw every patch; no status).
    void clear_cull_flags();
    /// Uploads flags from a CPU kernel: culled[p] nonzero sets the word of patch p to kCullFrustum
    /// (1), zero sets 0; culled holds patch_count() bytes.
    void set_cull_flags(const std::uint8_t* culled);
    /// Reads the flag words back (patch_count() values; bits 0-7 = cull reason, 0 = drawn by
    /// render(); bits 8-9 = status). Waits for the GPU.
    std::vector<std::uint32_t> read_cull_flags() const;
    /// Writes the flag words (patch_count() values, else throws), e.g. a pipeline's first-frame
    /// statuses.
    void set_flag_words(const std::vector<std::uint32_t>& words);
    /// Counts the times the flag words were replaced from the CPU (set_patches, clear_cull_flags,
    /// set_cull_flags, set_flag_words; not update_patches or GPU passes): a pipeline that sees it
    /// change starts again from a first frame.
    std::uint64_t flag_generation() const;

    // ---- occluders ---------------------------------------------------------------------------
    /// Sets the triangle-mesh occluders (Niessner & Loop §3), replacing the previous ones: triangle t has
    /// corners vertices[indices[3t + i]] (object space). They are drawn by render() and
    /// begin_frame() before any patch, with ids kIdOccluderBit | t, so they occlude
    /// patches through the depth buffer and the Hi-Z pyramid. Empty vectors remove them. Throws
    /// patchcull::Error when indices.size() is not a multiple of 3, an index is out of range, or
    /// there are 2^31 triangles or more.
    /// one_sided: triangle spans drawn with back faces culled (counter-clockwise = front, as
    /// GL's default): the environment objects that show nothing from behind (closed outward solids,
    /// a ground seen from above), so that back-face culling them at the object level removes no
    /// pixel (object_culling.h). The other triangles are drawn two-sided. Spans must lie within the
    /// triangles (else throws). Clears the culled spans (set_culled_occluders).
    void set_occluders(const std::vector<Vec3>& vertices, const std::vector<std::uint32_t>& indices,
                       const std::vector<TriangleSpan>& one_sided = {});
    std::size_t occluder_triangle_count() const;
    /// Occluder triangles culled by the object level: begin_frame() and render() with
    /// use_cull_flags skip them; render() without use_cull_flags (the unculled reference) draws
    /// every triangle. Spans may overlap and come in any order; each must lie within the triangles
    /// (else throws). An empty vector culls none.
    void set_culled_occluders(const std::vector<TriangleSpan>& culled);

    /// For occlusion queries on the frame being drawn (gl_object_queries.h): binds the frame's
    /// framebuffer (after begin_frame) with depth test GL_LEQUAL, neither colour nor depth
    /// writes and no face culling, so that the caller's proxies, drawn with its own program and
    /// vertex array, only test against the depth drawn so far. end_depth_test_draws restores the
    /// state the renderer's draws assume and unbinds; call it before the next draw_selected.
    void begin_depth_test_draws();
    void end_depth_test_draws();

    // ---- drawing -----------------------------------------------------------------------------
    /// Clears the framebuffer (colour dark grey, id 0, depth 1), draws the occluders, then every
    /// patch whose cull reason (flag bits 0-7) is 0 (every patch when !use_cull_flags), resizing
    /// the framebuffer to width x height when it changed (each in [1, 8192], else throws). Does not
    /// wait for the GPU. Throws patchcull::Error("GL: error 0x.... after render") when GL reports
    /// an error.
    void render(const RenderParams& params);

    /// The two steps of render() for a pipeline's passes: begin_frame clears the framebuffer
    /// (resized to params' size as render() does), draws the occluders and makes params the
    /// frame's camera and tessellation (and clears the drawn marks, read_drawn_patches);
    /// draw_selected then draws, over what is there, the patches whose flag word w has
    /// (w & mask) == value (shaders/patchcull_tcs.h's selections, e.g. kStatusVisible twice for
    /// the first pass of Niessner & Loop §3), as many times as needed. params.use_cull_flags is ignored.
    void begin_frame(const RenderParams& params);
    void draw_selected(std::uint32_t mask, std::uint32_t value);
    /// draw_selected restricted to the patches of spans (disjoint, any order, within the set, else
    /// throws): the patches of objects culled whole are never issued, so they cost no TCS work.
    void draw_selected(std::uint32_t mask, std::uint32_t value, const std::vector<PatchSpan>& spans);
    /// draw_selected's compacted form (gl_compaction.h): draws, over what is there, the patches of
    /// a list CompactPass wrote, without issuing the others: the commands [first_command,
    /// first_command + command_count) of draw.commands (DrawArraysIndirectCommand), each vertex
    /// pulling its control point by its list entry (shaders/patchcull_draw_list.h), every listed
    /// patch tessellated (no flag check) and recorded for read_drawn_patches as draw_selected's
    /// are. With draw.draw_count and has_indirect_count(): glMultiDrawArraysIndirectCount(ARB)
    /// (drawcount from that buffer at draw_count_offset, at most command_count); else
    /// glMultiDrawArraysIndirect of all command_count commands. Throws patchcull::Error when the
    /// list or command buffer is 0, the commands leave their buffer, or the draw-count offset is
    /// not a multiple of 4. For the llvmpipe note above, write the list with at most
    /// patches_per_draw() patches per command.
    void draw_indirect(const IndirectDraw& draw);
    /// At most this many patches in one sub-draw at begin_frame's tessellation (the llvmpipe
    /// workaround 2 above): the split of draw_selected, and CompactPass's patches_per_command for
    /// draw_indirect.
    std::size_t patches_per_draw() const;
    /// glMultiDrawArraysIndirectCount is there (GL 4.6 or GL_ARB_indirect_parameters).
    bool has_indirect_count() const;

    /// Visualisation (Niessner & Loop, Fig. 2's statuses): renders every patch, ignoring the flags, with a
    /// colour from its flag word, and the occluders in grey, seen through `view` (its camera, size
    /// and tessellation; use_cull_flags ignored), into a separate image (the framebuffer keeps the
    /// last frame). Legend:
    ///   green   visible (passed the latest test, was tagged visible: drawn in pass 1)
    ///   yellow  newly visible (passed, was not tagged visible: drawn in pass 2)
    ///   blue    frustum-culled
    ///   magenta back-patch-culled
    ///   red     occlusion-culled
    ///   cyan    culled with its object (object level, before the patch passes)
    ///   grey    no status yet (before any test); occluders a darker neutral grey
    /// With the frame's own camera no red or magenta patch may show in front (that would be a false
    /// cull); another camera shows the culled patches. Returns RGBA8, row 0 = top. Waits.
    std::vector<std::uint8_t> render_status_image(const RenderParams& view);
    /// render_status_image written as a PNG. Throws patchcull::Error("PATH: cannot write PNG").
    void write_status_png(const std::string& path, const RenderParams& view);

    /// Waits until every command issued so far has completed (glFinish): the end point of a
    /// wall-clock measurement.
    void finish() const;

    // ---- what a frame drew, for verification (waits for the GPU) -----------------------------
    /// One byte per patch: 1 when the last render(), or a draw_selected() since the last
    /// begin_frame(), tessellated it (levels > 0 in the TCS, in any pass), else 0 (culled). This, not the id buffer, is
    /// what a false cull is judged on: a drawn patch that loses a depth tie is absent from the id buffer.
    std::vector<std::uint8_t> read_drawn_patches() const;
    /// The front set of the last render: redraws the patches (params must be the last render's:
    /// camera, size, tessellation, use_cull_flags, discard_back_facing) with depth test GL_EQUAL
    /// against its depth buffer, no colour or depth writes, and returns one byte per patch: 1 when
    /// some fragment of the patch lies exactly at the front depth of its pixel (the patch
    /// contributes a pixel, including every patch of a depth tie, which the id buffer shows only
    /// one of). Leaves the framebuffer as it was. Throws patchcull::Error on a size mismatch.
    std::vector<std::uint8_t> mark_front_patches(const RenderParams& params);

    // ---- read-back of the last render (waits for the GPU; image order, row 0 = top) ----------
    int width() const;
    int height() const;
    std::vector<std::uint32_t> read_ids() const;  ///< patch index + 1, 0 = background
    std::vector<float> read_depth() const;        ///< window depth in [0,1], background 1 (0 reversed)
    /// The depth buffer with row 0 = bottom, hiz.h's order: what HiZPyramid::build takes as it is.
    std::vector<float> read_depth_bottom_up() const;
    std::vector<std::uint8_t> read_color() const;  ///< RGBA8, 4 bytes per pixel
    /// Writes the colour image of the last render as a PNG. Throws patchcull::Error("PATH: cannot
    /// write PNG") on failure.
    void write_color_png(const std::string& path) const;
    /// Copies the colour image of the last frame to the current context's window (the default
    /// framebuffer's back buffer) of window_width x window_height pixels, scaled to fill it
    /// (nearest texel). For GlContext::create_window contexts; then swap_buffers shows it.
    void blit_color_to_window(int window_width, int window_height) const;

    struct Impl;

private:
    void begin_frame_drawing(const RenderParams& params, bool honour_occluder_culls);
    std::unique_ptr<Impl> impl_;
    std::size_t last_upload_bytes_ = 0;
};

}  // namespace patchcull::gl
