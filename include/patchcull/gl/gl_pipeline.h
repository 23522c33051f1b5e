// patchcull/gl/gl_pipeline.h: the whole per-frame cull pipeline of one patch set on the GPU (library
// patchcull_gl): Niessner & Loop's two-pass temporal-coherence frame ("Patch-Based Occlusion
// Culling for Hardware Tessellation", Niessner & Loop §3, Fig. 2), built from the passes of gl_passes.h
// chained through the renderer's flag buffer, with PatchRenderer (gl_renderer.h) drawing. No
// decision is read back to the CPU; only the counters are (FrameStats).
//
// One frame with occlusion in the mode:
//   1. clear, occluders, the patches tagged visible by the previous frame (draw pass 1);
//   2. HiZBuildPass from that depth buffer;
//   3. the flag chain: CullStatusPass::begin; FrustumPass (with the displacement margins; or
//      FrustumDispPass, PipelineParams::frustum);
//      the back-patch pass of PipelineParams::backpatch (BackpatchConePass or BackpatchPtpPass;
//      displaced patches skipped); OcclusionPass (control-point boxes; displaced patches
//      skipped) - or those three as one FusedCullPass (PipelineParams::fused_pass);
//      DisplacedPass (Niessner & Loop §4.2's bound of each displaced patch, against the frustum
//      and the same pyramid); CullStatusPass::end (statuses, counters). The passes that skip
//      displaced (undisplaced) patches are dispatched on PatchRenderer::undisplaced_runs()
//      (displaced_runs()) alone, one dispatch per run of adjacent tested objects;
//   4. the newly visible patches (draw pass 2; skipped when aggressive).
// Without occlusion: the chain (without the Hi-Z passes; the displaced pass then tests the
// frustum only), then clear, occluders and the patches that passed (one draw).
// The first frame after set_patches or reset_visibility tags the even-indexed patches visible
// (Niessner & Loop §3: half of them). Conservative (except aggressive): the final id buffer equals the
// unculled render's, up to exact depth ties between patches (the draw order differs).
//
// Timing: on llvmpipe GL timer queries measure only part of the work (the vertex/tessellation
// stage, not rasterization), so passes are timed with a wall clock around glFinish() there; on a
// real GPU with GL_TIMESTAMP queries (FrameStats::timing says which).
//
// Threads, lifetime and errors as gl_renderer.h (patchcull::Error with one-line messages).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/displaced_bounds.h"
#include "patchcull/core/patch.h"
#include "patchcull/gl/gl_compaction.h"
#include "patchcull/gl/gl_passes.h"
#include "patchcull/gl/gl_renderer.h"

namespace patchcull::gl {

/// How a frame times its passes.
enum class TimingMethod {
    automatic,    ///< wall_clock on a software rasterizer, timer_query on a GPU
    wall_clock,   ///< steady_clock around glFinish() after each pass (serializes the passes)
    timer_query,  ///< GL_TIMESTAMP queries between passes (no stall; results read at frame end)
    off,          ///< no timing (every *_ms is 0)
};
const char* timing_method_name(TimingMethod method);  ///< "automatic", "wall-clock", "timer-query", "off"

/// How a frame's draw passes issue their patches.
/// flags: every patch of the drawn spans is issued (vertex shader for its 16 points, TCS once),
/// and the TCS gives the ones the pass does not keep tessellation levels 0 (patchcull_tcs.h).
/// indirect: before each draw, CompactPass (gl_compaction.h) lists the patches the pass keeps
/// (the same (mask, value) selection), and PatchRenderer::draw_indirect draws only those: a culled
/// patch costs nothing in the draw. The same patches are tessellated either way, so the image,
/// the flag words and the counters are the same.
enum class DrawMode { flags, indirect };
const char* draw_mode_name(DrawMode mode);  ///< "flags", "indirect"

/// Parameters of one frame of the culling pipeline.
struct FrameParams {
    RenderParams render;  ///< camera, size, tessellation (use_cull_flags is ignored)
    CullMode cull = CullMode::all;
    /// Niessner & Loop §3.1: skip the second pass (newly visible patches appear one frame late). NOT
    /// conservative for the current frame: its image can miss patches that became visible; the
    /// status update still fixes the next frame (identical again after one static frame).
    bool aggressive = false;
    TimingMethod timing = TimingMethod::automatic;
};

/// One object of the patch set: the patches [first, first + count), culled or not this frame.
/// An object with cull = false is drawn whole (its flag words get kStatusVisible), its tests are
/// not run: the per-object switch of Niessner & Loop §6.3 (culling an object costs more than it saves
/// when it is small on screen or almost all visible).
struct ObjectRange {
    std::size_t first = 0;
    std::size_t count = 0;
    bool cull = true;
};

/// Counts of one object in a frame (FrameStats::objects), as FrameStats's.
struct ObjectStats {
    std::size_t patches = 0, frustum_culled = 0, backpatch_culled = 0, occlusion_culled = 0, visible = 0;
    std::size_t object_culled = 0;  ///< in PipelineParams::object_culled
};

/// The frustum test of the flag chain. hull: FrustumPass (Niessner & Loop §4.1.1: every control
/// point outside one clip plane, displaced patches with their margin scaled by each plane's
/// normal), then for displaced patches DisplacedPass's bound (PipelineParams::bound) against the
/// frustum too. aabb: FrustumDispPass (Sathe: the control points' object-space box, grown by
/// max |D| on every side) for every patch, displaced ones included; DisplacedPass then runs only
/// in modes with occlusion, for its Hi-Z test (its bound's frustum test may still cull there what
/// the box kept). Both are conservative; aabb's box contains hull's points, so it culls fewer
/// undisplaced patches, and no CAF/OOBB is built for the frustum alone.
enum class FrustumTest { hull, aabb };
const char* frustum_test_name(FrustumTest test);  ///< "hull", "aabb"

/// What an ObjectPass draws with (CullPipeline gives it one per frame).
class ObjectDrawer {
public:
    /// Draws object i of PipelineParams::objects (an index into that vector) over what is in the
    /// frame's framebuffer: in a two-pass mode its patches tagged visible (the first pass's
    /// selection), otherwise its patches after the frame's patch tests (the chain runs on the
    /// object first). Object-culled spans are never drawn. A second call for the same object in
    /// one frame does nothing.
    virtual void draw(std::size_t object) = 0;
    /// The renderer drawing the frame (its framebuffer, for occlusion-query proxies:
    /// PatchRenderer::begin_depth_test_draws).
    virtual PatchRenderer& renderer() = 0;

protected:
    ~ObjectDrawer() = default;
};

/// Object-level occlusion inside the frame (gl_object_queries.h: hardware occlusion queries,
/// CHC, CHC++). CullPipeline calls run once per frame, after the clear and the occluders, in place
/// of the frame's first draw of PipelineParams::objects: the pass draws the objects it finds
/// visible through drawer.draw, in the order it chooses, issuing its queries between draws
/// against the depth buffer drawn so far. Every object it does not draw is culled for the frame
/// (its patches become object-culled: no patch test and no later draw). The caller answers for
/// those objects being invisible; a pass is conservative when it only leaves out objects whose
/// proxies are hidden behind what was already drawn (a subset of the final image).
class ObjectPass {
public:
    virtual ~ObjectPass() = default;
    virtual void run(ObjectDrawer& drawer) = 0;
};

/// Parameters of one pipeline frame: the frame and the choice of each test.
struct PipelineParams {
    FrameParams frame;
    /// The back-patch test: any method with a GPU pass (gl_backpatch_passes.h; the built-in ones
    /// are Loop, Niessner & Eisenacher's). A method without one: render_frame throws Error.
    BackpatchMethod backpatch = BackpatchMethod::tcone;
    PtpRule ptp_rule = PtpRule::ncnt;  ///< rule of ptp (ignored by the cones)
    /// Bound and cone of displaced patches (Niessner & Loop §4.2; used when the set has
    /// displacement_ranges and a displacement map is set).
    DisplacedBoundKind bound = DisplacedBoundKind::caf;
    NormalConeKind cone = NormalConeKind::acon;
    /// The frustum test of the chain (FrustumTest; hull is the pipeline's original behaviour).
    FrustumTest frustum = FrustumTest::hull;
    /// The fused pass: FusedCullPass (gl_passes.h) runs the frame's frustum, back-patch and
    /// Hi-Z tests in one dispatch per object in place of FrustumPass, BackpatchConePass and
    /// OcclusionPass, with the same decisions, so the frame (flag words, statuses, counts, image)
    /// is the same. Used where the choices allow it: frustum hull and back-patch tcone or ncone (or
    /// a mode without the back-patch test: BackpatchMethodInfo::fusable); with ptp, a method that
    /// is not fusable, or frustum aabb the separate passes run
    /// (FrameStats::fused_pass says which). Displaced patches keep their separate pass
    /// (DisplacedPass, after the fused one; the fused pass gives them the frustum test with their
    /// margin, as FrustumPass does). Its time is in FrameStats::cull_ms; backpatch_ms is 0.
    bool fused_pass = false;
    /// The objects (disjoint ranges, in any order, within the set), or empty: one object of every
    /// patch, culled. Patches outside every range are drawn unculled. Throws when a range leaves
    /// the set or two overlap.
    std::vector<ObjectRange> objects;
    /// Patches culled by the object level (object_culling.h: an object outside the frustum, a
    /// back-facing cluster) before the passes: no pass tests them and no draw issues them (no
    /// patch work on the GPU); their flag words become kCullObject with the status cleared, so a
    /// span that comes back next frame is tested and drawn as newly visible. Disjoint, any order,
    /// within the set (else render_frame throws). The caller answers for them being invisible.
    std::vector<PatchSpan> object_culled;
    /// Occluder triangles culled by the object level (PatchRenderer::set_culled_occluders, set at
    /// the start of the frame; the unculled reference still draws them).
    std::vector<TriangleSpan> culled_occluders;
    /// Object-level occlusion (ObjectPass), or null. Needs `objects`: it decides per object. With
    /// a mode without occlusion each object's patch tests run when the pass draws it; with
    /// occlusion the pass replaces draw pass 1 for the objects (the patches outside every object
    /// are drawn after it), then the Hi-Z pyramid is built and the chain and pass 2 run on the
    /// objects it drew. Its time counts in FrameStats::pass1_ms (one pass: the chain's too).
    ObjectPass* object_pass = nullptr;
    /// How the draw passes issue patches (DrawMode). indirect: each draw pass compacts its
    /// selection over its spans, one CompactPass range per span (an object's active spans, the
    /// gaps), into the pipeline's own list and command buffers (one set per draw pass: pass 1 =
    /// tagged visible by the previous frame, pass 2 = newly visible; the one-pass frame has one),
    /// with at most PatchRenderer::patches_per_draw() patches per command (a sixteenth of that on
    /// a software rasterizer, PassContext::is_software: llvmpipe tessellates large draws more
    /// slowly per patch), then draws what it
    /// compacted: where the context has glMultiDrawArraysIndirectCount (GL 4.6 or
    /// GL_ARB_indirect_parameters; PatchRenderer::has_indirect_count), one per span, each with
    /// its own range's draw count, so no command past a range's survivors is read; else one
    /// glMultiDrawArraysIndirect over all the commands of its spans (those past a range's
    /// survivors are empty). An ObjectPass's draws
    /// (CHC++'s included) compact and draw each object when it draws it. Nothing is read back
    /// for the draws; only FrameStats's read-back (after the frame) sums the commands.
    DrawMode draw = DrawMode::flags;
    /// The compaction of DrawMode::indirect (all give the same set; gl_compaction.h).
    /// fused_append: the lists the chain's end decides (pass 2 of a two-pass frame, the one-pass
    /// frame's draw without an object pass) are appended by CullStatusPass::end itself, each
    /// dispatch span into its range, as an atomic append would after it (no CompactPass for
    /// them); pass 1, the object pass's draws, and every list of a frame with object-culled
    /// spans (PipelineParams::object_culled, or objects the object pass left out: its dispatch
    /// spans then differ from its draw spans) use CompactPass's atomic_append.
    CompactMethod compact = CompactMethod::prefix_scan;
};

/// What one frame did. Counts are patches; each patch has exactly one of: frustum_culled,
/// backpatch_culled, occlusion_culled, object_culled, or it passed (visible = tagged visible for
/// the next frame).
struct FrameStats {
    std::size_t patches = 0;
    std::size_t object_culled = 0;     ///< in PipelineParams::object_culled, or of objects the ObjectPass left out
    std::size_t objects_left_out = 0;  ///< objects the ObjectPass did not draw (0 without one)
    bool two_pass = false;             ///< the mode includes occlusion (Niessner & Loop §3's pipeline)
    // "drawn" = tessellated (levels > 0). With DrawMode::flags every pass issues all patches of
    // its spans to the TCS (Niessner & Loop §6.3's RT_0 cost per pass), the others get levels 0
    // there; with DrawMode::indirect only the drawn ones are issued (pass*_submitted).
    std::size_t pass1_drawn = 0;     ///< patches drawn (tessellated) in the first pass
    std::size_t pass2_drawn = 0;     ///< ... in the second pass (newly visible; 0 when aggressive)
    std::size_t frustum_culled = 0;  ///< by a frustum test (a displaced patch's bound included)
    std::size_t backpatch_culled = 0;
    std::size_t occlusion_culled = 0;            ///< by a Hi-Z test (control points, or a displaced bound)
    std::size_t displaced_occlusion_culled = 0;  ///< of occlusion_culled: displaced patches
    std::size_t visible = 0;                     ///< passed every test of the mode
    std::size_t newly_visible = 0;               ///< passed, and were not tagged visible before (not drawn in pass 1)
    DrawMode draw = DrawMode::flags;             ///< PipelineParams::draw
    /// Patches issued to the vertex shader and TCS by each draw pass: flags, every patch of the
    /// spans drawn; indirect, the listed ones (read back from the commands after the frame).
    /// One pass: pass1 only; aggressive: pass2_submitted 0.
    std::size_t pass1_submitted = 0, pass2_submitted = 0;
    /// Per-pass times in milliseconds. Two-pass: pass1 (clear, occluders, patches tagged visible),
    /// hiz (build), cull (the whole flag chain), pass2 (newly visible); a draw pass's time includes
    /// its compaction (DrawMode::indirect; CompactMethod::fused_append's appends count in cull,
    /// and in its one-pass frames the occluders' draw too: they are drawn before the chain).
    /// One pass (no occlusion):
    /// cull first, then pass1 draws the patches that passed; hiz = pass2 = 0.
    double pass1_ms = 0, hiz_ms = 0, cull_ms = 0, pass2_ms = 0, total_ms = 0;
    /// Of cull_ms: the back-patch pass alone (0 when the mode has no back-patch test, or when the
    /// fused pass ran it).
    double backpatch_ms = 0;
    bool fused_pass = false;  ///< FusedCullPass ran the tests (PipelineParams::fused_pass, where allowed)
    TimingMethod timing = TimingMethod::off;  ///< the method used (never automatic)
    /// Per object of PipelineParams::objects, in its order (one entry for the whole set when it
    /// is empty). An object not culled this frame counts all its patches visible.
    std::vector<ObjectStats> objects;
};

/// A PatchRenderer and the cull passes of gl_passes.h on its buffers.
class CullPipeline {
public:
    /// Creates the renderer and the passes on ctx (programs compile on first use, which takes
    /// seconds for ncone, ptp and the displaced bounds on llvmpipe).
    explicit CullPipeline(const GlContext& ctx);
    CullPipeline(CullPipeline&&) noexcept;
    CullPipeline& operator=(CullPipeline&&) noexcept;
    CullPipeline(const CullPipeline&) = delete;
    CullPipeline& operator=(const CullPipeline&) = delete;
    ~CullPipeline();

    /// PatchRenderer::set_patches; statuses restart (the next frame is a first frame).
    void set_patches(const std::vector<BezierPatch>& patches, const PatchAttributes& attributes = {});
    /// PatchRenderer::update_patches: a new pose of the same patches, statuses kept.
    void update_patches(const std::vector<BezierPatch>& patches, const PatchAttributes& attributes = {});
    std::size_t patch_count() const;

    /// One frame (see the header). Throws patchcull::Error when the view matrix is singular or a
    /// GL call fails.
    FrameStats render_frame(const PipelineParams& params);

    /// Makes the next frame a first frame (even-indexed patches tagged visible).
    void reset_visibility();
    /// The next frame starts with no patch tagged visible: its pass 1 draws only the occluders, and
    /// pass 2 every patch that passes the tests against their pyramid. For a switch from frames
    /// drawn unculled (which tag every patch visible, so that pass 1 would draw them all) to
    /// culled ones, as `--cull auto` switches (CullAutoPolicy::resumes_culling).
    void forget_visibility();

    /// The pyramid of the last two-pass frame (HiZPyramid::data()'s layout, row 0 = bottom), and
    /// its level count (0 before any). Waits for the GPU.
    std::vector<float> read_hiz() const;
    int hiz_levels() const;

    /// The parts: the renderer for read-backs (read_ids, read_depth, write_color_png,
    /// write_status_png), occluders (set_occluders), the displacement map and the unculled
    /// reference (render with use_cull_flags = false); the passes' context (fma mode, probe).
    PatchRenderer& renderer();
    const PatchRenderer& renderer() const;
    PassContext& passes();

    struct Impl;  ///< the library's internals (src/gl/cull_pipeline_impl.h)

private:
    std::unique_ptr<Impl> impl_;
};

/// The eye position in world space of a view matrix (the inverse's translation). Throws
/// patchcull::Error when view is singular.
Vec3 eye_of_view(const Mat4& view);

}  // namespace patchcull::gl
