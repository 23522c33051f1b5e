// Posing on the GPU (gl_posing.h's StencilPoser, ScenePoser::gpu_tables/gpu_meshes,
// render --pose): the control points and ACC tangent vectors the compute pass writes into the
// renderer's buffers are BIT-IDENTICAL to ScenePoser::pose() (read back, compared as bytes), for
// both schemes, over several frames, with a mirrored, a walking and a rigid instance; the teapot
// poses through identity rows; the cull pipeline's id buffer and flag words with GPU posing equal
// those with CPU posing; `render --pose gpu --verify` has no false culls and the same per-frame
// statistics as --pose cpu (default scene both schemes, city_small with its displaced frogs);
// the CPU readers of posed patches (object level, --cull auto) keep a CPU pose under --pose gpu;
// `--pose foo` is a one-line error. llvmpipe, small sizes.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli_test_util.h"
#include "core/test_patches.h"
#include "gl_test_util.h"
#include "patchcull/core/error.h"
#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/gl/gl_posing.h"
#include "patchcull/gl/gl_renderer.h"
#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/model_loader.h"
#include "patchcull/import/scene_poser.h"
#include "shared.h"

using namespace patchcull;
using namespace patchcull::gl;

namespace {

template <class T>
std::vector<T> read_buffer(std::uint32_t buffer, std::size_t count) {
    std::vector<T> out(count);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(buffer, 0, static_cast<GLsizeiptr>(count * sizeof(T)), out.data());
    return out;
}

StencilTableView view_of(const PointStencils& s) {
    return {s.offsets.data(), s.rows(), s.indices.data(), s.weights.data()};
}

// A StencilPoser over the scene's tables (ScenePoser::gpu_tables), as tools/frame_poser.cpp
// makes it.
StencilPoser make_poser(ScenePoser& poser, bool on_current_context = false) {
    std::vector<PosingModel> models;
    for (const PoseModelTables& t : poser.gpu_tables())
        models.push_back({view_of(*t.patch_points), view_of(*t.tangent_points), t.tangent_index, t.vertex_count});
    std::vector<std::uint32_t> instance_models;
    for (const SceneInstance& i : poser.scene().instances)
        instance_models.push_back(static_cast<std::uint32_t>(i.model));
    test::context().make_current();
    StencilPoser gpu =
        on_current_context ? StencilPoser(StencilPoser::CurrentContext{}) : StencilPoser(test::context());
    gpu.set_tables(models, instance_models);
    return gpu;
}

void gpu_pose(StencilPoser& gpu, ScenePoser& poser, float t, PatchRenderer& r) {
    const PoseMeshes& meshes = poser.gpu_meshes(t);
    std::vector<PosingInstance> instances;
    for (std::size_t i = 0; i < meshes.first_vertex.size(); ++i)
        instances.push_back({meshes.first_vertex[i], meshes.to_world[i], meshes.mirrored[i] != 0});
    gpu.pose(meshes.vertices, instances, r.patch_buffer(), r.tangent_buffer());
}

// The renderer's tangent layout of a CPU pose (renderer_internal.h's set_patches).
std::vector<Vec4> tangent_layout(const ScenePoser& poser, std::size_t patches) {
    std::vector<Vec4> out(patches * 24);
    for (std::size_t p = 0; p < patches; ++p) {
        const std::int32_t t = poser.tangent_index()[p];
        if (t < 0) continue;
        const TangentPatches& tp = poser.tangents()[static_cast<std::size_t>(t)];
        for (int k = 0; k < 12; ++k) out[24 * p + k] = {tp.du[k].x, tp.du[k].y, tp.du[k].z, 0.0f};
        for (int k = 0; k < 12; ++k) out[24 * p + 12 + k] = {tp.dv[k].x, tp.dv[k].y, tp.dv[k].z, 0.0f};
        out[24 * p].w = 1.0f;
    }
    return out;
}

// The default scene with a mirrored (x -> -x) BigGuy, a walking frog and a rigid BigGuy: every
// path of ScenePoser at once.
Scene varied_default_scene(Scheme scheme) {
    Scene scene = make_default_scene(scheme);
    Mat4 mirror;
    mirror.at(0, 0) = -1;
    scene.instances[0].object_to_world = mirror * scene.instances[0].object_to_world;
    scene.instances[1].deforms = false;
    scene.instances[4].velocity = {0.2f, 0, -0.1f};
    return scene;
}

// Poses `scene` at each time on the CPU and on the GPU and compares the buffers bit for bit.
// small_upload: the scene's models have control meshes, so the per-frame upload must be a small
// fraction of the patches' (the teapot's identity rows upload its control points as Vec3).
void expect_identical_poses(const Scene& scene, const std::vector<float>& times, bool small_upload = true) {
    ScenePoser cpu(scene), gpu_side(scene);
    const std::vector<BezierPatch>& first = cpu.pose(times.front());
    PatchAttributes a;
    a.tangent_index = cpu.tangent_index();
    a.tangents = cpu.tangents();
    PatchRenderer r(test::context());
    // Zero points in the patch buffer (the tangent buffer gets the layout's size): everything compared
    // below was written by the pass.
    BezierPatch placeholder;  // zero points, weight 1 (weights must be positive: patch.h)
    for (Vec4& c : placeholder.cp) c = {0, 0, 0, 1};
    r.set_patches(std::vector<BezierPatch>(first.size(), placeholder), a);
    StencilPoser gpu = make_poser(gpu_side);
    ASSERT_EQ(gpu.patch_count(), first.size());
    for (float t : times) {
        const std::vector<BezierPatch>& posed = cpu.pose(t);
        gpu_pose(gpu, gpu_side, t, r);
        const std::vector<BezierPatch> back = read_buffer<BezierPatch>(r.patch_buffer(), posed.size());
        std::size_t differing = 0;
        for (std::size_t p = 0; p < posed.size(); ++p)
            differing += test_patches::bit_identical(back[p], posed[p]) ? 0 : 1;
        EXPECT_EQ(differing, 0u) << scene.name << " t=" << t << ": patches differing from the CPU pose";
        if (gpu.has_tangents()) {
            const std::vector<Vec4> expected = tangent_layout(cpu, posed.size());
            const std::vector<Vec4> got = read_buffer<Vec4>(r.tangent_buffer(), expected.size());
            EXPECT_EQ(std::memcmp(got.data(), expected.data(), expected.size() * sizeof(Vec4)), 0)
                << scene.name << " t=" << t << ": tangent vectors differ";
        }
    }
    EXPECT_GT(gpu.last_upload_bytes(), 0u);
    if (small_upload) {
        EXPECT_LT(gpu.last_upload_bytes(), first.size() * sizeof(BezierPatch) / 10) << "the pose upload is not small";
    }
}

const std::vector<float> kTimes = {0.0f, 1.0f / 12, 5.0f / 12, 1.3f};

}  // namespace

TEST(GpuPosing, BitIdenticalToCpuPoseAcc) {
    const Scene scene = varied_default_scene(Scheme::acc);
    ScenePoser probe(scene);
    probe.pose(0);
    ASSERT_FALSE(probe.tangents().empty()) << "acc must have tangent patches to compare";
    expect_identical_poses(scene, kTimes);
}

TEST(GpuPosing, BitIdenticalToCpuPoseOsd) { expect_identical_poses(varied_default_scene(Scheme::osd), kTimes); }

TEST(GpuPosing, TeapotPosesThroughIdentityRows) {
    Scene scene = make_model_scene(load_model("teapot", Scheme::acc, 0));
    scene.instances[0].velocity = {0.1f, 0, 0};
    expect_identical_poses(scene, {0.0f, 0.5f}, false);
}

// The poser made on the caller's current context (no GlContext) writes the same buffers.
TEST(GpuPosing, OnTheCallersCurrentContext) {
    Scene scene = make_model_scene(load_model("teapot", Scheme::acc, 0));  // no tangents to size
    scene.instances[0].velocity = {0.1f, 0, 0};
    ScenePoser a(scene), b(scene);
    StencilPoser own = make_poser(a), current = make_poser(b, true);
    PatchRenderer ra(test::context()), rb(test::context());
    ra.set_patches(a.pose(0.0f));
    rb.set_patches(b.pose(0.0f));
    gpu_pose(own, a, 0.25f, ra);
    gpu_pose(current, b, 0.25f, rb);
    const std::size_t bytes = ra.patch_count() * sizeof(BezierPatch);
    std::vector<std::uint8_t> pa(bytes), pb(bytes);
    glGetNamedBufferSubData(ra.patch_buffer(), 0, static_cast<GLsizeiptr>(bytes), pa.data());
    glGetNamedBufferSubData(rb.patch_buffer(), 0, static_cast<GLsizeiptr>(bytes), pb.data());
    EXPECT_EQ(pa, pb);
    std::vector<std::uint8_t> rest(bytes);
    const std::vector<BezierPatch>& at_rest = a.pose(0.0f);
    std::memcpy(rest.data(), at_rest.data(), bytes);
    EXPECT_NE(pa, rest) << "the pose at 0.25 s moved the teapot";
}

namespace {

// The posed control meshes written into a buffer of the caller's, as an engine's skinning output
// would hold them: x y z at `stride` bytes from `offset`; everything else (a float4 layout's w, the
// padding) is NaN bytes, which the pass must never read.
std::vector<std::uint8_t> interleave(const std::vector<Vec3>& vertices, std::size_t stride, std::size_t offset) {
    std::vector<std::uint8_t> bytes(offset + vertices.size() * stride + 4, 0xFF);
    for (std::size_t v = 0; v < vertices.size(); ++v) std::memcpy(&bytes[offset + v * stride], &vertices[v], 12);
    return bytes;
}

std::vector<std::uint8_t> read_bytes(std::uint32_t buffer, std::size_t bytes) {
    std::vector<std::uint8_t> out(bytes);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(buffer, 0, static_cast<GLsizeiptr>(bytes), out.data());
    return out;
}

// Poses `scene` at each time through the vector overload and through GpuVertices over the same
// positions in a caller buffer of the given layout, on the caller's current context with the
// caller's output buffers; the written patch and tangent buffers must be equal byte for byte (and
// the patches equal ScenePoser::pose()'s).
void expect_gpu_vertices_like_vector(const Scene& scene, int components, std::size_t stride, std::size_t offset) {
    SCOPED_TRACE(scene.name + ": " + std::to_string(components) + " floats, stride " + std::to_string(stride) +
                 ", offset " + std::to_string(offset));
    ScenePoser cpu(scene), gpu_side(scene);
    StencilPoser gpu = make_poser(gpu_side, true);  // the caller's current context
    const std::size_t patch_bytes = gpu.patch_count() * sizeof(BezierPatch);
    const std::size_t tangent_bytes = gpu.patch_count() * 24 * sizeof(Vec4);
    test::ScratchBuffer pa(patch_bytes), pb(patch_bytes), ta(tangent_bytes), tb(tangent_bytes);
    std::uint32_t caller_vertices = 0;
    glCreateBuffers(1, &caller_vertices);
    for (float t : kTimes) {
        const PoseMeshes& meshes = gpu_side.gpu_meshes(t);
        std::vector<PosingInstance> instances;
        for (std::size_t i = 0; i < meshes.first_vertex.size(); ++i)
            instances.push_back({meshes.first_vertex[i], meshes.to_world[i], meshes.mirrored[i] != 0});
        const std::vector<std::uint8_t> bytes = interleave(meshes.vertices, stride, offset);
        glNamedBufferData(caller_vertices, static_cast<GLsizeiptr>(bytes.size()), bytes.data(), GL_STREAM_DRAW);
        gpu.pose(meshes.vertices, instances, pa.name(), ta.name());
        const GpuVertices in{caller_vertices, offset, stride, components, meshes.vertices.size()};
        gpu.pose(in, instances, pb.name(), tb.name());
        EXPECT_EQ(gpu.last_upload_bytes(), instances.size() * 80) << "only the instances go up";
        GLint bound = 0, program = -1;
        glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, shared::kBindingPoseVertices, &bound);
        glGetIntegerv(GL_CURRENT_PROGRAM, &program);
        EXPECT_EQ(static_cast<std::uint32_t>(bound), caller_vertices) << "the state contract: left bound";
        EXPECT_EQ(program, 0);
        const std::vector<std::uint8_t> a = read_bytes(pa.name(), patch_bytes), b = read_bytes(pb.name(), patch_bytes);
        EXPECT_TRUE(a == b) << "t=" << t << ": patch buffers differ";
        const std::vector<BezierPatch>& posed = cpu.pose(t);
        ASSERT_EQ(posed.size() * sizeof(BezierPatch), patch_bytes);
        EXPECT_EQ(std::memcmp(b.data(), posed.data(), patch_bytes), 0) << "t=" << t << ": differs from the CPU pose";
        if (gpu.has_tangents()) {
            EXPECT_TRUE(read_bytes(ta.name(), tangent_bytes) == read_bytes(tb.name(), tangent_bytes))
                << "t=" << t << ": tangent buffers differ";
            const std::vector<Vec4> expected = tangent_layout(cpu, posed.size());
            EXPECT_EQ(std::memcmp(read_bytes(tb.name(), tangent_bytes).data(), expected.data(), tangent_bytes), 0)
                << "t=" << t << ": tangent vectors differ from the CPU pose";
        }
    }
    glDeleteBuffers(1, &caller_vertices);
}

// One line, naming what is wrong.
void expect_one_line(const std::function<void()>& f, const std::string& needle) {
    try {
        f();
        ADD_FAILURE() << "no error (expected one about " << needle << ")";
    } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(needle), std::string::npos) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
}

}  // namespace

// Float3 at an odd stride and offset (28 bytes from byte 8) and float4 (16 bytes, w never read),
// both schemes (acc with tangents, a mirrored, a walking and a rigid instance).
TEST(GpuPosing, CallerVertexBufferFloat3OddStride) {
    expect_gpu_vertices_like_vector(varied_default_scene(Scheme::acc), 3, 28, 8);
    expect_gpu_vertices_like_vector(varied_default_scene(Scheme::osd), 3, 28, 8);
}

TEST(GpuPosing, CallerVertexBufferFloat4) {
    expect_gpu_vertices_like_vector(varied_default_scene(Scheme::acc), 4, 16, 0);
    expect_gpu_vertices_like_vector(varied_default_scene(Scheme::acc), 4, 20, 12);
}

TEST(GpuPosing, CallerVertexBufferIsChecked) {
    test::context().make_current();
    StencilPoser gpu(StencilPoser::CurrentContext{});
    std::vector<std::uint32_t> offs(17);
    for (std::uint32_t r = 0; r <= 16; ++r) offs[r] = r;
    const std::vector<std::uint32_t> indices(16, 3);
    const std::vector<float> weights(16, 1.0f);
    const PosingModel model{{offs.data(), 16, indices.data(), weights.data()}, {}, {-1}, 4};
    gpu.set_tables({model}, {0, 0});
    test::ScratchBuffer out(2 * sizeof(BezierPatch));
    // 8 vertices of float3 at stride 28 from byte 8: 8 + 7 * 28 + 12 = 216 bytes.
    test::ScratchBuffer vertices(216);
    PosingInstance first, second;
    second.first_vertex = 4;
    const std::vector<PosingInstance> two{first, second};
    const GpuVertices good{vertices.name(), 8, 28, 3, 8};
    auto with = [&](auto change) {
        GpuVertices v = good;
        change(v);
        return [&gpu, &two, &out, v] { gpu.pose(v, two, out.name(), 0); };
    };
    expect_one_line(with([](GpuVertices& v) { v.components = 2; }), "2 components");
    expect_one_line(with([](GpuVertices& v) { v.components = 5; }), "5 components");
    expect_one_line(with([](GpuVertices& v) { v.offset_bytes = 6; }), "offset 6 bytes is not a multiple of 4");
    expect_one_line(with([](GpuVertices& v) { v.stride_bytes = 26; }), "stride 26 bytes is not a multiple of 4");
    expect_one_line(with([](GpuVertices& v) { v.stride_bytes = 8; }), "stride 8 bytes is smaller");
    expect_one_line(with([](GpuVertices& v) {
                        v.components = 4;
                        v.stride_bytes = 12;
                    }),
                    "stride 12 bytes is smaller than its 4 floats");
    expect_one_line(with([](GpuVertices& v) { v.offset_bytes = 12; }), "216 bytes do not hold 8 vertices");
    expect_one_line(with([](GpuVertices& v) { v.components = 4; }), "216 bytes do not hold 8 vertices");  // +4
    expect_one_line(with([](GpuVertices& v) { v.offset_bytes = 1u << 20; }), "do not hold");
    expect_one_line(with([](GpuVertices& v) { v.buffer = 0; }), "is not a buffer object");
    expect_one_line(with([&](GpuVertices& v) { v.buffer = out.name(); }), "is also an output buffer");
    expect_one_line(with([](GpuVertices& v) { v.count = 7; }), "vertices run past the 7 given");
    expect_one_line([&] { gpu.pose(good, {first}, out.name(), 0); }, "1 instances for tables of 2");
    // The good layout poses: vertex 3 of each instance, (1, 2, 3) and (4, 5, 6).
    std::vector<float> floats(216 / 4, -1.0f);
    floats[(8 + 3 * 28) / 4 + 0] = 1;
    floats[(8 + 3 * 28) / 4 + 1] = 2;
    floats[(8 + 3 * 28) / 4 + 2] = 3;
    floats[(8 + 7 * 28) / 4 + 0] = 4;
    floats[(8 + 7 * 28) / 4 + 1] = 5;
    floats[(8 + 7 * 28) / 4 + 2] = 6;
    glNamedBufferSubData(vertices.name(), 0, 216, floats.data());
    gpu.pose(good, two, out.name(), 0);
    const std::vector<float> back = out.read_floats(2 * 64);
    for (int k = 0; k < 32; ++k) {
        const float base = k < 16 ? 0.0f : 3.0f;
        EXPECT_EQ(back[4 * k], base + 1);
        EXPECT_EQ(back[4 * k + 1], base + 2);
        EXPECT_EQ(back[4 * k + 2], base + 3);
        EXPECT_EQ(back[4 * k + 3], 1.0f);
    }
}

TEST(GpuPosing, SplitModelsAreRefused) {
    Scene scene = make_model_scene(load_model("teapot", Scheme::acc, 1));
    ScenePoser poser(scene);
    try {
        poser.gpu_tables();
        FAIL() << "a split model was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("split"), std::string::npos) << e.what();
    }
}

TEST(GpuPosing, MalformedTablesAreRefused) {
    StencilPoser gpu(test::context());
    std::vector<std::uint32_t> offs(17);
    for (std::uint32_t r = 0; r <= 16; ++r) offs[r] = r;
    const std::vector<std::uint32_t> indices(16, 3);  // vertex 3 of a 2-vertex mesh
    const std::vector<float> weights(16, 1.0f);
    PosingModel model{{offs.data(), 16, indices.data(), weights.data()}, {}, {-1}, 2};
    EXPECT_THROW(gpu.set_tables({model}, {0}), Error);
    model.vertex_count = 4;
    EXPECT_THROW(gpu.set_tables({model}, {1}), Error);  // no model 1
    gpu.set_tables({model}, {0, 0});
    EXPECT_EQ(gpu.patch_count(), 2u);
    test::ScratchBuffer small(100);
    PosingInstance inst;
    EXPECT_THROW(gpu.pose(std::vector<Vec3>(4), {inst, inst}, small.name(), 0), Error);  // 100 bytes < 2 patches
    test::ScratchBuffer enough(2 * sizeof(BezierPatch));
    EXPECT_THROW(gpu.pose(std::vector<Vec3>(3), {inst, inst}, enough.name(), 0), Error);  // 3 < 4 vertices
    EXPECT_THROW(gpu.pose(std::vector<Vec3>(4), {inst}, enough.name(), 0), Error);        // one instance short
    gpu.pose(std::vector<Vec3>(4, Vec3{1, 2, 3}), {inst, inst}, enough.name(), 0);
    const std::vector<float> back = enough.read_floats(2 * 64);
    for (int k = 0; k < 32; ++k) {
        EXPECT_EQ(back[4 * k], 1.0f);
        EXPECT_EQ(back[4 * k + 3], 1.0f);
    }
}

TEST(GpuPosing, PipelineIdsAndFlagsEqualCpuPosing) {
    const Scene scene = varied_default_scene(Scheme::acc);
    const std::vector<Camera> cameras = scene.camera_path(3, 160.0f / 90.0f);
    std::vector<std::vector<std::uint32_t>> ids[2], flags[2];
    for (int mode = 0; mode < 2; ++mode) {
        ScenePoser poser(scene);
        CullPipeline pipeline(test::context());
        const std::vector<BezierPatch>& first = poser.pose(0);
        PatchAttributes a;
        a.tangent_index = poser.tangent_index();
        a.tangents = poser.tangents();
        a.depth = poser.depth();
        a.texcoords = poser.texcoords();
        a.displacement_ranges = poser.displacement_ranges();
        pipeline.set_patches(first, a);
        pipeline.renderer().set_displacement_map(scene.displacement);
        pipeline.renderer().set_occluders(scene.occluder_vertices, scene.occluder_indices);
        ScenePoser gpu_side(scene);
        StencilPoser gpu = make_poser(gpu_side);
        for (int f = 0; f < 3; ++f) {
            const float t = f / 12.0f;
            if (f > 0) {
                if (mode == 0) {
                    const std::vector<BezierPatch>& posed = poser.pose(t);
                    a.tangents = poser.tangents();
                    pipeline.update_patches(posed, a);
                } else {
                    gpu_pose(gpu, gpu_side, t, pipeline.renderer());
                }
            }
            PipelineParams params;
            params.frame.render.view = cameras[static_cast<std::size_t>(f)].view();
            params.frame.render.projection = cameras[static_cast<std::size_t>(f)].projection();
            params.frame.render.width = 160;
            params.frame.render.height = 90;
            params.frame.render.tess_level = 4;
            params.frame.render.discard_back_facing = true;
            params.frame.cull = CullMode::all;
            const FrameStats stats = pipeline.render_frame(params);
            EXPECT_GT(stats.frustum_culled + stats.occlusion_culled + stats.backpatch_culled, 0u);
            ids[mode].push_back(pipeline.renderer().read_ids());
            flags[mode].push_back(pipeline.renderer().read_cull_flags());
        }
    }
    for (int f = 0; f < 3; ++f) {
        EXPECT_EQ(ids[0][f], ids[1][f]) << "frame " << f << ": id buffers differ";
        EXPECT_EQ(flags[0][f], flags[1][f]) << "frame " << f << ": flag words differ";
    }
}

namespace {

using namespace patchcull::cli_test;

// Runs render with --pose cpu and gpu; both verified without false culls, with the same
// per-frame statistics; gpu uploads far fewer bytes after frame 0.
void expect_gpu_like_cpu(const std::string& args) {
    nlohmann::json runs[2];
    const char* modes[2] = {"cpu", "gpu"};
    for (int m = 0; m < 2; ++m) {
        const CliRun r = run(args + " --verify --json --pose " + modes[m]);
        ASSERT_EQ(r.status, 0) << args << " --pose " << modes[m] << ": " << r.err;
        runs[m] = nlohmann::json::parse(r.out);
        EXPECT_EQ(runs[m]["pose"], modes[m]);
        EXPECT_EQ(runs[m]["false_culls"], 0) << args;
    }
    ASSERT_EQ(runs[0]["frames"].size(), runs[1]["frames"].size());
    for (std::size_t f = 0; f < runs[0]["frames"].size(); ++f) {
        const auto& c = runs[0]["frames"][f];
        const auto& g = runs[1]["frames"][f];
        for (const char* key : {"pass1_drawn", "pass2_drawn", "frustum_culled", "backpatch_culled", "occlusion_culled",
                                "displaced_occlusion_culled", "visible", "newly_visible", "false_culls"})
            EXPECT_EQ(c[key], g[key]) << args << " frame " << f << " " << key;
        EXPECT_EQ(g["pose"]["where"], "gpu");
        if (f > 0) {
            EXPECT_EQ(g["pose"]["cpu_patches"], false);
            EXPECT_LT(g["pose"]["bytes_uploaded"].get<double>() * 10, c["pose"]["bytes_uploaded"].get<double>())
                << args << " frame " << f;
        }
    }
}

}  // namespace

TEST(GpuPosingCli, VerifiesLikeCpuOnTheDefaultSceneAcc) {
    expect_gpu_like_cpu("render default --scheme acc --size 96x54 --tess 4 --frames 3");
}

TEST(GpuPosingCli, VerifiesLikeCpuOnTheDefaultSceneOsd) {
    // Level 1: osd's deepest patches are tessellated 2^depth times finer (PatchAttributes::depth).
    expect_gpu_like_cpu("render default --scheme osd --size 96x54 --tess 1 --frames 2");
}

TEST(GpuPosingCli, VerifiesLikeCpuOnCitySmall) {
    expect_gpu_like_cpu("render " + std::string(PATCHCULL_SOURCE_DIR) +
                        "/data/scenes/city_small.json --size 96x54 --tess 2 --frames 2");
}

// The CPU object level reads posed patches (its boxes): under --pose gpu it keeps a CPU pose
// (cpu_patches) and stays exactly as conservative.
TEST(GpuPosingCli, CpuReadersKeepACpuPose) {
    for (const char* extra : {"--objects bvh", "--cull auto"}) {
        const CliRun r =
            run(std::string("render default --size 96x54 --tess 2 --frames 3 --verify --json --pose gpu ") + extra);
        ASSERT_EQ(r.status, 0) << extra << ": " << r.err;
        const auto j = nlohmann::json::parse(r.out);
        EXPECT_EQ(j["false_culls"], 0) << extra;
        for (const auto& frame : j["frames"]) {
            EXPECT_EQ(frame["pose"]["where"], "gpu") << extra;
            EXPECT_EQ(frame["pose"]["cpu_patches"], true) << extra;
        }
    }
}

TEST(GpuPosingCli, BadValueIsAOneLineError) {
    expect_one_line_error(run("render default --frames 1 --size 8x8 --pose foo"), "--pose");
    const CliRun split = run("render teapot --split 1 --frames 1 --size 8x8 --pose gpu");
    expect_one_line_error(split, "--pose gpu");
    EXPECT_NE(split.err.find("split"), std::string::npos) << split.err;
}
