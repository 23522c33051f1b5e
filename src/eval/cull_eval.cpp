// Cull-method evaluation over random views with dense-sample ground truth (patchcull/cull_eval.h).
// The methods run as an engine would run them: SIMD kernels over all cores, per view.
#include "patchcull/cull_eval.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>

#include "patchcull/backpatch.h"
#include "patchcull/error.h"
#include "patchcull/frustum.h"
#include "patchcull/ground_truth.h"
#include "patchcull/parallel.h"
#include "patchcull/scene.h"

namespace patchcull {
namespace {

constexpr std::size_t kGrain = 1024;

/// Everything a kernel may need for one view.
struct ViewContext {
    Mat4 object_to_clip;
    FrustumPlanes planes;
    Vec3 eye;     ///< object space
    float alpha;  ///< clip-space eye z (backpatch.h)
};

/// Which ground truth judges a method's decisions: a sample inside the view volume (frustum
/// methods), or a sampled tangent plane facing the eye (back-patch methods, seed 001).
enum class Truth { frustum, backface };

struct Method {
    const char* name;
    Truth truth;
    std::function<void(const PatchBatchView&, const float*, const ViewContext&, std::uint8_t*)> kernel;
};

const std::vector<Method>& methods() {
    static const std::vector<Method> table = {
        {"frustum", Truth::frustum,
         [](const PatchBatchView& b, const float* d, const ViewContext& v, std::uint8_t* out) {
             cull_frustum_simd(b, d, v.planes, out);
         }},
        {"frustum-disp", Truth::frustum,
         [](const PatchBatchView& b, const float* d, const ViewContext& v, std::uint8_t* out) {
             cull_frustum_disp_simd(b, d, v.object_to_clip, ClipDepth::zero_to_one, out);
         }},
        {"tcone", Truth::backface,
         [](const PatchBatchView& b, const float*, const ViewContext& v, std::uint8_t* out) {
             cull_tcone_simd(b, v.eye, out);
         }},
        {"ncone", Truth::backface,
         [](const PatchBatchView& b, const float*, const ViewContext& v, std::uint8_t* out) {
             cull_ncone_simd(b, v.eye, out);
         }},
        {"ptp", Truth::backface,
         [](const PatchBatchView& b, const float*, const ViewContext& v, std::uint8_t* out) {
             cull_ptp_simd(b, v.object_to_clip, v.alpha, PtpRule::ncnt, out);
         }},
        {"ptp-pcnt", Truth::backface,
         [](const PatchBatchView& b, const float*, const ViewContext& v, std::uint8_t* out) {
             cull_ptp_simd(b, v.object_to_clip, v.alpha, PtpRule::pcnt, out);
         }},
    };
    return table;
}

const Method* find_method(const std::string& name) {
    for (const Method& m : methods())
        if (name == m.name) return &m;
    return nullptr;
}

}  // namespace

std::vector<std::string> cull_method_names() {
    std::vector<std::string> names;
    for (const Method& m : methods()) names.push_back(m.name);
    return names;
}

bool is_cull_method(const std::string& name) { return find_method(name) != nullptr; }

CullEvalResult evaluate_cull(const PatchFrame& frame, const DisplacementMap* displacement,
                             const CullEvalOptions& options) {
    std::vector<const Method*> selected;
    bool needs_frustum_truth = false, needs_backface_truth = false;
    for (const std::string& name : options.methods) {
        const Method* m = find_method(name);
        if (!m) throw Error("--methods: unknown cull method '" + name + "'");
        selected.push_back(m);
        (m->truth == Truth::frustum ? needs_frustum_truth : needs_backface_truth) = true;
    }
    if (needs_backface_truth && displacement && !displacement->empty())
        throw Error("--displace: back-patch methods (tcone, ncone, ptp) do not bound displaced patches (seed 001 §8)");
    const std::size_t n = frame.patches.size();
    const PatchBatch batch = make_batch(frame.patches);
    const std::vector<DisplacementRange> ranges = displacement_ranges(frame, displacement);
    std::vector<float> max_disp(n);
    float largest = 0;
    for (std::size_t p = 0; p < n; ++p) {
        max_disp[p] = ranges[p].max_abs();
        largest = std::max(largest, max_disp[p]);
    }
    const float* disp_ptr = largest > 0 ? max_disp.data() : nullptr;

    // Ground-truth samples of every patch, computed once (the frame is static): surface points
    // for the frustum truth, tangent planes for the back-facing truth.
    const int grid = options.ground_truth_grid;
    const std::size_t per_patch = static_cast<std::size_t>(grid) * grid;
    std::vector<Vec3> samples(needs_frustum_truth ? n * per_patch : 0);
    std::vector<SampleSphere> spheres(needs_frustum_truth ? n : 0);
    std::vector<PlaneD> planes(needs_backface_truth ? n * per_patch : 0);
    parallel_for_ranges(n, 64, [&](std::size_t first, std::size_t last) {
        for (std::size_t p = first; p < last; ++p) {
            if (needs_backface_truth) sample_tangent_planes(frame.patches[p], grid, &planes[p * per_patch]);
            if (!needs_frustum_truth) continue;
            const PatchInfo& info = frame.info[p];
            const TangentPatches* t = info.tangent_index >= 0 ? &frame.tangents[info.tangent_index] : nullptr;
            sample_displaced_patch(frame.patches[p], t, info.uv, displacement, grid, &samples[p * per_patch]);
            spheres[p] = bounding_sphere(&samples[p * per_patch], per_patch);
        }
    });

    Bounds bounds = patch_bounds(frame);
    bounds.min = bounds.min - Vec3{largest, largest, largest};
    bounds.max = bounds.max + Vec3{largest, largest, largest};
    ViewGenerator views(bounds, options.mode, options.seed, options.aspect);

    CullEvalResult result;
    result.patches = n;
    result.views = options.views;
    result.methods.resize(selected.size());
    std::vector<double> seconds(selected.size(), 0.0);
    std::vector<std::uint8_t> culled(n);
    for (int view = 0; view < options.views; ++view) {
        const Camera camera = views.next();
        ViewContext ctx;
        ctx.object_to_clip = camera.view_projection();
        ctx.planes = make_frustum_planes(ctx.object_to_clip, ClipDepth::zero_to_one);
        ctx.eye = camera.eye;
        ctx.alpha = clip_space_eye_alpha(camera.projection());
        for (std::size_t m = 0; m < selected.size(); ++m) {
            const auto start = std::chrono::steady_clock::now();
            parallel_for_ranges(n, kGrain, [&](std::size_t first, std::size_t last) {
                selected[m]->kernel(batch.view().subrange(first, last - first), disp_ptr ? disp_ptr + first : nullptr,
                                    ctx, culled.data() + first);
            });
            seconds[m] += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            // Judge every culled patch against the ground truth, in parallel (the truth costs far
            // more than the kernel).
            const bool backface = selected[m]->truth == Truth::backface;
            std::atomic<std::uint64_t> culled_count{0}, false_count{0};
            parallel_for_ranges(n, 256, [&](std::size_t first, std::size_t last) {
                std::uint64_t local_culled = 0, local_false = 0;
                for (std::size_t p = first; p < last; ++p) {
                    if (!culled[p]) continue;
                    ++local_culled;
                    if (backface) {
                        local_false += any_plane_faces_eye(&planes[p * per_patch], per_patch, ctx.eye) ? 1 : 0;
                    } else if (!sphere_outside_clip_volume(ctx.object_to_clip, spheres[p])) {  // exact shortcut
                        local_false += any_point_in_clip_volume(ctx.object_to_clip, &samples[p * per_patch], per_patch) ? 1 : 0;
                    }
                }
                culled_count += local_culled;
                false_count += local_false;
            });
            result.methods[m].culled += culled_count;
            result.methods[m].false_culls += false_count;
        }
        if (options.on_view_done) options.on_view_done(view + 1);
    }
    const double pairs = static_cast<double>(n) * std::max(1, options.views);
    for (std::size_t m = 0; m < selected.size(); ++m) {
        CullMethodResult& r = result.methods[m];
        r.name = selected[m]->name;
        r.cull_rate = options.views > 0 ? r.culled / pairs : 0.0;
        r.ns_per_patch = options.views > 0 ? seconds[m] * 1e9 / pairs : 0.0;
    }
    return result;
}

}  // namespace patchcull
