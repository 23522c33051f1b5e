// Cull-method evaluation over random views with dense-sample ground truth (patchcull/cull_eval.h).
// The methods run as an engine would run them: SIMD kernels over all cores, per view.
#include "patchcull/cull_eval.h"

#include <algorithm>
#include <chrono>
#include <functional>

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
};

/// Which ground truth judges a method's decisions.
enum class Truth { frustum };

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
             cull_frustum_disp_simd(b, d, v.object_to_clip, out);
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
    for (const std::string& name : options.methods) {
        const Method* m = find_method(name);
        if (!m) throw Error("--methods: unknown cull method '" + name + "'");
        selected.push_back(m);
    }
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

    // Ground-truth samples of every patch, computed once (the frame is static).
    const int grid = options.ground_truth_grid;
    const std::size_t per_patch = static_cast<std::size_t>(grid) * grid;
    std::vector<Vec3> samples(n * per_patch);
    std::vector<SampleSphere> spheres(n);
    parallel_for_ranges(n, 64, [&](std::size_t first, std::size_t last) {
        for (std::size_t p = first; p < last; ++p) {
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
        ctx.planes = make_frustum_planes(ctx.object_to_clip);
        for (std::size_t m = 0; m < selected.size(); ++m) {
            const auto start = std::chrono::steady_clock::now();
            parallel_for_ranges(n, kGrain, [&](std::size_t first, std::size_t last) {
                selected[m]->kernel(batch.view().subrange(first, last - first), disp_ptr ? disp_ptr + first : nullptr,
                                    ctx, culled.data() + first);
            });
            seconds[m] += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            CullMethodResult& r = result.methods[m];
            for (std::size_t p = 0; p < n; ++p) {
                if (!culled[p]) continue;
                ++r.culled;
                if (sphere_outside_clip_volume(ctx.object_to_clip, spheres[p])) continue;  // exact shortcut
                if (any_point_in_clip_volume(ctx.object_to_clip, &samples[p * per_patch], per_patch)) ++r.false_culls;
            }
        }
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
