// The frame pipeline (CullPipeline::render_frame; §3 of Niessner & Loop, "Patch-Based Occlusion Culling for
// Hardware Tessellation") and the strict id-buffer test:
// for the cull modes none / frustum / occlusion / all, at several fixed cameras and through
// animated moving sequences (the split teapot and BigGuy, deformed every frame, the camera moving
// along orbit_sequence, with a ground quad and a wall as triangle occluders), the FINAL patch-id
// buffer with culling is identical to the unculled render's at the same resolution and
// tessellation. A patch present in the unculled buffer but culled is a false cull and fails.
// Also: the aggressive variant (§3.1) misses only newly visible patches and is exact again after
// one static frame; adaptive tessellation; the flag chain of the passes and the back-patch mode; occluders; statistics,
// timing and the status image.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "gl_test_util.h"
#include "patchcull/core/camera.h"
#include "patchcull/core/displacement.h"
#include "patchcull/gl/gl_verification.h"
#include "patchcull/import/animation.h"
#include "patchcull/import/model_loader.h"

using namespace patchcull;
using namespace patchcull::gl;

namespace {

constexpr int kSize = 256;

// The teapot is an open surface drawn two-sided, on which back-patch culling is not conservative
// (README, "What contributes a pixel"): its modes combine frustum and occlusion; the back-patch
// test runs on the closed BigGuy, drawn one-sided.
const CullMode kFrustumOcclusion = static_cast<CullMode>(kCullFrustum | kCullOcclusion);
const CullMode kModes[] = {CullMode::none, CullMode::frustum, CullMode::occlusion, kFrustumOcclusion};

// A pipeline frame with the default tests' choices (tcone, caf/acon, one object).
PipelineParams pipeline_params(const FrameParams& frame) {
    PipelineParams p;
    p.frame = frame;
    return p;
}

std::string mode_name(CullMode mode) {
    return mode == kFrustumOcclusion ? std::string("frustum+occlusion") : std::string(cull_mode_name(mode));
}

// Ground quad under the model and a wall in front of part of it (both two-sided: no face culling).
// `up` is the model's vertical axis (0 = x, 1 = y, 2 = z); the wall stands on the -side of axis
// `front` (the other horizontal axis, also 0/1/2).
struct Occluders {
    std::vector<Vec3> vertices;
    std::vector<std::uint32_t> indices;
};

float& axis(Vec3& v, int a) { return a == 0 ? v.x : a == 1 ? v.y : v.z; }

Occluders ground_and_wall(const Bounds& b, int up, int front) {
    const int side = 3 - up - front;
    const float r = b.radius();
    Occluders o;
    auto quad = [&](Vec3 p0, Vec3 p1, Vec3 p2, Vec3 p3) {
        const auto base = static_cast<std::uint32_t>(o.vertices.size());
        for (Vec3 p : {p0, p1, p2, p3}) o.vertices.push_back(p);
        for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) o.indices.push_back(base + i);
    };
    auto point = [&](float s, float f, float u) {
        Vec3 p{};
        axis(p, side) = s;
        axis(p, front) = f;
        axis(p, up) = u;
        return p;
    };
    Vec3 c = b.center();
    Vec3 lo = b.min, hi = b.max;
    const float ground = axis(lo, up) - 0.002f * r;
    const float cs = axis(c, side), cf = axis(c, front);
    quad(point(cs - 3 * r, cf - 3 * r, ground), point(cs + 3 * r, cf - 3 * r, ground),
         point(cs + 3 * r, cf + 3 * r, ground), point(cs - 3 * r, cf + 3 * r, ground));
    // Wall: covers the -side half of the model seen from -front, up to 60% of its height.
    const float wall_f = axis(lo, front) - 0.25f * r;
    const float top = axis(lo, up) + 0.6f * (axis(hi, up) - axis(lo, up));
    quad(point(cs - 1.5f * r, wall_f, ground), point(cs + 0.1f * r, wall_f, ground), point(cs + 0.1f * r, wall_f, top),
         point(cs - 1.5f * r, wall_f, top));
    return o;
}

// The teapot after two splits (512 patches) turned y-up (x, y, z) -> (x, z, -y), so that
// orbit_sequence (which orbits about y, above the model) sees it standing on the ground.
std::vector<BezierPatch> teapot_y_up() {
    std::vector<BezierPatch> patches = test::split_teapot(2);
    for (BezierPatch& p : patches)
        for (Vec4& c : p.cp) c = {c.x, c.z, -c.y, c.w};
    return patches;
}

Camera camera_at(const Bounds& b, Vec3 direction, float distance, Vec3 up = {0, 1, 0}) {
    Camera cam;
    cam.target = b.center();
    cam.eye = b.center() + normalize(direction) * (distance * b.radius());
    cam.up = up;
    cam.z_near = 0.02f * b.radius();
    cam.z_far = 12.0f * b.radius();
    return cam;
}

RenderParams params_for(const Camera& cam, int level = 6) {
    RenderParams p;
    p.view = cam.view();
    p.projection = cam.projection();
    p.width = p.height = kSize;
    p.tess_level = level;
    return p;
}

std::vector<std::uint32_t> reference_ids(PatchRenderer& r, RenderParams params) {
    params.use_cull_flags = false;
    r.render(params);
    return r.read_ids();
}

// The comparison of a culled frame with the unculled render. Culling is all or nothing per patch, so
// when every patch of the unculled image is drawn, each pixel's nearest fragment is drawn too: the
// depth buffers are equal and an id can differ only where two patches put fragments at exactly the
// same depth (an exact tie along an intersection, e.g. the teapot's spout entering the body, where
// GL_LESS keeps whichever was drawn first: the unculled render draws in index order, the pipeline
// the first-pass patches before the second-pass ones). Such pixels are counted as ties, and each
// is verified by drawing the two patches alone: both must produce exactly that depth there. Any
// other difference, and any patch of the unculled image missing from the culled one (a false cull),
// fails.
struct Diff {
    std::size_t pixels = 0;  // differing pixels that are not verified ties
    std::size_t ties = 0;    // verified exact depth ties
    std::size_t false_culls = 0;
};

struct Frame {
    std::vector<std::uint32_t> ids;
    std::vector<float> depth;
};

Frame read_frame(const PatchRenderer& r) { return {r.read_ids(), r.read_depth()}; }

// Depth of patch p alone at pixel i (with the occluders), from a second renderer holding the same
// patches, so that the pipeline's statuses in the first are untouched.
float depth_of_patch_alone(const std::vector<BezierPatch>& patches, const Occluders* occ, const RenderParams& params,
                           std::uint32_t p, std::size_t i) {
    static PatchRenderer* verifier = new PatchRenderer(test::context());
    verifier->set_patches(patches);
    if (occ)
        verifier->set_occluders(occ->vertices, occ->indices);
    else
        verifier->set_occluders({}, {});
    std::vector<std::uint8_t> culled(patches.size(), 1);
    culled[p] = 0;
    verifier->set_cull_flags(culled.data());
    verifier->render(params);
    return verifier->read_depth()[i];
}

Diff compare_frames(const Frame& ref, const Frame& got, const std::vector<std::uint32_t>& words,
                    const std::vector<BezierPatch>* patches, const Occluders* occ, const RenderParams& params,
                    const std::string& what) {
    Diff d;
    const std::set<std::uint32_t> ref_ids = test::ids_present(ref.ids), got_ids = test::ids_present(got.ids);
    for (std::uint32_t id : ref_ids)
        if (!got_ids.count(id) && (id & kIdOccluderBit) == 0) {
            if (++d.false_culls <= 3)
                ADD_FAILURE() << what << ": false cull of patch " << id - 1 << " (flag word 0x" << std::hex
                              << words[id - 1] << std::dec << ")";
        }
    for (std::size_t i = 0; i < ref.ids.size(); ++i) {
        if (ref.ids[i] == got.ids[i]) {
            EXPECT_EQ(ref.depth[i], got.depth[i]) << what << " pixel " << i;
            continue;
        }
        const std::uint32_t a = ref.ids[i], b = got.ids[i];
        bool tie = patches && d.ties < 20 && ref.depth[i] == got.depth[i] && a != 0 && b != 0 &&
                   (a & kIdOccluderBit) == 0 && (b & kIdOccluderBit) == 0;
        if (tie) {
            const float da = depth_of_patch_alone(*patches, occ, params, a - 1, i);
            const float db = depth_of_patch_alone(*patches, occ, params, b - 1, i);
            tie = da == ref.depth[i] && db == ref.depth[i];
        }
        if (tie) {
            ++d.ties;
        } else if (++d.pixels <= 3) {
            ADD_FAILURE() << what << ": pixel (" << i % kSize << ", row " << i / kSize << ") id " << b << " depth "
                          << got.depth[i] << ", unculled " << a << " depth " << ref.depth[i];
        }
    }
    return d;
}

// Every patch visible in the final image is tagged visible (else the status is a false cull).
void expect_visible_patches_tagged(const std::vector<std::uint32_t>& ids, const std::vector<std::uint32_t>& words,
                                   const std::string& what) {
    std::size_t bad = 0;
    for (std::uint32_t id : test::ids_present(ids)) {
        if (id & kIdOccluderBit) continue;
        const std::uint32_t w = words[id - 1];
        if (((w & kCullReasonMask) != 0 || (w & kStatusVisible) == 0) && ++bad <= 3)
            ADD_FAILURE() << what << ": patch " << id - 1 << " shows but its word is 0x" << std::hex << w;
    }
}

void check_stats(const FrameStats& s, std::size_t patches, CullMode mode, bool first_frame, const std::string& what) {
    EXPECT_EQ(s.patches, patches) << what;
    EXPECT_EQ(s.frustum_culled + s.backpatch_culled + s.occlusion_culled + s.visible, patches) << what;
    const auto m = static_cast<std::uint32_t>(mode);
    if (!(m & kCullBackPatch)) {
        EXPECT_EQ(s.backpatch_culled, 0u) << what;
    }
    if (!(m & kCullFrustum)) {
        EXPECT_EQ(s.frustum_culled, 0u) << what;
    }
    if (!(m & kCullOcclusion)) {
        EXPECT_EQ(s.occlusion_culled, 0u) << what;
    }
    EXPECT_EQ(s.two_pass, (m & kCullOcclusion) != 0) << what;
    if (s.two_pass) {
        EXPECT_EQ(s.pass2_drawn, s.newly_visible) << what;
        if (first_frame) {
            EXPECT_EQ(s.pass1_drawn, (patches + 1) / 2) << what;
        }
    } else {
        EXPECT_EQ(s.pass1_drawn, s.visible) << what;
        EXPECT_EQ(s.pass2_drawn, 0u) << what;
    }
    EXPECT_EQ(s.timing, test::context().is_software() ? TimingMethod::wall_clock : TimingMethod::timer_query) << what;
    EXPECT_GE(s.pass1_ms, 0.0);
    EXPECT_GE(s.cull_ms, 0.0);
    EXPECT_GE(s.total_ms, s.pass1_ms);
}

struct Totals {
    std::size_t frames = 0, frustum = 0, occluded = 0, pass1 = 0, pass2 = 0, ties = 0;
};

// Runs one frame of mode and compares it with the unculled render (patches: the set uploaded).
Totals strict_frame(CullPipeline& pipeline, const std::vector<BezierPatch>& patches, const Occluders* occ,
                    const RenderParams& params, CullMode mode, bool first_frame, const std::string& what) {
    PatchRenderer& r = pipeline.renderer();
    RenderParams unculled = params;
    unculled.use_cull_flags = false;
    r.render(unculled);
    const Frame ref = read_frame(r);
    const std::vector<std::uint8_t> front = r.mark_front_patches(unculled);
    FrameParams fp;
    fp.render = params;
    fp.cull = mode;
    const FrameStats s = pipeline.render_frame(pipeline_params(fp));
    const Frame got = read_frame(r);
    const std::vector<std::uint32_t> words = r.read_cull_flags();
    const Diff d = compare_frames(ref, got, words, &patches, occ, params, what);
    // The library's comparison: per patch, the front set against the drawn set.
    const FrameComparison cmp =
        gl::compare_frames({ref.ids, ref.depth, front}, {got.ids, got.depth, r.read_drawn_patches()});
    EXPECT_TRUE(cmp.conservative()) << what;
    EXPECT_EQ(cmp.depth_ties, d.ties) << what;
    EXPECT_EQ(d.pixels, 0u) << what;
    EXPECT_EQ(d.false_culls, 0u) << what;
    EXPECT_LE(d.ties, 20u) << what;
    expect_visible_patches_tagged(got.ids, words, what);
    check_stats(s, r.patch_count(), mode, first_frame, what);
    return {1, s.frustum_culled, s.occlusion_culled, s.pass1_drawn, s.pass2_drawn, d.ties};
}

// The model animated: every Cartesian control point moved by animate() (a pure function of the
// position, so shared control points stay shared and the surface watertight).
std::vector<BezierPatch> deform(const std::vector<BezierPatch>& rest, float t) {
    std::vector<Vec3> points;
    points.reserve(rest.size() * 16);
    for (const BezierPatch& p : rest)
        for (const Vec4& c : p.cp) points.push_back(cartesian(c));
    std::vector<Vec3> moved;
    animate(points, t, AnimationParams{}, moved);
    std::vector<BezierPatch> out = rest;
    std::size_t k = 0;
    for (BezierPatch& p : out)
        for (Vec4& c : p.cp) c = homogeneous(moved[k++], c.w);
    return out;
}

// A moving camera: orbit_sequence, every third frame pulled in so that parts leave the view.
std::vector<Camera> moving_cameras(const Bounds& b, int frames, float degrees) {
    std::vector<Camera> cams = orbit_sequence(b, frames, degrees);
    for (std::size_t f = 0; f < cams.size(); ++f)
        if (f % 3 == 2) {
            Camera& c = cams[f];
            c.eye = c.target + (c.eye - c.target) * 0.45f;
            c.z_near = 0.01f * b.radius();
        }
    return cams;
}

// The teapot on the ground behind a wall (ground_and_wall), in a pipeline of its own with both set.
struct TeapotBehindAWall {
    std::vector<BezierPatch> patches = teapot_y_up();
    Bounds bounds = test::control_point_bounds(patches);
    Occluders occluders = ground_and_wall(bounds, 1, 2);
    CullPipeline pipeline{test::context()};
    TeapotBehindAWall() {
        pipeline.renderer().set_patches(patches);
        pipeline.renderer().set_occluders(occluders.vertices, occluders.indices);
    }
};

}  // namespace

TEST(OcclusionPipeline, StrictIdBufferIdenticalAtFixedCameras) {
    TeapotBehindAWall scene;
    const std::vector<BezierPatch>& patches = scene.patches;
    const Bounds& b = scene.bounds;
    const Occluders& occ = scene.occluders;
    CullPipeline& pipeline = scene.pipeline;
    const Camera cams[] = {
        camera_at(b, {0.3f, 0.35f, -1}, 2.4f),            // front, through the wall
        camera_at(b, {1, 0.25f, 0.3f}, 2.0f),             // side
        camera_at(b, {0.05f, 1, 0.1f}, 2.2f, {0, 0, 1}),  // top down
        camera_at(b, {0.6f, 0.2f, -0.8f}, 0.8f),          // close: parts outside the frustum
        camera_at(b, {0.2f, -1, -0.4f}, 2.0f),            // under the ground: everything hidden
        camera_at(b, {-0.3f, 0.05f, -1}, 3.0f),           // low behind the wall
    };
    Totals total;
    for (CullMode mode : kModes) {
        for (std::size_t c = 0; c < std::size(cams); ++c) {
            pipeline.reset_visibility();
            // Two frames from the same camera: the first starts from the even half tagged visible.
            for (int frame = 0; frame < 2; ++frame) {
                const std::string what =
                    mode_name(mode) + " camera " + std::to_string(c) + " frame " + std::to_string(frame);
                const Totals t = strict_frame(pipeline, patches, &occ, params_for(cams[c]), mode, frame == 0, what);
                total.frustum += t.frustum;
                total.occluded += t.occluded;
                total.pass2 += t.pass2;
                total.ties += t.ties;
            }
        }
    }
    // The cameras make both tests cull, and the second pass draw.
    EXPECT_GT(total.frustum, 200u);
    EXPECT_GT(total.occluded, 1000u);
    EXPECT_GT(total.pass2, 100u);
    std::printf(
        "[ info     ] fixed cameras: %zu frustum-, %zu occlusion-culled, %zu second-pass draws, "
        "%zu exact depth-tie pixels\n",
        total.frustum, total.occluded, total.pass2, total.ties);
}

TEST(OcclusionPipeline, ForgetVisibilityStartsPassOneEmptyAndStaysStrict) {
    // After an unculled frame every patch is tagged visible, and pass 1 of the next culled frame
    // would draw them all; forget_visibility starts that frame from none (occluders only in pass 1,
    // every patch that passes in pass 2), and it still matches the unculled render.
    TeapotBehindAWall scene;
    const std::vector<BezierPatch>& patches = scene.patches;
    const Bounds& b = scene.bounds;
    const Occluders& occ = scene.occluders;
    CullPipeline& pipeline = scene.pipeline;
    const Camera cams[] = {camera_at(b, {0.3f, 0.35f, -1}, 2.4f), camera_at(b, {0.6f, 0.2f, -0.8f}, 0.8f)};
    for (std::size_t c = 0; c < std::size(cams); ++c) {
        const RenderParams params = params_for(cams[c]);
        FrameParams unculled;
        unculled.render = params;
        unculled.cull = CullMode::none;
        const FrameStats none = pipeline.render_frame(pipeline_params(unculled));
        EXPECT_EQ(none.visible, patches.size());
        pipeline.forget_visibility();
        const std::string what = "camera " + std::to_string(c) + ", the frame after forget_visibility";
        const Totals t = strict_frame(pipeline, patches, &occ, params, kFrustumOcclusion, false, what);
        EXPECT_EQ(t.pass1, 0u) << what;
        EXPECT_GT(t.pass2, 0u) << what;
        // The frame after it is an ordinary one: pass 1 draws what was visible.
        const Totals next = strict_frame(pipeline, patches, &occ, params, kFrustumOcclusion, false, what + " + 1");
        EXPECT_EQ(next.pass1, t.pass2) << what;
    }
}

TEST(OcclusionPipeline, StrictIdBufferIdenticalThroughAnimatedTeapotSequence) {
    const std::vector<BezierPatch> rest = teapot_y_up();
    const Bounds b = test::control_point_bounds(rest);
    const Occluders occ = ground_and_wall(b, 1, 2);
    const std::vector<Camera> cams = moving_cameras(b, 9, 20.0f);
    for (CullMode mode : kModes) {
        for (bool adaptive : {false, true}) {
            if (adaptive && mode != kFrustumOcclusion) continue;
            CullPipeline pipeline(test::context());
            PatchRenderer& r = pipeline.renderer();
            r.set_patches(rest);
            r.set_occluders(occ.vertices, occ.indices);
            Totals total;
            for (std::size_t f = 0; f < cams.size(); ++f) {
                const std::vector<BezierPatch> posed = deform(rest, 0.15f * static_cast<float>(f));
                r.update_patches(posed);
                RenderParams params = params_for(cams[f]);
                if (adaptive) {
                    params.tess_level = 8;
                    params.adaptive_tess = true;
                    params.tess_reference_distance = 1.5f * b.radius();
                }
                const std::string what =
                    mode_name(mode) + (adaptive ? " adaptive" : "") + " frame " + std::to_string(f);
                const Totals t = strict_frame(pipeline, posed, &occ, params, mode, f == 0, what);
                total.frustum += t.frustum;
                total.occluded += t.occluded;
                total.pass2 += t.pass2;
                total.ties += t.ties;
            }
            std::printf(
                "[ info     ] teapot %s%s: %zu frustum-, %zu occlusion-culled, %zu second-pass draws, "
                "%zu tie pixels\n",
                mode_name(mode).c_str(), adaptive ? " adaptive" : "", total.frustum, total.occluded, total.pass2,
                total.ties);
            if (mode == kFrustumOcclusion) {
                EXPECT_GT(total.frustum, 50u);
                EXPECT_GT(total.occluded, 300u);
                EXPECT_GT(total.pass2, 50u);  // patches becoming visible as the camera moves
            }
        }
    }
}

TEST(OcclusionPipeline, StrictIdBufferIdenticalThroughAnimatedBigGuy) {
    // BigGuy through the import layer (model_loader.h, allowed in tests only): ~1.3k ACC patches, the
    // control mesh deformed every frame, the camera orbiting.
    const LoadedModel model = load_model(shipped_model_path("bigguy.obj"), Scheme::acc, 0);
    ASSERT_TRUE(model.subdiv.has_value());
    const std::vector<Vec3>& rest_positions = model.subdiv->mesh.positions;
    const Bounds b = patch_bounds(model.rest);
    const Occluders occ = ground_and_wall(b, 1, 2);
    const std::vector<Camera> cams = moving_cameras(b, 6, 25.0f);
    PatchFrame frame;
    std::vector<Vec3> positions;
    ASSERT_TRUE(model.closed);
    for (CullMode mode : {CullMode::frustum, CullMode::occlusion, CullMode::all}) {
        CullPipeline pipeline(test::context());
        PatchRenderer& r = pipeline.renderer();
        r.set_patches(model.rest.patches);
        r.set_occluders(occ.vertices, occ.indices);
        Totals total;
        for (std::size_t f = 0; f < cams.size(); ++f) {
            animate(rest_positions, 0.2f * static_cast<float>(f), AnimationParams{}, positions);
            evaluate_frame(model, positions, frame);
            r.update_patches(frame.patches);
            const std::string what = std::string("bigguy ") + cull_mode_name(mode) + " frame " + std::to_string(f);
            RenderParams params = params_for(cams[f], 4);
            params.discard_back_facing = model.closed;  // one-sided: the back-patch test's visibility
            const Totals t = strict_frame(pipeline, frame.patches, &occ, params, mode, f == 0, what);
            total.frustum += t.frustum;
            total.occluded += t.occluded;
            total.pass2 += t.pass2;
            total.ties += t.ties;
        }
        std::printf(
            "[ info     ] bigguy %s (%zu patches): %zu frustum-, %zu occlusion-culled, %zu second-pass "
            "draws, %zu tie pixels\n",
            cull_mode_name(mode), r.patch_count(), total.frustum, total.occluded, total.pass2, total.ties);
        if (mode == CullMode::all) {
            EXPECT_GT(total.occluded, 500u);
        }
    }
}

TEST(OcclusionPipeline, AggressiveMissesOnlyNewlyVisibleAndRecoversAfterOneFrame) {
    const std::vector<BezierPatch> rest = teapot_y_up();
    const Bounds b = test::control_point_bounds(rest);
    const Occluders occ = ground_and_wall(b, 1, 2);
    CullPipeline pipeline(test::context());
    PatchRenderer& r = pipeline.renderer();
    r.set_patches(rest);
    r.set_occluders(occ.vertices, occ.indices);
    const std::vector<Camera> cams = moving_cameras(b, 6, 30.0f);
    std::size_t missed_pixels = 0;
    for (std::size_t f = 0; f < cams.size(); ++f) {
        const RenderParams params = params_for(cams[f]);
        RenderParams unculled = params;
        unculled.use_cull_flags = false;
        r.render(unculled);
        const Frame ref_frame = read_frame(r);
        const std::vector<std::uint32_t>& ref = ref_frame.ids;
        FrameParams fp;
        fp.render = params;
        fp.cull = kFrustumOcclusion;
        fp.aggressive = true;
        const FrameStats s = pipeline.render_frame(pipeline_params(fp));
        EXPECT_EQ(s.pass2_drawn, 0u);
        const std::vector<std::uint32_t> got = r.read_ids();
        const std::vector<float> got_depth = r.read_depth();
        const std::vector<std::uint32_t> words = r.read_cull_flags();
        // Every difference is a patch that became visible this frame (drawn from the next one).
        for (std::size_t i = 0; i < ref.size(); ++i) {
            if (ref[i] == got[i]) continue;
            if (got[i] != 0 && ref_frame.depth[i] == got_depth[i]) continue;  // an exact tie
            ++missed_pixels;
            ASSERT_NE(ref[i], 0u) << "frame " << f << " pixel " << i;
            ASSERT_EQ(ref[i] & kIdOccluderBit, 0u);  // occluders are drawn in every pass 1
            EXPECT_NE(words[ref[i] - 1] & kStatusNewlyVisible, 0u) << "frame " << f << " pixel " << i;
        }
        // The same camera again: exact.
        const FrameStats again = pipeline.render_frame(pipeline_params(fp));
        const Diff d = compare_frames(ref_frame, read_frame(r), r.read_cull_flags(), &rest, &occ, params,
                                      "aggressive repeat frame " + std::to_string(f));
        EXPECT_EQ(d.pixels, 0u);
        EXPECT_EQ(d.false_culls, 0u);
        EXPECT_EQ(again.pass2_drawn, 0u);
    }
    EXPECT_GT(missed_pixels, 0u);  // the first frame (half the patches) misses some
}

TEST(OcclusionPipeline, AdaptiveTessellationFollowsDistance) {
    const std::vector<BezierPatch> patches = teapot_y_up();
    const Bounds b = test::control_point_bounds(patches);
    CullPipeline pipeline(test::context());
    PatchRenderer& r = pipeline.renderer();
    r.set_patches(patches);
    RenderParams p = params_for(camera_at(b, {0.3f, 0.3f, -1}, 2.0f), 16);
    r.render(p);
    const std::vector<float> uniform16 = r.read_depth();
    // A reference distance far beyond the model: every edge gets the maximum level, as uniform.
    p.adaptive_tess = true;
    p.tess_reference_distance = 100.0f * b.radius();
    r.render(p);
    EXPECT_EQ(r.read_depth(), uniform16);
    // A small one: level 1 almost everywhere, the silhouette and depth change.
    p.tess_reference_distance = 0.01f * b.radius();
    r.render(p);
    const std::vector<float> coarse = r.read_depth();
    std::size_t differ = 0;
    for (std::size_t i = 0; i < coarse.size(); ++i) differ += coarse[i] != uniform16[i];
    EXPECT_GT(differ, coarse.size() / 50);
}

TEST(OcclusionPipeline, FlagChainKeepsTheFirstReasonAndSkipsCulledPatches) {
    // gl_passes.h's chain on the renderer's buffers: a patch culled by an earlier pass keeps its
    // reason, the frustum pass then decides the rest as cull_frustum_scalar does, the tcone pass
    // the survivors as cull_tcone_scalar does (displaced patches skipped), and the status pass
    // turns reasons into statuses, keeping them across begin.
    const std::vector<BezierPatch> patches = teapot_y_up();
    const Bounds b = test::control_point_bounds(patches);
    const Camera cam = camera_at(b, {0.6f, 0.2f, -0.8f}, 0.8f);  // close: parts outside the frustum
    const Mat4 m = cam.view_projection();
    const Vec3 eye = cam.eye;
    const PatchBatch batch = make_batch(patches);
    std::vector<std::uint8_t> outside(patches.size()), back(patches.size());
    cull_tcone_scalar(batch.view(), eye, back.data());
    // One back-facing patch is marked displaced (margin > 0): the tcone pass must skip it.
    std::size_t displaced = 2;
    while (displaced < patches.size() && !back[displaced]) ++displaced;
    ASSERT_LT(displaced, patches.size());
    std::vector<float> margins(patches.size(), 0.0f);
    margins[displaced] = 1e-4f;
    PatchRenderer r(test::context());
    r.set_patches(patches, test::margins_only(margins));
    CullStatusPass status(test::passes());
    FrustumPass frustum(test::passes());
    BackpatchConePass cones(test::passes());
    std::vector<std::uint32_t> words(patches.size(), kStatusVisible);
    words[0] = kStatusVisible | kCullOcclusion;  // stale from the last frame: begin clears it
    r.set_flag_words(words);
    status.begin(r.patch_buffers());
    std::vector<std::uint32_t> after_begin = r.read_cull_flags();
    for (std::uint32_t w : after_begin) ASSERT_EQ(w, kStatusVisible);
    words.assign(patches.size(), kStatusVisible);
    words[1] = kStatusVisible | kCullOcclusion;  // culled by an "earlier pass" of this frame
    r.set_flag_words(words);
    const FrustumPlanes planes = make_frustum_planes(m, ClipDepth::zero_to_one);
    frustum.run(r.patch_buffers(), planes);
    cones.run(r.patch_buffers(), BackpatchMethod::tcone, eye);
    const std::vector<std::uint32_t> got = r.read_cull_flags();
    cull_frustum_scalar(batch.view(), margins.data(), planes, outside.data());
    std::size_t frustum_culled = 0, back_culled = 0;
    for (std::size_t p = 0; p < patches.size(); ++p) {
        std::uint32_t reason = 0;
        if (p == 1)
            reason = kCullOcclusion;
        else if (outside[p])
            reason = kCullFrustum;
        else if (back[p] && margins[p] == 0.0f)
            reason = kCullBackPatch;
        ASSERT_EQ(got[p] & kCullReasonMask, reason) << "patch " << p;
        ASSERT_EQ(got[p] & ~kCullReasonMask, kStatusVisible) << "patch " << p << ": statuses untouched";
        frustum_culled += reason == kCullFrustum;
        back_culled += reason == kCullBackPatch;
    }
    EXPECT_GT(frustum_culled, 5u);
    EXPECT_GT(back_culled, 5u);
    if (!outside[displaced]) {
        EXPECT_EQ(got[displaced] & kCullReasonMask, 0u)
            << "the displaced patch " << displaced << " was back-patch tested";
    }
    status.end(r.patch_buffers(), 0);
    const std::vector<std::uint32_t> ended = r.read_cull_flags();
    for (std::size_t p = 0; p < patches.size(); ++p) {
        const std::uint32_t reason = got[p] & kCullReasonMask;
        ASSERT_EQ(ended[p], reason ? reason : kStatusVisible) << "patch " << p;
    }
}

TEST(OcclusionPipeline, BackPatchModeCullsWhatTheGpuPassDecides) {
    // CullMode::backpatch alone: the frame's back-patch pass culls exactly cull_tcone_scalar's set
    // (nothing else runs before it), and the counters say so.
    const std::vector<BezierPatch> patches = teapot_y_up();
    const Bounds b = test::control_point_bounds(patches);
    CullPipeline pipeline(test::context());
    pipeline.set_patches(patches);
    const Camera cam = camera_at(b, {0.3f, 0.35f, -1}, 2.2f);
    PipelineParams pp;
    pp.frame.render = params_for(cam);
    pp.frame.cull = CullMode::backpatch;
    const FrameStats s = pipeline.render_frame(pp);
    std::vector<std::uint8_t> back(patches.size());
    cull_tcone_scalar(make_batch(patches).view(), eye_of_view(pp.frame.render.view), back.data());
    std::size_t expected = 0;
    const std::vector<std::uint32_t> words = pipeline.renderer().read_cull_flags();
    for (std::size_t p = 0; p < patches.size(); ++p) {
        expected += back[p];
        ASSERT_EQ((words[p] & kCullBackPatch) != 0, back[p] != 0) << "patch " << p;
    }
    EXPECT_GT(expected, 10u);
    EXPECT_EQ(s.backpatch_culled, expected);
    EXPECT_EQ(s.visible, patches.size() - expected);
}

TEST(OcclusionPipeline, OccludersWriteTaggedIdsAndHidePatches) {
    const std::vector<BezierPatch> patches = teapot_y_up();
    const Bounds b = test::control_point_bounds(patches);
    const Occluders occ = ground_and_wall(b, 1, 2);
    CullPipeline pipeline(test::context());
    PatchRenderer& r = pipeline.renderer();
    r.set_patches(patches);
    const RenderParams params = params_for(camera_at(b, {0.3f, 0.35f, -1}, 2.4f));
    const std::set<std::uint32_t> without = test::ids_present(reference_ids(r, params));
    r.set_occluders(occ.vertices, occ.indices);
    EXPECT_EQ(r.occluder_triangle_count(), 4u);
    const std::set<std::uint32_t> with = test::ids_present(reference_ids(r, params));
    std::size_t occluder_ids = 0, patch_ids = 0;
    for (std::uint32_t id : with) {
        if (id & kIdOccluderBit) {
            EXPECT_LT(id & ~kIdOccluderBit, 4u);
            ++occluder_ids;
        } else {
            ++patch_ids;
        }
    }
    EXPECT_GE(occluder_ids, 3u);           // ground (2 triangles) and wall
    EXPECT_LT(patch_ids, without.size());  // the wall hides patches
    EXPECT_THROW(r.set_occluders(occ.vertices, {0, 1}), patchcull::Error);
    EXPECT_THROW(r.set_occluders(occ.vertices, {0, 1, 99}), patchcull::Error);
    r.set_occluders({}, {});
    EXPECT_EQ(r.occluder_triangle_count(), 0u);
    EXPECT_EQ(test::ids_present(reference_ids(r, params)), without);
}

TEST(OcclusionPipeline, TimingMethodsAndStatusImage) {
    TeapotBehindAWall scene;
    const Bounds& b = scene.bounds;
    CullPipeline& pipeline = scene.pipeline;
    PatchRenderer& r = pipeline.renderer();
    FrameParams fp;
    fp.render = params_for(camera_at(b, {0.3f, 0.35f, -1}, 2.4f));
    fp.cull = kFrustumOcclusion;
    FrameStats s = pipeline.render_frame(pipeline_params(fp));
    EXPECT_EQ(s.timing, test::context().is_software() ? TimingMethod::wall_clock : TimingMethod::timer_query);
    EXPECT_GT(s.pass1_ms, 0.0);
    EXPECT_GT(s.total_ms, 0.0);
    EXPECT_NEAR(s.total_ms, s.pass1_ms + s.hiz_ms + s.cull_ms + s.pass2_ms, 1e-6);
    for (TimingMethod m : {TimingMethod::wall_clock, TimingMethod::timer_query, TimingMethod::off}) {
        fp.timing = m;
        s = pipeline.render_frame(pipeline_params(fp));
        EXPECT_EQ(s.timing, m);
        if (m == TimingMethod::off)
            EXPECT_EQ(s.total_ms, 0.0);
        else
            EXPECT_GE(s.total_ms, 0.0);
    }
    // Own camera: no occlusion-culled (red) or frustum-culled (blue) patch shows.
    auto count_colour = [](const std::vector<std::uint8_t>& rgba, auto pred) {
        std::size_t n = 0;
        for (std::size_t i = 0; i < rgba.size(); i += 4) n += pred(rgba[i], rgba[i + 1], rgba[i + 2]);
        return n;
    };
    auto red = [](int R, int G, int B) { return R > 40 && R > 3 * G && R > 3 * B; };
    auto blue = [](int R, int G, int B) { return B > 40 && B > 2 * R && B > G + 20; };
    auto green = [](int R, int G, int B) { return G > 40 && G > 2 * R && G > 2 * B; };
    const std::vector<std::uint8_t> own = r.render_status_image(fp.render);
    EXPECT_EQ(count_colour(own, red), 0u);
    EXPECT_EQ(count_colour(own, blue), 0u);
    EXPECT_GT(count_colour(own, green), 1000u);
    // The id buffer of the frame is untouched by the visualisation.
    const std::vector<std::uint32_t> ids = r.read_ids();
    r.render_status_image(fp.render);
    EXPECT_EQ(r.read_ids(), ids);
    // From behind and above, the culled patches show.
    RenderParams observer = params_for(camera_at(b, {-0.4f, 0.8f, 1}, 2.6f));
    observer.width = 320;
    const std::vector<std::uint8_t> behind = r.render_status_image(observer);
    EXPECT_EQ(behind.size(), 320u * kSize * 4);
    EXPECT_GT(count_colour(behind, red), 200u);
    const std::string path = ::testing::TempDir() + "/patchcull_status.png";
    r.write_status_png(path, observer);
    EXPECT_GT(std::filesystem::file_size(path), 1000u);
}

TEST(OcclusionPipeline, UpdatePatchesKeepsStatusAndChecksCount) {
    const std::vector<BezierPatch> patches = teapot_y_up();
    CullPipeline pipeline(test::context());
    PatchRenderer& r = pipeline.renderer();
    r.set_patches(patches);
    FrameParams fp;
    fp.render = params_for(camera_at(test::control_point_bounds(patches), {0.3f, 0.35f, -1}, 2.4f));
    fp.cull = kFrustumOcclusion;
    pipeline.render_frame(pipeline_params(fp));
    const std::vector<std::uint32_t> words = r.read_cull_flags();
    r.update_patches(patches);
    EXPECT_EQ(r.read_cull_flags(), words);
    FrameStats s = pipeline.render_frame(pipeline_params(fp));
    EXPECT_EQ(s.newly_visible, 0u);       // same pose, same camera: nothing becomes visible
    EXPECT_LE(s.visible, s.pass1_drawn);  // the fuller first pass may occlude more
    EXPECT_THROW(r.update_patches(std::vector<BezierPatch>(patches.begin(), patches.end() - 1)), patchcull::Error);
    r.set_patches(patches);  // a new set: statuses start again from the even half
    s = pipeline.render_frame(pipeline_params(fp));
    EXPECT_EQ(s.pass1_drawn, patches.size() / 2);
    CullMode m = CullMode::none;
    EXPECT_TRUE(parse_cull_mode("occlusion", m));
    EXPECT_EQ(m, CullMode::occlusion);
    EXPECT_FALSE(parse_cull_mode("bogus", m));
    EXPECT_EQ(m, CullMode::occlusion);
    EXPECT_STREQ(cull_mode_name(CullMode::backpatch), "backpatch");
}

TEST(OcclusionPipeline, CompareFramesJudgesFalseCullsPerPatch) {
    // 6 pixels: equal; a tie (ids 2 and 3 at the same depth); id 5 replaced by a farther id 3; an
    // occluder vs a patch; background vs a patch; an equal occluder. 8 patches: the reference's
    // front set is patches 0, 1, 4 (ids 1, 2, 5) and 6, which lost a depth tie in the reference
    // (absent from its id buffer, found by mark_front_patches).
    const FrameCapture reference = {{1, 2, 5, kIdOccluderBit | 1, 0, kIdOccluderBit},
                                    {0.5f, 0.4f, 0.3f, 0.2f, 1.0f, 0.1f},
                                    {1, 1, 0, 0, 1, 0, 1, 0}};
    // Patch 1 (id 2) was drawn and lost the tie at pixel 1: a tie, not a false cull. Patch 4
    // (id 5) was not drawn: a false cull. Patch 6 was not drawn either: a false cull although the
    // reference's id buffer never shows it (a tie must not hide a culled patch). Patch 3 was not
    // drawn and is not at the front: a correct cull.
    const FrameCapture culled = {
        {1, 3, 3, 7, 6, kIdOccluderBit}, {0.5f, 0.4f, 0.35f, 0.2f, 0.9f, 0.1f}, {1, 1, 1, 0, 0, 1, 0, 1}};
    const FrameComparison c = gl::compare_frames(reference, culled);
    EXPECT_EQ(c.differing_pixels, 4u);
    EXPECT_EQ(c.depth_ties, 1u);
    EXPECT_EQ(c.false_culled, (std::vector<std::uint32_t>{4, 6}));
    EXPECT_FALSE(c.conservative());
    EXPECT_FALSE(c.identical());

    // Only the tie differs and every front patch was drawn: conservative, not identical.
    FrameCapture tie_only = reference;
    tie_only.ids[1] = 3;
    tie_only.patches = {1, 1, 1, 1, 1, 1, 1, 1};
    const FrameComparison t = gl::compare_frames(reference, tie_only);
    EXPECT_TRUE(t.false_culled.empty());
    EXPECT_EQ(t.depth_ties, 1u);
    EXPECT_TRUE(t.conservative());
    EXPECT_FALSE(t.identical());

    EXPECT_TRUE(gl::compare_frames(reference, reference).identical());
    FrameCapture short_depth = culled;
    short_depth.depth.clear();
    EXPECT_THROW(gl::compare_frames(reference, short_depth), patchcull::Error);
    FrameCapture fewer_patches = culled;
    fewer_patches.patches.pop_back();
    EXPECT_THROW(gl::compare_frames(reference, fewer_patches), patchcull::Error);
}

TEST(OcclusionPipeline, DisplacedPatchesWithoutRangesAreNotHiZTested) {
    // The control-point Hi-Z test bounds the undisplaced patch only: without ranges (the input of
    // the displaced pass), patches with a nonzero margin are never occlusion-culled, and while a
    // map is drawn without margins nothing is culled at all; drawn without displacement, the
    // margins no longer matter. The frames stay identical to the unculled ones.
    const std::vector<BezierPatch> patches = teapot_y_up();
    const Bounds b = test::control_point_bounds(patches);
    const Occluders occ = ground_and_wall(b, 1, 2);
    const DisplacementMap map = make_procedural_displacement(64, 0.03f * length(b.max - b.min));
    PatchAttributes attributes;
    for (std::size_t p = 0; p < patches.size(); ++p) {
        const float s = 0.25f;
        const Vec2 o{s * static_cast<float>(p % 4), s * static_cast<float>((p / 4) % 4)};
        const std::array<Vec2, 4> uv = {o, o + Vec2{s, 0}, o + Vec2{0, s}, o + Vec2{s, s}};
        attributes.texcoords.push_back(uv);
        attributes.max_displacement.push_back(map.patch_range(uv.data()).max_abs());
    }
    const RenderParams params = params_for(camera_at(b, {0.3f, 0.35f, -1}, 2.0f));
    for (int variant = 0; variant < 3; ++variant) {
        CullPipeline pipeline(test::context());
        PatchRenderer& r = pipeline.renderer();
        if (variant == 1)
            r.set_patches(patches);  // no margins
        else
            r.set_patches(patches, attributes);
        r.set_displacement_map(map);
        r.set_occluders(occ.vertices, occ.indices);
        RenderParams p = params;
        p.displace = variant != 2;  // variant 2: the map is set but not drawn
        const std::string what = "displaced variant " + std::to_string(variant);
        Totals total;
        for (int frame = 0; frame < 2; ++frame) {
            const Totals t = strict_frame(pipeline, patches, &occ, p, kFrustumOcclusion, frame == 0, what);
            total.occluded += t.occluded;
            total.frustum += t.frustum;
        }
        if (variant == 2) {
            EXPECT_GT(total.occluded, 100u) << what;  // drawn undisplaced: the base patches are the surface
        } else {
            EXPECT_EQ(total.occluded, 0u) << what;
        }
        if (variant == 1) {
            EXPECT_EQ(total.frustum, 0u) << what;  // no margins: nothing bounds the displaced surface
        }
    }
    // Margins of zero where the surface is not displaced (no map): the test runs again.
    CullPipeline pipeline(test::context());
    PatchRenderer& r = pipeline.renderer();
    r.set_patches(patches, test::margins_only(std::vector<float>(patches.size(), 0.0f)));
    r.set_occluders(occ.vertices, occ.indices);
    Totals total;
    for (int frame = 0; frame < 2; ++frame)
        total.occluded +=
            strict_frame(pipeline, patches, &occ, params, kFrustumOcclusion, frame == 0, "zero margins").occluded;
    EXPECT_GT(total.occluded, 100u);
}
