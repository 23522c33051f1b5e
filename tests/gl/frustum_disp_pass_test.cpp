// The GPU displaced-AABB frustum pass (FrustumDispPass, shaders/frustum_disp.comp.glsl) against
// the CPU reference kernel cull_frustum_disp_scalar (Sathe's test): decisions and the six plane
// maxima bit for bit over random views and patches (inside, across the planes, behind the eye),
// both depth conventions; the margin (max |D|) is used; and the strict id-buffer test on a
// displaced render: culling never changes the picture.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "gl_test_util.h"
#include "patchcull/core/camera.h"
#include "patchcull/core/clip_space.h"
#include "patchcull/core/displacement.h"
#include "patchcull/core/frustum.h"

using namespace patchcull;
using namespace patchcull::gl;

namespace {

float coord(const Vec4& v, int a) { return a == 0 ? v.x : a == 1 ? v.y : v.z; }

struct RandomCase {
    std::vector<BezierPatch> patches;
    std::vector<float> displacement;  // empty or one per patch
    Mat4 object_to_clip;
    ClipDepth depth = ClipDepth::zero_to_one;
};

// Patches scattered in a 12-unit cube around a random camera looking into it from up to 3 units
// away: some inside, some across the planes, some behind the eye (w <= 0 in clip space); a third
// rational (weights in [0.25, 4]); odd seeds with random margins (30% of them 0), even seeds none;
// every third seed an OpenGL -1..1 projection.
RandomCase random_case(std::uint32_t seed, std::size_t count) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    auto range = [&](float lo, float hi) { return lo + (hi - lo) * u01(rng); };
    Camera cam;
    cam.eye = {range(-3, 3), range(-3, 3), range(-3, 3)};
    cam.target = {range(-1, 1), range(-1, 1), range(-1, 1)};
    cam.up = normalize(Vec3{range(-1, 1), range(-1, 1), range(-1, 1)});
    cam.fovy_radians = range(0.3f, 2.0f);
    cam.aspect = range(0.5f, 2.0f);
    cam.z_near = range(0.01f, 1.0f);
    cam.z_far = cam.z_near + range(0.5f, 20.0f);
    RandomCase c;
    c.object_to_clip = cam.view_projection();
    if (seed % 3 == 0) {
        // The same camera's matrix written for OpenGL's -1..1 depth: z' = 2z - w.
        Mat4 gl = c.object_to_clip;
        for (int col = 0; col < 4; ++col)
            gl.m[col * 4 + 2] = 2.0f * c.object_to_clip.at(2, col) - c.object_to_clip.at(3, col);
        c.object_to_clip = gl;
        c.depth = ClipDepth::minus_one_to_one;
    }
    const bool displaced = seed % 2 == 1;
    for (std::size_t p = 0; p < count; ++p) {
        const Vec3 centre{range(-6, 6), range(-6, 6), range(-6, 6)};
        const float size = std::pow(10.0f, range(-2.0f, 0.5f));
        const bool rational = p % 3 == 0;
        BezierPatch patch;
        for (Vec4& cp : patch.cp) {
            const Vec3 x = centre + Vec3{range(-size, size), range(-size, size), range(-size, size)};
            cp = homogeneous(x, rational ? std::pow(2.0f, range(-2, 2)) : 1.0f);
        }
        c.patches.push_back(patch);
        if (displaced) c.displacement.push_back(u01(rng) < 0.3f ? 0.0f : std::pow(10.0f, range(-3.0f, 0.0f)));
    }
    return c;
}

// cull_frustum_disp_scalar's arithmetic (src/core/frustum.cpp) returning the six maxima over the
// corners that the decision compares with 0: what the GPU pass reports through plane_values. Its
// decisions are checked against the kernel's below, so it cannot drift from it unnoticed.
std::vector<float> cpu_plane_values(const std::vector<BezierPatch>& patches, const float* disp, const Mat4& any,
                                    ClipDepth depth) {
    const Mat4 m = to_zero_to_one(any, depth);
    std::vector<float> out(6 * patches.size());
    for (std::size_t p = 0; p < patches.size(); ++p) {
        const float d = disp ? disp[p] : 0.0f;
        float lo[3], hi[3];
        for (int a = 0; a < 3; ++a) lo[a] = hi[a] = coord(patches[p].cp[0], a) / patches[p].cp[0].w;
        for (int k = 1; k < 16; ++k)
            for (int a = 0; a < 3; ++a) {
                const float v = coord(patches[p].cp[k], a) / patches[p].cp[k].w;
                lo[a] = lo[a] < v ? lo[a] : v;
                hi[a] = hi[a] > v ? hi[a] : v;
            }
        const float box[3][2] = {{lo[0] - d, hi[0] + d}, {lo[1] - d, hi[1] + d}, {lo[2] - d, hi[2] + d}};
        float mx[6] = {};
        for (int corner = 0; corner < 8; ++corner) {
            float clip[4];
            for (int r = 0; r < 4; ++r) {
                const float tz = std::fma(m.at(r, 2), box[2][corner & 1], m.at(r, 3));
                const float tyz = std::fma(m.at(r, 1), box[1][(corner >> 1) & 1], tz);
                clip[r] = std::fma(m.at(r, 0), box[0][corner >> 2], tyz);
            }
            const float v[6] = {clip[3] + clip[0], clip[3] - clip[0], clip[3] + clip[1],
                                clip[3] - clip[1], clip[2],           clip[3] - clip[2]};
            for (int q = 0; q < 6; ++q) mx[q] = corner == 0 ? v[q] : (mx[q] > v[q] ? mx[q] : v[q]);
        }
        std::copy(mx, mx + 6, out.begin() + static_cast<std::ptrdiff_t>(6 * p));
    }
    return out;
}

std::uint32_t bits(float f) {
    std::uint32_t b;
    std::memcpy(&b, &f, 4);
    return b;
}

// The pass on the renderer's whole set as a chain of its own: reasons cleared, then the pass;
// plane_values (optional) receives the six maxima per patch.
void cull_frustum_disp(PatchRenderer& r, const Mat4& object_to_clip, ClipDepth depth,
                       std::vector<float>* plane_values = nullptr) {
    static CullStatusPass status(test::passes());
    static FrustumDispPass pass(test::passes());
    const PatchBuffers buffers = r.patch_buffers();
    status.begin(buffers);
    if (!plane_values) {
        pass.run(buffers, object_to_clip, depth);
        return;
    }
    test::ScratchBuffer values(6 * buffers.count * sizeof(float));
    pass.run(buffers, object_to_clip, depth, values.name());
    *plane_values = values.read_floats(6 * buffers.count);
}

}  // namespace

TEST(GpuFrustumDispCull, SameDecisionsAndValuesAsCpuKernelOnRandomInputs) {
    PatchRenderer r(test::context());
    std::size_t culled_total = 0, total = 0, value_mismatches = 0, behind_eye = 0;
    for (std::uint32_t seed = 1; seed <= 12; ++seed) {
        const RandomCase c = random_case(seed, 2000);
        PatchAttributes attributes;
        attributes.max_displacement = c.displacement;
        r.set_patches(c.patches, attributes);
        std::vector<float> gpu_values;
        cull_frustum_disp(r, c.object_to_clip, c.depth, &gpu_values);
        const std::vector<std::uint32_t> gpu = r.read_cull_flags();

        const float* disp = c.displacement.empty() ? nullptr : c.displacement.data();
        const PatchBatch batch = make_batch(c.patches);
        std::vector<std::uint8_t> cpu(c.patches.size());
        cull_frustum_disp_scalar(batch.view(), disp, c.object_to_clip, c.depth, cpu.data());
        const std::vector<float> cpu_values = cpu_plane_values(c.patches, disp, c.object_to_clip, c.depth);
        ASSERT_EQ(gpu.size(), cpu.size());
        ASSERT_EQ(gpu_values.size(), cpu_values.size());
        const Mat4 m = to_zero_to_one(c.object_to_clip, c.depth);
        for (std::size_t p = 0; p < cpu.size(); ++p) {
            ASSERT_EQ(gpu[p] != 0, cpu[p] != 0) << "seed " << seed << " patch " << p;
            if (gpu[p]) {
                ASSERT_EQ(gpu[p], 1u);  // kCullFrustum
            }
            bool values_cull = false;  // the test's copy of the arithmetic decides as the kernel
            for (int q = 0; q < 6; ++q) values_cull = values_cull || cpu_values[6 * p + q] < 0.0f;
            ASSERT_EQ(values_cull, cpu[p] != 0) << "seed " << seed << " patch " << p;
            for (int q = 0; q < 6; ++q) {
                const std::size_t i = 6 * p + static_cast<std::size_t>(q);
                if (bits(gpu_values[i]) != bits(cpu_values[i]) && ++value_mismatches <= 5)
                    ADD_FAILURE() << "seed " << seed << " patch " << p << " plane " << q << ": GPU " << gpu_values[i]
                                  << " CPU " << cpu_values[i];
            }
            culled_total += cpu[p];
            for (const Vec4& cp : c.patches[p].cp) {
                const Vec4 clip = m * cp;  // w > 0 weights keep the sign of clip w
                if (clip.w <= 0.0f) {
                    ++behind_eye;
                    break;
                }
            }
        }
        total += cpu.size();
    }
    EXPECT_EQ(value_mismatches, 0u);
    // Both outcomes are well represented, and patches reach behind the eye.
    EXPECT_GT(culled_total, total / 10);
    EXPECT_LT(culled_total, total * 9 / 10);
    EXPECT_GT(behind_eye, total / 20);
}

TEST(GpuFrustumDispCull, MarginIsUsedAndCatchesAZeroBuffer) {
    // Patches just outside the left plane at distances 0.05 .. 0.5: without margins all culled;
    // with margin 1 none; with the mixed buffer exactly those whose margin reaches the frustum.
    // A pass that ignored the buffer (or read it as zeros) fails the mixed case.
    Camera cam;  // at (0,0,5) looking at the origin
    const Mat4 vp = cam.view_projection();
    const FrustumPlanes planes = make_frustum_planes(vp, ClipDepth::zero_to_one);
    std::vector<BezierPatch> patches;
    std::vector<float> margins;
    for (int i = 0; i < 10; ++i) {
        BezierPatch patch;
        // The left plane at z = 0 is x = -5 tan(fovy/2) aspect; place the patch's right edge outside it.
        const float edge = -planes.rows[0].w / planes.rows[0].x;  // x where w + x = 0 on the z = 0 plane (y = 0)
        const float gap = 0.05f * static_cast<float>(i + 1);
        for (int k = 0; k < 16; ++k) {
            const int col = k % 4, row = k / 4;
            patch.cp[k] = homogeneous(Vec3{edge - gap - 0.1f * col, 0.1f * row - 0.15f, 0.0f});
        }
        patches.push_back(patch);
        margins.push_back(i % 2 ? 0.6f : 0.0f);
    }
    PatchRenderer r(test::context());
    const PatchBatch batch = make_batch(patches);
    std::vector<std::uint8_t> cpu(patches.size());

    r.set_patches(patches);
    cull_frustum_disp(r, vp, ClipDepth::zero_to_one);
    for (std::uint32_t f : r.read_cull_flags()) EXPECT_EQ(f, 1u);

    r.set_patches(patches, test::margins_only(margins));
    cull_frustum_disp(r, vp, ClipDepth::zero_to_one);
    const auto flags = r.read_cull_flags();
    cull_frustum_disp_scalar(batch.view(), margins.data(), vp, ClipDepth::zero_to_one, cpu.data());
    std::size_t kept = 0;
    for (std::size_t p = 0; p < patches.size(); ++p) {
        EXPECT_EQ(flags[p] != 0, cpu[p] != 0) << "patch " << p;
        if (margins[p] == 0.0f) {
            EXPECT_EQ(flags[p], 1u) << "patch " << p;
        }
        // A margin larger than the gap (the box reaches over the plane) keeps the patch.
        if (margins[p] > 0.05f * static_cast<float>(p + 1) * 1.5f) {
            EXPECT_EQ(flags[p], 0u) << "patch " << p;
        }
        kept += flags[p] == 0;
    }
    EXPECT_GT(kept, 0u);
}

TEST(GpuFrustumDispCull, StrictIdBufferUnchangedByCullingDisplaced) {
    // The rendered surface is displaced (procedural map, each patch sampling its own texture
    // window) with the margin = the patch's DisplacementRange max |D|. Culling with the pass must
    // not change the id buffer; the margin must matter (some visible patches are culled without
    // it) and the pass must cull.
    const std::vector<BezierPatch> patches = test::split_teapot(2);  // 512 patches
    const Bounds bounds = test::control_point_bounds(patches);
    const DisplacementMap map = make_procedural_displacement(64, 0.08f * length(bounds.max - bounds.min));
    const PatchAttributes attributes = test::random_texture_windows(patches.size(), map, 7);
    PatchRenderer r(test::context());
    r.set_patches(patches, attributes);
    r.set_displacement_map(map);
    const PatchBatch batch = make_batch(patches);
    ViewGenerator gen(bounds, ViewMode::free, 31);
    std::size_t culled = 0, visible = 0, needed_margin = 0, disagreements = 0;
    const int views = 10;
    for (int v = 0; v < views; ++v) {
        const Camera cam = gen.next();
        SCOPED_TRACE("view " + std::to_string(v));
        RenderParams params;
        params.view = cam.view();
        params.projection = cam.projection();
        params.width = params.height = 192;
        params.tess_level = 8;
        params.use_cull_flags = false;
        r.render(params);
        const std::vector<std::uint32_t> reference = r.read_ids();

        cull_frustum_disp(r, cam.view_projection(), ClipDepth::zero_to_one);
        const std::vector<std::uint32_t> flags = r.read_cull_flags();
        params.use_cull_flags = true;
        r.render(params);
        const std::vector<std::uint32_t> culled_ids = r.read_ids();

        std::vector<std::uint8_t> cpu(patches.size()), cpu_no_margin(patches.size());
        cull_frustum_disp_scalar(batch.view(), attributes.max_displacement.data(), cam.view_projection(),
                                 ClipDepth::zero_to_one, cpu.data());
        cull_frustum_disp_scalar(batch.view(), nullptr, cam.view_projection(), ClipDepth::zero_to_one,
                                 cpu_no_margin.data());
        for (std::size_t p = 0; p < patches.size(); ++p) {
            disagreements += (flags[p] != 0) != (cpu[p] != 0);
            culled += flags[p] != 0;
        }
        const auto present = test::ids_present(reference);
        for (std::uint32_t id : present) {
            EXPECT_EQ(flags[id - 1], 0u) << "false cull: patch " << id - 1 << " is visible unculled but culled";
            needed_margin += cpu_no_margin[id - 1];
        }
        visible += present.size();
        std::size_t differ = 0;
        for (std::size_t i = 0; i < reference.size(); ++i) differ += culled_ids[i] != reference[i];
        EXPECT_EQ(differ, 0u) << "pixels differ between the culled and the unculled id buffer";
    }
    EXPECT_EQ(disagreements, 0u);
    EXPECT_GT(culled, views * patches.size() / 10);
    EXPECT_GT(visible, static_cast<std::size_t>(views) * 20);
    EXPECT_GT(needed_margin, 0u);
    RecordProperty("culled", static_cast<int>(culled));
    RecordProperty("needed_margin", static_cast<int>(needed_margin));
}
