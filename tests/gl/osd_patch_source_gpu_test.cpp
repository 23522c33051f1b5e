// The GPU cull passes over the caller's own control points (GpuPatchSource of gl_passes.h,
// shaders/patch_source.h) against the CPU entries over the same PatchSourceView or
// OsdPatchTableSource (core/patch_source.h, import/osd_patch_table.h): the flag words equal the
// CPU decisions patch for patch (FrustumPass <-> cull_frustum, OcclusionPass <-> cull_occlusion,
// BackpatchConePass and BackpatchPtpPass <-> cull_backpatch; in a second test FrustumDispPass <->
// cull_frustum_disp and FusedCullPass <-> cull_fused for every test mask that is a valid plan, tcone
// and ncone), in every ClipDepth convention.
// - OpenSubdiv tables: regression shapes with semi-sharp and infinitely sharp creases, corners,
//   holes and boundaries, adaptively refined to levels 1-4 with Gregory-basis and B-spline-basis
//   end caps, the vertex buffer float3 or float4 at odd strides and offsets; the table's index
//   arrays and boundary masks uploaded once (GpuOsdTable below, the binding an engine writes).
// - Plain sources: Bezier and B-spline patches (random boundary masks, phantom slots holding
//   indices past the buffer) and Gregory patches indexed into a shuffled float3 or rational float4
//   buffer, and consecutive points without indices, a few with NaN and infinite coordinates.
// - An index past point_count leaves its patch unculled; each bad input is a one-line Error.
#include <gtest/gtest.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyRefiner.h>

#include "core/ptp_internal.h"
#include "gl_test_util.h"
#include "import/osd_topology.h"
#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/clip_space.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/fused_cull.h"
#include "patchcull/core/hiz.h"
#include "patchcull/core/patch_source.h"
#include "patchcull/gl/gl_passes.h"
#include "patchcull/import/obj.h"
#include "patchcull/import/osd_patch_table.h"

using namespace patchcull;
using namespace patchcull::gl;
namespace Far = OpenSubdiv::Far;

namespace {

// ---- GL helpers --------------------------------------------------------------------------------

// A GL buffer holding `bytes` bytes of data (zeros when data is null), deleted at scope end.
class GlBuffer {
public:
    GlBuffer() = default;
    GlBuffer(const void* data, std::size_t bytes) {
        test::passes();
        glCreateBuffers(1, &name_);
        std::vector<std::uint8_t> zeros;
        if (!data) {
            zeros.assign(std::max<std::size_t>(bytes, 4), 0);
            data = zeros.data();
        }
        glNamedBufferData(name_, static_cast<GLsizeiptr>(std::max<std::size_t>(bytes, 4)), data, GL_DYNAMIC_DRAW);
    }
    GlBuffer(GlBuffer&& o) noexcept : name_(std::exchange(o.name_, 0)) {}
    GlBuffer& operator=(GlBuffer&& o) noexcept {
        std::swap(name_, o.name_);
        return *this;
    }
    ~GlBuffer() {
        if (name_) glDeleteBuffers(1, &name_);
    }
    GLuint name() const { return name_; }

private:
    GLuint name_ = 0;
};

struct Passes {
    FrustumPass frustum{test::passes()};
    OcclusionPass occlusion{test::passes()};
    BackpatchConePass cones{test::passes()};
    BackpatchPtpPass ptp{test::passes()};
    HiZBuildPass hiz_build{test::passes()};
    FrustumDispPass frustum_disp{test::passes()};
    FusedCullPass fused{test::passes()};
};

Passes& gpu() {
    static Passes p;
    return p;
}

// ---- Subjects: CPU views and their GPU twins over one flag buffer --------------------------------

struct Part {
    PatchSourceView cpu;
    GpuPatchSource gpu;  // flags [gpu.first, gpu.first + gpu.count)
};

struct Subject {
    std::string name;
    std::vector<Part> parts;
    const OsdPatchTableSource* table = nullptr;  // the CPU decisions over the table when set
    std::size_t patch_count = 0;
    GlBuffer flags;
    Vec3 centre{0, 0, 0};
    float radius = 1;
    std::vector<std::uint8_t> gregory;  // per patch
};

// An OsdPatchTableSource's arrays as GPU patch sources over the caller's vertex buffer: the
// table's index arrays (in array order) and the boundary masks (a byte per table patch) uploaded
// once; array a is a source of its own whose flags are the table's patches [first_patch,
// first_patch + count) of one flag buffer.
struct GpuOsdTable {
    GlBuffer indices, masks;
    std::vector<GpuPatchSource> arrays;

    GpuOsdTable(const OsdPatchTableSource& table, GLuint vertices, const PointLayout& layout, GLuint flags) {
        std::vector<std::uint32_t> all_indices;
        std::vector<std::uint8_t> all_masks((table.patch_count() + 3) / 4 * 4, 0);
        std::vector<std::size_t> index_offset;
        for (const OsdPatchArraySource& a : table.arrays()) {
            const std::size_t n = static_cast<std::size_t>(patch_source_points(a.source.basis)) * a.source.count;
            index_offset.push_back(all_indices.size());
            all_indices.insert(all_indices.end(), a.source.indices, a.source.indices + n);
            if (a.source.boundary_mask)
                std::copy(a.source.boundary_mask, a.source.boundary_mask + a.source.count,
                          all_masks.begin() + static_cast<std::ptrdiff_t>(a.first_patch));
        }
        indices = GlBuffer(all_indices.data(), all_indices.size() * sizeof(std::uint32_t));
        masks = GlBuffer(all_masks.data(), all_masks.size());
        for (std::size_t i = 0; i < table.arrays().size(); ++i) {
            const OsdPatchArraySource& a = table.arrays()[i];
            GpuPatchSource s;
            s.vertices = vertices;
            s.stride_bytes = layout.stride_bytes;
            s.offset_bytes = layout.offset_bytes;
            s.components = layout.components;
            s.point_count = layout.point_count;
            s.basis = a.source.basis;
            s.indices = indices.name();
            s.indices_offset_bytes = index_offset[i] * sizeof(std::uint32_t);
            if (a.source.boundary_mask) {
                s.boundary_masks = masks.name();
                s.masks_offset_bytes = a.first_patch;
            }
            s.flags = flags;
            s.first = a.first_patch;
            s.count = a.source.count;
            s.source_first = 0;
            arrays.push_back(s);
        }
    }
};

// ---- Views ------------------------------------------------------------------------------------

constexpr int W = 64, H = 48;

struct ViewCase {
    CullView view;
    HiZPyramid hiz;
    HiZTexture gpu_hiz;
    GLuint depth_texture = 0;
    ViewCase() = default;
    ViewCase(const ViewCase&) = delete;
    ViewCase& operator=(const ViewCase&) = delete;
    ~ViewCase() {
        glDeleteTextures(1, &depth_texture);
        glDeleteTextures(1, &gpu_hiz.texture);
    }
};

// A random view of a subject in convention depth, from distances that put parts of it outside
// the frustum (the far plane cuts through it), and a depth layer of random rectangles across its
// depth range; the pyramid built on the CPU and on the GPU from the same depth buffer.
void make_view(const Subject& s, std::mt19937& rng, ClipDepth depth, ViewCase& out) {
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    Vec3 dir{u(rng), u(rng), u(rng)};
    dir = normalize(dir + Vec3{0, 0, 1e-3f});
    const float dist = s.radius * (0.4f + 2.6f * unit(rng));
    const Vec3 eye = s.centre + dist * dir;
    const Vec3 target = s.centre + (0.6f * s.radius) * Vec3{u(rng), u(rng), u(rng)};
    const float fovy = 0.5f + 0.8f * unit(rng);
    const float z_near = 0.02f * s.radius, z_far = dist + 0.8f * s.radius;
    const Mat4 projection = perspective(fovy, float(W) / float(H), z_near, z_far, depth);
    out.view = make_cull_view(look_at(eye, target, {0, 1, 0}), projection, depth, eye);

    const bool reversed = is_reversed(depth);
    std::vector<float> buffer(static_cast<std::size_t>(W) * H, reversed ? 0.0f : 1.0f);
    const auto window_depth = [&](float distance) {
        const Vec4 q = projection * Vec4{0, 0, -distance, 1};
        const float d = q.z / q.w;
        return depth == ClipDepth::minus_one_to_one ? 0.5f * d + 0.5f : d;
    };
    for (int r = 0; r < 6; ++r) {
        const int x0 = static_cast<int>(unit(rng) * W), y0 = static_cast<int>(unit(rng) * H);
        const int w = 1 + static_cast<int>(unit(rng) * W * 0.7f), h = 1 + static_cast<int>(unit(rng) * H * 0.7f);
        const float z = window_depth(std::max(2.0f * z_near, dist + s.radius * (1.2f * unit(rng) - 0.9f)));
        for (int y = y0; y < std::min(H, y0 + h); ++y)
            for (int x = x0; x < std::min(W, x0 + w); ++x) {
                float& d = buffer[static_cast<std::size_t>(y) * W + static_cast<std::size_t>(x)];
                d = reversed ? std::max(d, z) : std::min(d, z);
            }
    }
    out.hiz.build(buffer.data(), W, H, depth);
    glCreateTextures(GL_TEXTURE_2D, 1, &out.depth_texture);
    glTextureStorage2D(out.depth_texture, 1, GL_DEPTH_COMPONENT32F, W, H);
    glTextureSubImage2D(out.depth_texture, 0, 0, 0, W, H, GL_DEPTH_COMPONENT, GL_FLOAT, buffer.data());
    out.gpu_hiz = create_hiz_texture(W, H);
    gpu().hiz_build.run(out.depth_texture, out.gpu_hiz, depth);
}

// ---- The comparison ---------------------------------------------------------------------------

struct Tally {
    std::size_t tested = 0, viewed = 0, frustum = 0, occluded = 0, back = 0, gregory_culled = 0;
    std::size_t gregory_back = 0;  // Gregory patches the CPU culls by a back-patch cone
    std::size_t box = 0, fused_frustum = 0, fused_back = 0, fused_occluded = 0;  // the second test's
    int mismatches = 0;
};

// Which passes compare_view compares: the first test's (frustum, occlusion, back-patch) or the
// second's (frustum-disp, fused).
enum class Compared { separate, box_and_fused };

// Clears the flags, runs `pass` on every part, reads the flag words back.
std::vector<std::uint32_t> run_gpu(const Subject& s, const std::function<void(const GpuPatchSource&)>& pass) {
    const std::uint32_t zero = 0;
    glClearNamedBufferData(s.flags.name(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    for (const Part& p : s.parts) pass(p.gpu);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<std::uint32_t> flags(s.patch_count);
    glGetNamedBufferSubData(s.flags.name(), 0, static_cast<GLsizeiptr>(flags.size() * 4), flags.data());
    return flags;
}

// Expects flag word i to be want(i) for every patch.
void expect_flags(const Subject& s, const char* what, ClipDepth depth, const std::vector<std::uint32_t>& got,
                  const std::function<std::uint32_t(std::size_t)>& want, Tally& tally) {
    for (std::size_t i = 0; i < s.patch_count; ++i) {
        ++tally.tested;
        const std::uint32_t w = want(i);
        if (w != 0 && s.gregory[i]) ++tally.gregory_culled;
        if ((w & kCullBackPatch) != 0 && s.gregory[i]) ++tally.gregory_back;
        if (got[i] != w && ++tally.mismatches <= 8)
            ADD_FAILURE() << s.name << ", " << what << ", " << clip_depth_name(depth) << ": patch " << i
                          << (s.gregory[i] ? " (gregory)" : "") << " has flag word " << got[i] << ", the CPU says "
                          << w;
    }
}

std::vector<float> read_floats(const GlBuffer& buffer, std::size_t count) {
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<float> out(count);
    glGetNamedBufferSubData(buffer.name(), 0, static_cast<GLsizeiptr>(count * sizeof(float)), out.data());
    return out;
}

bool same_float(float a, float b) {
    return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b) || (std::isnan(a) && std::isnan(b));
}

// The points the CPU reads for patch i of a source: source_bezier_patch's 16 (Bezier and B-spline),
// or a Gregory patch's 20 as stored.
std::vector<Vec4> cpu_points(const PatchSourceView& v, std::size_t i) {
    std::vector<Vec4> out;
    if (v.basis != PatchBasis::gregory) {
        const BezierPatch b = source_bezier_patch(v, i);
        out.assign(std::begin(b.cp), std::end(b.cp));
        return out;
    }
    for (std::size_t k = 0; k < 20; ++k) {
        const std::size_t index = v.indices ? v.indices[20 * i + k] : 20 * i + k;
        float q[4] = {0, 0, 0, 1};
        std::memcpy(q, static_cast<const char*>(v.points.data) + v.points.offset_bytes + index * v.points.stride_bytes,
                    static_cast<std::size_t>(v.points.components) * sizeof(float));
        out.push_back({q[0], q[1], q[2], q[3]});
    }
    return out;
}

// The gathered points, bit for bit, through the frustum pass's diagnostics: the six plane maxima
// of every patch equal FrustumVerdict's over the CPU's points.
void expect_gathered_points(const Subject& s, const CullView& view, const std::vector<float>& got, Tally& tally) {
    for (const Part& part : s.parts)
        for (std::size_t i = 0; i < part.gpu.count; ++i) {
            FrustumVerdict verdict;
            for (const Vec4& q : cpu_points(part.cpu, i)) {
                float v[6];
                frustum_plane_values(view.planes, q.x, q.y, q.z, q.w, v);
                verdict.add(v);
            }
            const std::size_t p = part.gpu.first + i;
            for (int q = 0; q < 6; ++q)
                if (!same_float(got[6 * p + static_cast<std::size_t>(q)], verdict.max[q]) && ++tally.mismatches <= 8)
                    ADD_FAILURE() << s.name << ", " << clip_depth_name(view.depth) << ": patch " << p
                                  << (s.gregory[p] ? " (gregory)" : "") << ", plane " << q << ": the GPU's maximum "
                                  << got[6 * p + static_cast<std::size_t>(q)] << ", the CPU's " << verdict.max[q];
        }
}

// The same through ptp's diagnostics: every control plane value t (a sum over all 16 points) and
// margin, bit for bit (Bezier and B-spline parts).
void expect_ptp_planes(const Subject& s, const CullView& view, const std::vector<float>& got, Tally& tally) {
    ptp_detail::PtpClipRows rows;
    if (!ptp_detail::ptp_clip_rows(view.object_to_clip, view.alpha, rows)) return;
    for (const Part& part : s.parts) {
        if (part.cpu.basis == PatchBasis::gregory) continue;
        for (std::size_t i = 0; i < part.gpu.count; ++i) {
            const BezierPatch b = source_bezier_patch(part.cpu, i);
            float t[64], thr[64];
            ptp_detail::ptp_control_planes_z(b, rows, t);
            // A patch with a NaN point is never culled and its margins are not compared: the
            // max and min over the points then depend on where the NaN stands and on how each
            // machine's max treats it (the CPU's std::max keeps its first argument).
            const bool all_finite = std::all_of(std::begin(b.cp), std::end(b.cp), [](const Vec4& q) {
                return std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) && std::isfinite(q.w);
            });
            const bool finite = ptp_detail::ptp_rounding_margins(b, rows, thr) && all_finite;
            const std::size_t p = part.gpu.first + i;
            for (std::size_t k = 0; k < 64; ++k) {
                const bool same =
                    same_float(got[128 * p + k], t[k]) && (!finite || same_float(got[128 * p + 64 + k], thr[k]));
                if (!same && ++tally.mismatches <= 8)
                    ADD_FAILURE() << s.name << ", " << clip_depth_name(view.depth) << ": patch " << p << ", ptp t[" << k
                                  << "]: the GPU's " << got[128 * p + k] << " (margin " << got[128 * p + 64 + k]
                                  << "), the CPU's " << t[k] << " (margin " << thr[k] << ")";
            }
        }
    }
}

// FrustumDispPass <-> cull_frustum_disp; FusedCullPass <-> cull_fused with the plan of its test
// mask in the chain's order (frustum, back-patch, Hi-Z), over every part (an OpenSubdiv table's
// arrays, each at its table position).
void compare_box_and_fused(const Subject& s, const ViewCase& vc, Tally& tally) {
    const CullView& view = vc.view;
    const std::size_t n = s.patch_count;
    std::vector<std::uint8_t> cpu(n + 1, 0xAB);
    const auto for_parts = [&](const std::function<void(const PatchSourceView&, std::uint8_t*)>& entry) {
        std::fill(cpu.begin(), cpu.end() - 1, 0);
        for (const Part& p : s.parts) entry(p.cpu, cpu.data() + p.gpu.first);
    };
    tally.viewed += n;

    for_parts([&](const PatchSourceView& v, std::uint8_t* out) { cull_frustum_disp(v, nullptr, view, out); });
    EXPECT_EQ(cpu[n], 0xAB);
    std::vector<std::uint32_t> got = run_gpu(s, [&](const GpuPatchSource& g) { gpu().frustum_disp.run(g, view); });
    expect_flags(
        s, "frustum-disp", view.depth, got, [&](std::size_t i) { return cpu[i] ? kCullFrustum : 0u; }, tally);
    tally.box += static_cast<std::size_t>(std::count_if(cpu.begin(), cpu.end() - 1, [](auto c) { return c; }));

    struct Fused {
        std::uint32_t tests;
        BackpatchMethod method;
        const char* name;
    };
    const std::uint32_t all = kCullFrustum | kCullBackPatch | kCullOcclusion;
    for (const Fused& f :
         {Fused{all, BackpatchMethod::tcone, "fused FBH tcone"}, Fused{all, BackpatchMethod::ncone, "fused FBH ncone"},
          Fused{kCullFrustum | kCullOcclusion, BackpatchMethod::tcone, "fused FH"},
          Fused{kCullFrustum | kCullBackPatch, BackpatchMethod::tcone, "fused FB"},
          Fused{kCullBackPatch, BackpatchMethod::ncone, "fused B ncone"}}) {
        FusedPlan plan;  // the chain's order
        plan.count = 0;
        for (const auto& [bit, stage] :
             {std::pair{kCullFrustum, FusedStage::frustum}, std::pair{kCullBackPatch, FusedStage::backpatch},
              std::pair{kCullOcclusion, FusedStage::occlusion}})
            if (f.tests & bit) plan.stages[plan.count++] = stage;
        const FusedCullSetup setup = make_fused_setup(
            view, f.method == BackpatchMethod::ncone ? BackPatchCone::ncone : BackPatchCone::tcone, &vc.hiz);
        for_parts([&](const PatchSourceView& v, std::uint8_t* out) { cull_fused(v, setup, plan, out); });
        got = run_gpu(s, [&](const GpuPatchSource& g) { gpu().fused.run(g, f.tests, view, f.method, &vc.gpu_hiz); });
        expect_flags(
            s, f.name, view.depth, got,
            [&](std::size_t i) {
                return cpu[i] == kFusedFrustumCulled     ? kCullFrustum
                       : cpu[i] == kFusedBackPatchCulled ? kCullBackPatch
                       : cpu[i] == kFusedOccluded        ? kCullOcclusion
                                                         : 0u;
            },
            tally);
        for (std::size_t i = 0; i < n; ++i) {
            tally.fused_frustum += cpu[i] == kFusedFrustumCulled;
            tally.fused_back += cpu[i] == kFusedBackPatchCulled;
            tally.fused_occluded += cpu[i] == kFusedOccluded;
        }
    }
}

void compare_view(const Subject& s, const ViewCase& vc, Tally& tally, Compared compared) {
    if (compared == Compared::box_and_fused) return compare_box_and_fused(s, vc, tally);
    const CullView& view = vc.view;
    const std::size_t n = s.patch_count;
    std::vector<std::uint8_t> cpu(n + 1, 0xAB);
    // Flag words outside every part's range stay 0 (the CPU's 0 there too).
    const auto for_parts = [&](const std::function<void(const PatchSourceView&, std::uint8_t*)>& entry) {
        std::fill(cpu.begin(), cpu.end() - 1, 0);
        for (const Part& p : s.parts) entry(p.cpu, cpu.data() + p.gpu.first);
    };
    tally.viewed += n;

    // Frustum.
    if (s.table) {
        cull_frustum(*s.table, nullptr, view, cpu.data());
    } else {
        for_parts([&](const PatchSourceView& v, std::uint8_t* out) { cull_frustum(v, nullptr, view, out); });
    }
    EXPECT_EQ(cpu[n], 0xAB);
    const GlBuffer plane_values(nullptr, 6 * n * sizeof(float));
    std::vector<std::uint32_t> got =
        run_gpu(s, [&](const GpuPatchSource& g) { gpu().frustum.run(g, view, plane_values.name()); });
    expect_gathered_points(s, view, read_floats(plane_values, 6 * n), tally);
    expect_flags(
        s, "frustum", view.depth, got, [&](std::size_t i) { return cpu[i] ? kCullFrustum : 0u; }, tally);
    tally.frustum += static_cast<std::size_t>(std::count_if(cpu.begin(), cpu.end() - 1, [](auto c) { return c; }));

    // Occlusion (with the frustum test first, as cull_occlusion).
    if (s.table) {
        cull_occlusion(*s.table, view, vc.hiz, cpu.data());
    } else {
        for_parts([&](const PatchSourceView& v, std::uint8_t* out) { cull_occlusion(v, view, vc.hiz, out); });
    }
    got = run_gpu(s, [&](const GpuPatchSource& g) { gpu().occlusion.run(g, view, vc.gpu_hiz); });
    expect_flags(
        s, "occlusion", view.depth, got,
        [&](std::size_t i) {
            return cpu[i] == kHiZFrustumCulled ? kCullFrustum : cpu[i] == kHiZOccluded ? kCullOcclusion : 0u;
        },
        tally);
    tally.occluded += static_cast<std::size_t>(std::count(cpu.begin(), cpu.end() - 1, kHiZOccluded));

    // Back-patch: tcone, ncone, ptp with both rules.
    struct Method {
        BackpatchMethod id;
        PtpRule rule;
        const char* name;
    };
    for (const Method& m : {Method{BackpatchMethod::tcone, PtpRule::ncnt, "tcone"},
                            Method{BackpatchMethod::ncone, PtpRule::ncnt, "ncone"},
                            Method{BackpatchMethod::ptp, PtpRule::ncnt, "ptp ncnt"},
                            Method{BackpatchMethod::ptp, PtpRule::pcnt, "ptp pcnt"}}) {
        BackpatchOptions options;
        options.ptp_rule = m.rule;
        if (s.table) {
            cull_backpatch(m.id, *s.table, view, options, cpu.data());
        } else {
            for_parts(
                [&](const PatchSourceView& v, std::uint8_t* out) { cull_backpatch(m.id, v, view, options, out); });
        }
        const bool with_planes = m.id == BackpatchMethod::ptp && m.rule == PtpRule::ncnt;
        const GlBuffer ptp_planes(nullptr, with_planes ? 128 * n * sizeof(float) : 4);
        got = run_gpu(s, [&](const GpuPatchSource& g) {
            if (m.id == BackpatchMethod::ptp) {
                gpu().ptp.run(g, view.object_to_clip, view.alpha, m.rule, with_planes ? ptp_planes.name() : 0);
            } else {
                gpu().cones.run(g, m.id, view.eye);
            }
        });
        expect_flags(
            s, m.name, view.depth, got, [&](std::size_t i) { return cpu[i] ? kCullBackPatch : 0u; }, tally);
        if (with_planes) expect_ptp_planes(s, view, read_floats(ptp_planes, 128 * n), tally);
        tally.back += static_cast<std::size_t>(std::count_if(cpu.begin(), cpu.end() - 1, [](auto c) { return c; }));
    }
}

// Views of the subject in every convention (views_per_depth of each).
void compare_views(const Subject& s, std::mt19937& rng, int views_per_depth, Tally& tally, Compared compared) {
    for (int v = 0; v < views_per_depth; ++v)
        for (ClipDepth depth :
             {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one, ClipDepth::reversed, ClipDepth::reversed_infinite}) {
            ViewCase vc;
            make_view(s, rng, depth, vc);
            compare_view(s, vc, tally, compared);
        }
}

// ---- OpenSubdiv tables --------------------------------------------------------------------------

using EndCap = Far::PatchTableFactory::Options::EndCapType;
constexpr EndCap kGregoryEnds = Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS;
constexpr EndCap kBsplineEnds = Far::PatchTableFactory::Options::ENDCAP_BSPLINE_BASIS;

struct D3 {
    double x = 0, y = 0, z = 0;
    void Clear(void* = nullptr) { x = y = z = 0; }
    void AddWithWeight(const D3& p, double w) {
        x += w * p.x;
        y += w * p.y;
        z += w * p.z;
    }
};

// A table of shape (tests/data/opensubdiv) at level with the end caps given, and its vertex
// buffer (every refined level, then the local points) in layout.
struct OsdCase {
    osd_detail::RefinerPtr refiner;
    std::unique_ptr<const Far::PatchTable> table;
    std::vector<unsigned char> bytes;
    PointLayout layout;
    OsdPatchTableSource source;
    GlBuffer vertices;
    std::unique_ptr<GpuOsdTable> gpu_table;
    Subject subject;
};

std::unique_ptr<OsdCase> make_osd_case(const std::string& shape, int level, EndCap ends, int components,
                                       std::size_t stride, std::size_t offset) {
    auto c = std::make_unique<OsdCase>();
    const ControlMesh mesh = load_obj(std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/opensubdiv/" + shape + ".obj");
    c->refiner = osd_detail::create_refiner(mesh);
    Far::PatchTableFactory::Options options(level);
    options.SetEndCapType(ends);
    c->refiner->RefineAdaptive(options.GetRefineAdaptiveOptions());
    c->table.reset(Far::PatchTableFactory::Create(*c->refiner, options));
    const int refined = c->refiner->GetNumVerticesTotal();
    std::vector<D3> all(static_cast<std::size_t>(refined + c->table->GetNumLocalPoints()));
    for (std::size_t v = 0; v < mesh.positions.size(); ++v)
        all[v] = D3{mesh.positions[v].x, mesh.positions[v].y, mesh.positions[v].z};
    Far::PrimvarRefinerReal<double> primvar(*c->refiner);
    D3* src = all.data();
    for (int l = 1; l <= c->refiner->GetMaxLevel(); ++l) {
        D3* dst = src + c->refiner->GetLevel(l - 1).GetNumVertices();
        primvar.Interpolate(l, src, dst);
        src = dst;
    }
    if (const auto* local = c->table->GetLocalPointStencilTable<float>())
        local->UpdateValues(all.data(), all.data() + refined);
    c->bytes.assign(all.size() * stride, 0xCD);  // padding: NaN-like garbage
    Vec3 lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
    for (std::size_t i = 0; i < all.size(); ++i) {
        const float xyzw[4] = {static_cast<float>(all[i].x), static_cast<float>(all[i].y), static_cast<float>(all[i].z),
                               1.0f};
        std::memcpy(c->bytes.data() + i * stride + offset, xyzw, static_cast<std::size_t>(components) * sizeof(float));
        lo = {std::min(lo.x, xyzw[0]), std::min(lo.y, xyzw[1]), std::min(lo.z, xyzw[2])};
        hi = {std::max(hi.x, xyzw[0]), std::max(hi.y, xyzw[1]), std::max(hi.z, xyzw[2])};
    }
    c->layout = PointLayout{c->bytes.data(), stride, offset, components, all.size()};
    c->source = OsdPatchTableSource(*c->table, c->layout);
    c->vertices = GlBuffer(c->bytes.data(), c->bytes.size());
    Subject& s = c->subject;
    s.name = shape + " level " + std::to_string(level) + (ends == kGregoryEnds ? ", gregory" : ", bspline") +
             " ends, float" + std::to_string(components) + " stride " + std::to_string(stride);
    s.patch_count = c->source.patch_count();
    s.flags = GlBuffer(nullptr, s.patch_count * sizeof(std::uint32_t));
    c->gpu_table = std::make_unique<GpuOsdTable>(c->source, c->vertices.name(), c->layout, s.flags.name());
    s.table = &c->source;
    s.gregory.assign(s.patch_count, 0);
    for (std::size_t a = 0; a < c->source.arrays().size(); ++a) {
        const OsdPatchArraySource& arr = c->source.arrays()[a];
        s.parts.push_back({arr.source, c->gpu_table->arrays[a]});
        if (arr.source.basis == PatchBasis::gregory)
            std::fill_n(s.gregory.begin() + static_cast<std::ptrdiff_t>(arr.first_patch), arr.source.count, 1);
    }
    s.centre = 0.5f * (lo + hi);
    s.radius = 0.5f * length(hi - lo);
    return c;
}

// Every shape and level with both end caps, float3 and float4 alternating: one view per convention.
// For the second test (box_and_fused) half of them: Gregory end caps at levels 1 and 3, B-spline
// end caps at levels 2 and 4.
void check_tables(Compared compared) {
    const char* const shapes[] = {"catmark_chaikin1", "catmark_cubes_infsharp", "catmark_edgeonly",
                                  "catmark_hole_test1"};
    std::mt19937 rng(compared == Compared::separate ? 20261204 : 1204);
    Tally tally;
    std::size_t gregory = 0, boundary = 0, tables = 0;
    for (const char* shape : shapes)
        for (int level = 1; level <= 4; ++level)
            for (EndCap ends : {kGregoryEnds, kBsplineEnds}) {
                if (compared == Compared::box_and_fused && (level % 2 == 1) != (ends == kGregoryEnds)) continue;
                const bool float4 = (level + (ends == kBsplineEnds)) % 2 == 1;
                const auto c = make_osd_case(shape, level, ends, float4 ? 4 : 3, float4 ? 36 : 28, float4 ? 12 : 8);
                for (const OsdPatchArraySource& a : c->source.arrays()) {
                    if (a.source.basis == PatchBasis::gregory) gregory += a.source.count;
                    if (a.source.boundary_mask)
                        for (std::size_t p = 0; p < a.source.count; ++p) boundary += a.source.boundary_mask[p] != 0;
                }
                compare_views(c->subject, rng, 1, tally, compared);
                ++tables;
                if (tally.mismatches > 8) break;
            }
    EXPECT_EQ(tally.mismatches, 0);
    EXPECT_GT(gregory, 100u);
    EXPECT_GT(boundary, 100u);
    if (compared == Compared::box_and_fused) {
        EXPECT_EQ(tables, 16u);
        EXPECT_GT(tally.box, tally.viewed / 40) << "frustum-disp culls";
        EXPECT_GT(tally.fused_frustum, tally.viewed / 10) << "fused frustum culls (the five masks together)";
        EXPECT_GT(tally.fused_occluded, tally.viewed / 100) << "fused occlusion culls";
        EXPECT_GT(tally.fused_back, tally.viewed / 10) << "fused back-patch culls";
        EXPECT_GT(tally.gregory_culled, 10u);
        return;
    }
    EXPECT_EQ(tables, 32u);
    // The views cull a good fraction, Gregory end caps included: the comparison sees both answers.
    EXPECT_GT(tally.frustum, tally.viewed / 20) << "frustum culls";
    EXPECT_GT(tally.occluded, tally.viewed / 100) << "occlusion culls";
    EXPECT_GT(tally.back, tally.viewed / 10) << "back-patch culls (the four methods together)";
    EXPECT_GT(tally.gregory_culled, 10u);
    EXPECT_GT(tally.gregory_back, 0u) << "Gregory patches culled by the Gregory cone";
}

// ---- Plain sources ----------------------------------------------------------------------------

// Bezier and B-spline sources over the split teapot's control points, and a Gregory source of
// the same patches (F+ and F- the Bezier interior point, moved apart a little), in a shuffled
// vertex buffer with unused vertices between (indexed), and consecutive points (not indexed; the
// Gregory points after the others, from a multiple of 20: a CPU view from there, source_first on
// the GPU); float3 at stride 20 from byte 4, or homogeneous float4 with weights in [0.5, 2] at
// stride 24 from byte 8. A few patches of each source carry NaN or infinite coordinates.
struct PlainCase {
    std::vector<unsigned char> bytes;
    std::vector<std::uint32_t> indices, bspline_indices, gregory_indices;
    std::vector<std::uint8_t> masks;
    GlBuffer vertices, index_buffer, mask_buffer;
    Subject subject;
};

std::unique_ptr<PlainCase> make_plain_case(int components, bool indexed, std::uint32_t seed) {
    auto c = std::make_unique<PlainCase>();
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(0, 1);
    const std::vector<BezierPatch> patches = test::split_teapot(2);  // 512 patches
    const std::size_t n = patches.size();
    const std::size_t stride = components == 4 ? 24 : 20, offset = components == 4 ? 8 : 4;
    // Points: patch p's point k is point 16 p + k, its Gregory patch's point k is point g0 + 20 p +
    // k, each placed at slot perm[point] of a buffer twice as large (indexed) or at point (not
    // indexed).
    const std::size_t g0 = (16 * n + 19) / 20 * 20, logical = g0 + 20 * n;
    const std::size_t points = indexed ? 2 * logical : logical;
    std::vector<std::uint32_t> perm(points);
    std::iota(perm.begin(), perm.end(), 0u);
    if (indexed) std::shuffle(perm.begin(), perm.end(), rng);
    c->bytes.assign(points * stride, 0x7F);
    for (std::size_t p = 0; p < n; ++p)
        for (int k = 0; k < 16; ++k) {
            Vec4 q = patches[p].cp[k];
            if (p % 97 == 5 && k == 6) q.y = std::numeric_limits<float>::quiet_NaN();
            if (p % 97 == 11 && k == 9) q.x = std::numeric_limits<float>::infinity();
            const float w = components == 4 ? std::exp2(2.0f * unit(rng) - 1.0f) : 1.0f;
            const float xyzw[4] = {w * q.x, w * q.y, w * q.z, w};
            const std::size_t at = perm[16 * p + static_cast<std::size_t>(k)];
            std::memcpy(c->bytes.data() + at * stride + offset, xyzw, static_cast<std::size_t>(components) * 4);
        }
    // Gregory points (Far's GREGORY_BASIS order: corner c's P, E+, E-, F+, F- at 5c) of patch p.
    constexpr int kGregoryOf[20][2] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}, {1, 1}, {3, 0}, {3, 1}, {2, 0}, {2, 1}, {2, 1},
                                       {3, 3}, {2, 3}, {3, 2}, {2, 2}, {2, 2}, {0, 3}, {0, 2}, {1, 3}, {1, 2}, {1, 2}};
    std::mt19937 gregory_rng(seed + 1);  // its own: the other sources' points and masks stay as they were
    for (std::size_t p = 0; p < n; ++p)
        for (int k = 0; k < 20; ++k) {
            Vec4 q = patches[p].cp[4 * kGregoryOf[k][1] + kGregoryOf[k][0]];
            if (k % 5 >= 3)
                q = {q.x + 0.02f * (unit(gregory_rng) - 0.5f), q.y + 0.02f * (unit(gregory_rng) - 0.5f), q.z, q.w};
            if (p % 97 == 7 && k == 13) q.z = std::numeric_limits<float>::quiet_NaN();
            if (p % 97 == 13 && k == 2) q.x = -std::numeric_limits<float>::infinity();
            const float w = components == 4 ? std::exp2(2.0f * unit(gregory_rng) - 1.0f) : 1.0f;
            const float xyzw[4] = {w * q.x, w * q.y, w * q.z, w};
            const std::size_t at = perm[g0 + 20 * p + static_cast<std::size_t>(k)];
            std::memcpy(c->bytes.data() + at * stride + offset, xyzw, static_cast<std::size_t>(components) * 4);
        }
    const PointLayout layout{c->bytes.data(), stride, offset, components, points};
    c->vertices = GlBuffer(c->bytes.data(), c->bytes.size());
    Subject& s = c->subject;
    s.name = std::string("teapot, float") + std::to_string(components) + (indexed ? ", indexed" : ", consecutive");
    // Flags: the Bezier source's patches at [0, n), the B-spline source's at [n + 3, 2n + 3), the
    // Gregory source's at [2n + 5, 3n + 5).
    s.patch_count = 3 * n + 5;
    s.flags = GlBuffer(nullptr, s.patch_count * sizeof(std::uint32_t));
    s.gregory.assign(s.patch_count, 0);
    std::fill_n(s.gregory.begin() + static_cast<std::ptrdiff_t>(2 * n + 5), n, 1);
    if (indexed) {
        c->indices.assign(perm.begin(), perm.begin() + static_cast<std::ptrdiff_t>(16 * n));
        c->bspline_indices = c->indices;
        c->masks.resize((n + 3) / 4 * 4);
        for (std::size_t p = 0; p < n; ++p) {
            c->masks[p] = static_cast<std::uint8_t>(p % 3 == 0 ? 0 : rng() % 16);
            const std::uint32_t real = bspline_real_slots(c->masks[p]);
            for (int k = 0; k < 16; ++k)  // phantom slots: never read
                if (!((real >> k) & 1u))
                    c->bspline_indices[16 * p + static_cast<std::size_t>(k)] = 0xFFFFFFF0u + p % 16;
        }
        c->gregory_indices.assign(perm.begin() + static_cast<std::ptrdiff_t>(g0),
                                  perm.begin() + static_cast<std::ptrdiff_t>(g0 + 20 * n));
        // One index buffer: two patches of garbage, the B-spline source's indices (from byte
        // 128), the Bezier source's (from byte 128 + 64 n), the Gregory source's (from byte 128 +
        // 128 n); the masks after two bytes of garbage.
        std::vector<std::uint32_t> gpu_indices(32, 0xFFFFFFFFu);
        gpu_indices.insert(gpu_indices.end(), c->bspline_indices.begin(), c->bspline_indices.end());
        gpu_indices.insert(gpu_indices.end(), c->indices.begin(), c->indices.end());
        gpu_indices.insert(gpu_indices.end(), c->gregory_indices.begin(), c->gregory_indices.end());
        std::vector<std::uint8_t> gpu_masks(2, 0xFF);
        gpu_masks.insert(gpu_masks.end(), c->masks.begin(), c->masks.end());
        gpu_masks.resize((gpu_masks.size() + 3) / 4 * 4, 0xFF);
        c->index_buffer = GlBuffer(gpu_indices.data(), gpu_indices.size() * 4);
        c->mask_buffer = GlBuffer(gpu_masks.data(), gpu_masks.size());
    }
    for (PatchBasis basis : {PatchBasis::bezier, PatchBasis::bspline, PatchBasis::gregory}) {
        Part part;
        part.cpu.points = layout;
        part.cpu.count = n;
        part.cpu.basis = basis;
        GpuPatchSource& g = part.gpu;
        g.vertices = c->vertices.name();
        g.stride_bytes = stride;
        g.offset_bytes = offset;
        g.components = components;
        g.point_count = points;
        g.basis = basis;
        g.flags = s.flags.name();
        g.count = n;
        if (basis == PatchBasis::bspline) {
            g.first = n + 3;
            g.source_first = 0;
        }
        if (basis == PatchBasis::gregory) {
            g.first = 2 * n + 5;
            if (!indexed) {  // the points from g0: a view from there, source patches from g0 / 20
                part.cpu.points.data = c->bytes.data() + g0 * stride;
                part.cpu.points.point_count = points - g0;
                g.source_first = g0 / 20;
            }
        }
        if (indexed) {
            part.cpu.indices = basis == PatchBasis::bspline  ? c->bspline_indices.data()
                               : basis == PatchBasis::bezier ? c->indices.data()
                                                             : c->gregory_indices.data();
            g.indices = c->index_buffer.name();
            g.indices_offset_bytes = 32 * 4 + (basis == PatchBasis::bspline  ? 0
                                               : basis == PatchBasis::bezier ? 64 * n
                                                                             : 128 * n);
            if (basis == PatchBasis::bspline) {
                part.cpu.boundary_mask = c->masks.data();
                g.boundary_masks = c->mask_buffer.name();
                g.masks_offset_bytes = 2;
            }
        }
        s.parts.push_back(part);
    }
    s.centre = {0, 0, 1.5f};
    s.radius = 3.5f;
    return c;
}

// float3 and float4, indexed and consecutive: one view per convention.
void check_plain_sources(Compared compared) {
    std::mt19937 rng(compared == Compared::separate ? 7 : 8);
    Tally tally;
    for (int components : {3, 4})
        for (bool indexed : {true, false}) {
            const auto c = make_plain_case(components, indexed, 100u + static_cast<std::uint32_t>(components));
            compare_views(c->subject, rng, 1, tally, compared);
        }
    EXPECT_EQ(tally.mismatches, 0);
    EXPECT_GT(tally.gregory_culled, 0u);
    if (compared == Compared::box_and_fused) {
        EXPECT_GT(tally.box, 0u);
        EXPECT_GT(tally.fused_frustum, 0u);
        EXPECT_GT(tally.fused_occluded, 0u);
        EXPECT_GT(tally.fused_back, 0u);
        return;
    }
    EXPECT_GT(tally.frustum, 0u);
    EXPECT_GT(tally.occluded, 0u);
    EXPECT_GT(tally.back, 0u);
}

// One test, so that llvmpipe compiles the seven programs once (about 12 s without Mesa's shader
// cache; the comparisons themselves take about 4 s on 2 cores).
TEST(OsdPatchSourceGpu, TablesAndStridedSourcesMatchTheCpuPatchForPatch) {
    check_plain_sources(Compared::separate);
    check_tables(Compared::separate);
}

// FrustumDispPass and FusedCullPass (tcone and ncone, Bezier, B-spline and Gregory programs) on
// the same kinds of sources: half of the tables, every plain source.
TEST(OsdPatchSourceGpu, FrustumDispAndFusedMatchTheCpuPatchForPatch) {
    check_plain_sources(Compared::box_and_fused);
    check_tables(Compared::box_and_fused);
}

// A source patch whose index lies past point_count is never read: the passes leave it unculled
// (the CPU entries refuse the view instead), and the other patches are culled as usual.
TEST(OsdPatchSourceGpu, IndexPastThePointsLeavesThePatchUnculled) {
    const std::vector<BezierPatch> patches = test::split_teapot(0);
    std::vector<float> points;
    for (const BezierPatch& b : patches)
        for (const Vec4& q : b.cp) points.insert(points.end(), {q.x, q.y, q.z});
    std::vector<std::uint32_t> indices(16 * patches.size());
    std::iota(indices.begin(), indices.end(), 0u);
    indices[16 * 3 + 5] = static_cast<std::uint32_t>(16 * patches.size());  // one past the points
    const GlBuffer vertices(points.data(), points.size() * 4), index_buffer(indices.data(), indices.size() * 4);
    Subject s;
    s.patch_count = patches.size();
    s.flags = GlBuffer(nullptr, patches.size() * 4);
    GpuPatchSource g;
    g.vertices = vertices.name();
    g.stride_bytes = 12;
    g.point_count = 16 * patches.size();
    g.indices = index_buffer.name();
    g.flags = s.flags.name();
    g.count = patches.size();
    s.parts.push_back({PatchSourceView{}, g});
    // Looking away from the teapot: every readable patch is outside the frustum.
    const CullView view =
        make_cull_view(look_at({0, 0, 10}, {0, 0, 20}, {0, 1, 0}),
                       perspective(0.8f, 1.0f, 0.1f, 100.0f, ClipDepth::zero_to_one), ClipDepth::zero_to_one);
    const std::vector<std::uint32_t> got = run_gpu(s, [&](const GpuPatchSource& src) { gpu().frustum.run(src, view); });
    for (std::size_t p = 0; p < patches.size(); ++p) EXPECT_EQ(got[p], p == 3 ? 0u : kCullFrustum) << "patch " << p;
    const std::vector<std::uint32_t> box =
        run_gpu(s, [&](const GpuPatchSource& src) { gpu().frustum_disp.run(src, view); });
    const std::vector<std::uint32_t> fused = run_gpu(s, [&](const GpuPatchSource& src) {
        gpu().fused.run(src, kCullFrustum | kCullBackPatch, view, BackpatchMethod::tcone, nullptr);
    });
    for (std::size_t p = 0; p < patches.size(); ++p) {
        EXPECT_EQ(box[p], p == 3 ? 0u : kCullFrustum) << "frustum-disp, patch " << p;
        EXPECT_EQ(fused[p], p == 3 ? 0u : kCullFrustum) << "fused, patch " << p;
    }
}

// ---- Bad input --------------------------------------------------------------------------------

// The message of what run() throws ("" when nothing): one line.
std::string error_of(const std::function<void()>& run) {
    try {
        run();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

TEST(OsdPatchSourceGpu, BadSourcesAreOneLineErrors) {
    std::vector<float> points(16 * 4 * 2, 0.5f);
    const GlBuffer vertices(points.data(), points.size() * 4);  // 32 float4 points, 512 bytes
    std::vector<std::uint32_t> indices(32, 0);
    const GlBuffer index_buffer(indices.data(), indices.size() * 4);
    const GlBuffer small(nullptr, 8), flags(nullptr, 8), masks(nullptr, 4);
    const auto good = [&] {
        GpuPatchSource g;
        g.vertices = vertices.name();
        g.stride_bytes = 16;
        g.components = 4;
        g.point_count = 32;
        g.flags = flags.name();
        g.count = 2;
        return g;
    };
    const CullView view =
        make_cull_view(look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}),
                       perspective(0.8f, 1.0f, 0.1f, 100.0f, ClipDepth::zero_to_one), ClipDepth::zero_to_one);
    const auto frustum_error = [&](const GpuPatchSource& g) { return error_of([&] { gpu().frustum.run(g, view); }); };
    EXPECT_EQ(frustum_error(good()), "");

    struct Bad {
        std::function<void(GpuPatchSource&)> change;
        const char* says;
    };
    const Bad bad[] = {
        {[](GpuPatchSource& g) { g.components = 5; }, "source.components is 5"},
        {[](GpuPatchSource& g) { g.stride_bytes = 18; }, "multiples of 4"},
        {[](GpuPatchSource& g) { g.offset_bytes = 2; }, "multiples of 4"},
        {[](GpuPatchSource& g) { g.stride_bytes = 12; }, "a point must lie inside its vertex"},
        {[](GpuPatchSource& g) { g.basis = static_cast<PatchBasis>(7); }, "unknown source.basis 7"},
        {[&](GpuPatchSource& g) { g.boundary_masks = masks.name(); }, "boundary_masks is for bspline sources only"},
        {[&](GpuPatchSource& g) {
             g.basis = PatchBasis::gregory;
             g.boundary_masks = masks.name();
         },
         "the basis is gregory"},
        {[](GpuPatchSource& g) { g.point_count = 31; }, "need 32 points, but point_count is 31"},
        {[](GpuPatchSource& g) { g.point_count = 0; }, "source.point_count is 0"},
        {[](GpuPatchSource& g) { g.basis = PatchBasis::gregory; }, "need 40 points"},
        {[&](GpuPatchSource& g) { g.vertices = small.name(); }, "vertex buffer of 8 bytes, 512 needed"},
        {[](GpuPatchSource& g) { g.vertices = 0; }, "vertex 0 is not a buffer"},
        {[&](GpuPatchSource& g) {
             g.indices = index_buffer.name();
             g.indices_offset_bytes = 8;
         },
         "index buffer of 128 bytes, 136 needed"},
        {[&](GpuPatchSource& g) {
             g.indices = index_buffer.name();
             g.indices_offset_bytes = 2;
         },
         "indices_offset_bytes is 2, not a multiple of 4"},
        {[&](GpuPatchSource& g) {
             g.basis = PatchBasis::bspline;
             g.boundary_masks = masks.name();
             g.masks_offset_bytes = 3;
         },
         "boundary-mask buffer of 4 bytes, 8 needed"},
        {[&](GpuPatchSource& g) { g.first = 1; }, "flag buffer of 8 bytes, 12 needed"},
        {[&](GpuPatchSource& g) {
             g.flags = index_buffer.name();
             g.margins = small.name();
             g.first = 1;
         },
         "margin buffer of 8 bytes, 12 needed"},
        {[](GpuPatchSource& g) { g.source_first = 1; }, "need 48 points"},
    };
    for (const Bad& b : bad) {
        GpuPatchSource g = good();
        b.change(g);
        const std::string e = frustum_error(g);
        EXPECT_NE(e.find(b.says), std::string::npos) << "got: " << e << "\nwanted: " << b.says;
        EXPECT_EQ(e.rfind("GL: FrustumPass: ", 0), 0u) << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
    // The other passes check alike, before anything runs.
    GpuPatchSource g = good();
    g.boundary_masks = masks.name();
    HiZTexture hiz = create_hiz_texture(8, 8);
    EXPECT_NE(error_of([&] { gpu().occlusion.run(g, view, hiz); }).find("GL: OcclusionPass: source.boundary_masks"),
              std::string::npos);
    EXPECT_NE(error_of([&] {
                  gpu().cones.run(g, BackpatchMethod::tcone, view.eye);
              }).find("GL: BackpatchConePass: source.boundary_masks"),
              std::string::npos);
    EXPECT_NE(error_of([&] {
                  gpu().ptp.run(g, view.object_to_clip, view.alpha, PtpRule::ncnt);
              }).find("GL: BackpatchPtpPass: source.boundary_masks"),
              std::string::npos);
    EXPECT_NE(error_of([&] { gpu().frustum_disp.run(g, view); }).find("GL: FrustumDispPass: source.boundary_masks"),
              std::string::npos);
    EXPECT_NE(error_of([&] {
                  gpu().fused.run(g, kCullFrustum, view, BackpatchMethod::tcone, nullptr);
              }).find("GL: FusedCullPass: source.boundary_masks"),
              std::string::npos);
    // The fused pass's own refusals hold over a source too, one line each.
    for (const std::string& e :
         {error_of([&] { gpu().fused.run(good(), kCullOcclusion, view, BackpatchMethod::tcone, nullptr); }),
          error_of([&] { gpu().fused.run(good(), kCullBackPatch, view, BackpatchMethod::ptp, nullptr); }),
          error_of([&] { gpu().fused.run(good(), kCullObject, view, BackpatchMethod::tcone, nullptr); })}) {
        EXPECT_EQ(e.rfind("GL: FusedCullPass: ", 0), 0u) << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
    const GlBuffer few_values(nullptr, 8);
    EXPECT_NE(error_of([&] {
                  gpu().frustum_disp.run(good(), view, few_values.name());
              }).find("GL: FrustumDispPass: plane-value buffer of 8 bytes, 48 needed"),
              std::string::npos);
    glDeleteTextures(1, &hiz.texture);
    // ptp never culls a Gregory source: validated, nothing runs.
    g = good();
    g.basis = PatchBasis::gregory;
    g.count = 1;
    EXPECT_FALSE(gpu().ptp.run(g, view.object_to_clip, view.alpha, PtpRule::ncnt));
    EXPECT_EQ(error_of([&] { gpu().cones.run(g, BackpatchMethod::ncone, view.eye); }), "");
    // An empty range reads nothing and checks nothing.
    GpuPatchSource empty;
    EXPECT_EQ(error_of([&] { gpu().frustum.run(empty, view); }), "");
}

}  // namespace
