// patchcull/gl_renderer.h: the OpenGL 4.5 renderer (library patchcull_gl): a headless EGL
// context, bicubic patches drawn through hardware tessellation (TCS/TES) into an off-screen
// framebuffer, per-patch cull flags read by the TCS, and GPU cull passes (compute shaders) that
// mirror the CPU kernels.
//
// Conventions (as math.h, frustum.h and displacement.h):
// - Patches are in object space = world space (no model matrix); render parameters give view and
//   projection, object_to_clip = projection * view. Clip space is GL's with
//   glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE): depth z/w in [0,1], larger = farther, cleared to 1,
//   depth test GL_LESS.
// - Framebuffer: RGBA8 colour, R32UI patch id, DEPTH32F; all read-backs are width*height values in
//   image order: row 0 is the TOP row (GL window row height-1), pixel (x, row) at [row*width + x].
// - Patch id buffer: 0 = background, patch index p (its position in the uploaded set) writes p + 1.
//   Ids with the top bit set are reserved for triangle-mesh occluders (not implemented yet; they
//   will be drawn by a separate call into the same framebuffer before or after the patches).
// - Cull flags: one uint per patch, 0 = draw, nonzero = culled (bit 1 frustum, 2 back-patch,
//   4 occlusion; shaders/shared.h). A culled patch gets tessellation levels 0 in the TCS and is
//   discarded by the tessellator (seed 000 §3, seed 002: cull in the patch-constant phase).
// - Tessellation: uniform integer level L (equal_spacing) on every edge and the interior, L in
//   [1, 64]; the surface is evaluated exactly (rational Bezier) at the (L+1)^2 tessellator points.
// - Displacement (optional, the rendered surface): S = B + D(s,t) n as in displacement.h, D from a
//   DisplacementMap uploaded as an R32F GL_REPEAT bilinear texture, (s,t) from per-patch corner
//   texcoords. Points where du x dv = 0 (degenerate patch corners) are not displaced. The cull
//   margin (per-patch max |D|) is given separately, so tests can check that it bounds the surface.
//
// Workarounds for Mesa llvmpipe (../shared/PLATFORM.md), applied ALWAYS (they cost nothing
// measurable on a GPU and keep one code path):
// 1. gl_PrimitiveID restarts every 4096 input vertices on llvmpipe: the patch index is derived as
//    gl_VertexID / 16 in the vertex shader and passed on; gl_PrimitiveID is never used.
// 2. llvmpipe emits garbage when one 4096-vertex chunk yields more than 65536 tessellated vertices:
//    every draw is split with glMultiDrawArrays into sub-draws of at most
//    max(1, 65536 / (L+1)^2) patches (809 at L = 8, 226 at L = 16, 15 at L = 64).
// On llvmpipe GL timer queries measure only part of the work: time with a wall clock around
// finish(). On a real GPU use timer queries.
//
// Threads and lifetime: a GlContext is current on the thread that created it; every other object
// here must be created, used and destroyed on that thread while the context lives (destroy
// renderers before their context). Objects are move-only.
//
// Linking: patchcull_gl links libepoxy, which loads libEGL.so.1 and libOpenGL.so.0 (or libGL.so.1)
// at run time; binaries start without them and create_headless() reports their absence.
//
// Planned, not implemented yet (the API leaves room for them): triangle-mesh occluders
// (set_occluders(positions, triangles): drawn by render() before the patches, ids
// kIdOccluderBit | mesh index), the back-patch and Hi-Z occlusion passes (more cull_* calls ORing
// their bits into the same flags), and a GLFW window context beside create_headless().
//
// Errors: factories and calls that can fail throw patchcull::Error with a one-line message
// ("EGL: no display ...", "GL: shader patch.tesc.glsl: <first log line>", "GL: error 0x0502 after
// render"). patchcull prints nothing (Mesa itself may write driver warnings to stderr).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "patchcull/displacement.h"
#include "patchcull/error.h"
#include "patchcull/frustum.h"
#include "patchcull/math.h"
#include "patchcull/patch.h"

namespace patchcull::gl {

/// An OpenGL 4.5 core context without a window.
class GlContext {
public:
    /// Creates a headless context and makes it current on the calling thread. Tries, in order:
    /// an EGL device (EGL_EXT_platform_device) that is not Mesa's software device (a GPU), then
    /// Mesa's surfaceless platform (EGL_MESA_platform_surfaceless: llvmpipe without a GPU), then
    /// the software EGL device. Throws patchcull::Error with a one-line message naming the last
    /// failure when none gives a GL 4.5 core context (e.g. "EGL: no display: ...").
    static GlContext create_headless();

    GlContext(GlContext&&) noexcept;
    GlContext& operator=(GlContext&&) noexcept;
    GlContext(const GlContext&) = delete;
    GlContext& operator=(const GlContext&) = delete;
    ~GlContext();

    /// Makes this context current on the calling thread (needed only after another context was).
    void make_current() const;

    /// GL_RENDERER, GL_VENDOR and GL_VERSION strings.
    const std::string& renderer() const;
    const std::string& vendor() const;
    const std::string& version() const;
    /// How the display was obtained: "device" (GPU), "surfaceless" or "software-device".
    const std::string& platform() const;
    /// True for a software rasterizer (llvmpipe, softpipe, swrast).
    bool is_software() const;

    struct Impl;

private:
    explicit GlContext(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

/// Per-patch data beyond the control points. Each vector is empty (absent) or has one entry per
/// patch.
struct PatchAttributes {
    /// Cull margin: bound on |D| of the rendered displacement (DisplacementRange::max_abs()), >= 0.
    /// Read by the GPU frustum pass exactly as cull_frustum_scalar reads max_displacement.
    std::vector<float> max_displacement;
    /// Corner texcoords at (u,v) = (0,0), (1,0), (0,1), (1,1) (PatchInfo::uv) for displacement;
    /// absent means those same four values for every patch (PatchInfo's default).
    std::vector<std::array<Vec2, 4>> texcoords;
};

/// Parameters of one frame.
struct RenderParams {
    Mat4 view;        ///< world -> view (look_at); also gives the eye position for shading
    Mat4 projection;  ///< view -> clip (perspective, depth [0,1])
    int width = 256;
    int height = 256;
    int tess_level = 8;           ///< uniform tessellation level, clamped to [1, 64]
    bool use_cull_flags = true;   ///< false: ignore the flags and draw every patch (the reference)
    bool displace = true;         ///< displace the surface when a displacement map is set
};

/// Draws one uploaded set of patches with hardware tessellation into its own framebuffer.
class PatchRenderer {
public:
    /// Makes ctx current and compiles the embedded shaders (shaders/*.glsl), then checks GLSL fma()
    /// (see fma_via_double). Throws patchcull::Error("GL: shader NAME: <log>") when the driver
    /// rejects one, or when ctx lacks GL 4.5 core. Control points must be finite with w > 0.
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
    std::size_t patch_count() const;

    /// True when the cull passes compute once-rounded multiply-adds in double precision
    /// (shaders/exact_fma.h): on software rasterizers (llvmpipe rounds GLSL fma() twice), and on a
    /// GPU whose GLSL fma() failed the constructor's check (a few cases next to float midpoints).
    bool fma_via_double() const;

    /// Sets the height map the TES samples (a copy goes to the GPU); an empty map (the initial
    /// state) turns displacement off. Throws patchcull::Error when texels.size() != width*height.
    void set_displacement_map(const DisplacementMap& map);

    // ---- cull flags --------------------------------------------------------------------------
    /// Sets every flag to 0 (draw every patch).
    void clear_cull_flags();
    /// Uploads flags from a CPU kernel: culled[p] nonzero sets flag kCullFrustum (1) on patch p,
    /// zero sets 0; culled holds patch_count() bytes.
    void set_cull_flags(const std::uint8_t* culled);
    /// Reads the flags back (patch_count() values; 0 = draw). Waits for the GPU.
    std::vector<std::uint32_t> read_cull_flags() const;

    /// The GPU frustum pass (shaders/cull_frustum.comp.glsl, one invocation per patch): writes
    /// flag kCullFrustum (1) or 0 for every patch, overwriting the flags, from the control points,
    /// the max_displacement margins and planes. Makes the same decisions as cull_frustum_scalar on
    /// the same inputs (same operations, a once-rounded multiply-add where the CPU uses std::fma;
    /// on llvmpipe, which flushes subnormals to zero, values below 1.2e-38 in magnitude may differ).
    /// When plane_values is non-null it also receives, per patch, the six maxima over the control
    /// points of the plane values that the decision compares with 0 (6 * patch_count() floats,
    /// patch-major): a diagnostic for tests of the arithmetic. Only plane_values waits for the GPU.
    /// At most 65535 * 64 patches (one dispatch), else throws patchcull::Error.
    void cull_frustum(const FrustumPlanes& planes, std::vector<float>* plane_values = nullptr);

    // ---- drawing -----------------------------------------------------------------------------
    /// Clears the framebuffer (colour dark grey, id 0, depth 1) and draws every patch whose flag is
    /// 0 (every patch when !use_cull_flags), resizing the framebuffer to width x height when it
    /// changed (each in [1, 8192], else throws). Does not wait for the GPU. Throws
    /// patchcull::Error("GL: error 0x.... after render") when GL reports an error.
    void render(const RenderParams& params);

    /// Waits until every command issued so far has completed (glFinish): the end point of a
    /// wall-clock measurement.
    void finish() const;

    // ---- read-back of the last render (waits for the GPU; image order, row 0 = top) ----------
    int width() const;
    int height() const;
    std::vector<std::uint32_t> read_ids() const;     ///< patch index + 1, 0 = background
    std::vector<float> read_depth() const;           ///< window depth in [0,1], 1 = background
    std::vector<std::uint8_t> read_color() const;    ///< RGBA8, 4 bytes per pixel
    /// Writes the colour image of the last render as a PNG. Throws patchcull::Error("PATH: cannot
    /// write PNG") on failure.
    void write_color_png(const std::string& path) const;

    struct Impl;

private:
    bool native_fma_rounds_once();
    std::unique_ptr<Impl> impl_;
};

/// Writes an id buffer (as read_ids returns it) as a PNG with one distinct colour per id, black
/// for the background: for looking at false culls. Throws patchcull::Error on failure.
void write_ids_png(const std::string& path, const std::vector<std::uint32_t>& ids, int width, int height);

}  // namespace patchcull::gl
