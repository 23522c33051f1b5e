// Cull-method evaluation over random views with dense-sample ground truth (patchcull/cull_eval.h).
// The methods run as an engine would run them: SIMD kernels over all cores, per view.
#include "patchcull/cull_eval.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <string>

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

/// Seeded views of the DistanceViews distribution (cull_eval.h). Its own splitmix64 stream, so
/// the contain and free distributions (camera.cpp) keep their sequences.
class DistanceViewGenerator {
public:
    DistanceViewGenerator(const Bounds& object, const DistanceViews& range, std::uint64_t seed, float aspect)
        : object_(object), range_(range), state_(seed * 0x9E3779B97F4A7C15ull + 0xD1B54A32D192ED03ull), aspect_(aspect) {}

    Camera next() {
        Camera cam;
        cam.aspect = aspect_;
        cam.fovy_radians = DistanceViews::fovy_degrees * 3.14159265f / 180.0f;
        const Vec3 c = object_.center();
        const float radius = std::max(object_.radius(), 1e-6f);
        // The narrower side of the view: the bounding sphere must fit inside it.
        const float half_v = 0.5f * cam.fovy_radians;
        const float half = std::min(half_v, std::atan(std::tan(half_v) * std::min(aspect_, 1.0f)));
        const float fit = radius / std::sin(half);
        const float distance = fit * (range_.min + (range_.max - range_.min) * uniform());
        const Vec3 dir = unit_vector();
        cam.eye = c + dir * distance;
        cam.target = c;
        // An up vector across the view direction (a random one could lie along it).
        Vec3 up = cross(dir, unit_vector());
        if (length(up) < 1e-3f) up = cross(dir, std::fabs(dir.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0});
        cam.up = normalize(up);
        cam.z_near = std::max(1e-4f * radius, (distance - radius) * 0.9f);
        cam.z_far = (distance + radius) * 1.1f;
        return cam;
    }

private:
    float uniform() {  // [0, 1), the top 24 bits of splitmix64 as camera.cpp does
        std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        z ^= z >> 31;
        return static_cast<float>(z >> 40) * (1.0f / 16777216.0f);
    }
    Vec3 unit_vector() {
        const float z = 2 * uniform() - 1;
        const float a = 6.2831853f * uniform();
        const float r = std::sqrt(std::max(0.0f, 1 - z * z));
        return {r * std::cos(a), r * std::sin(a), z};
    }

    Bounds object_;
    DistanceViews range_;
    std::uint64_t state_;
    float aspect_;
};

void check_distance_views(const DistanceViews& d) {
    // Written so NaN fails every test.
    if (!(d.min >= 1.0f && d.min <= 1000.0f))
        throw Error("distance range: min " + std::to_string(d.min) + " is not in 1..1000 (below 1 the object leaves the view)");
    if (!(d.max >= d.min && d.max <= 1000.0f))
        throw Error("distance range: max " + std::to_string(d.max) + " is not in min..1000");
}

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
    if (options.distance) check_distance_views(*options.distance);
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
    std::optional<DistanceViewGenerator> distance_views;
    if (options.distance) distance_views.emplace(bounds, *options.distance, options.seed, options.aspect);
    const Vec3 centre = bounds.center();
    const double radius = std::max(bounds.radius(), 1e-6f);
    double eye_distance_sum = 0;

    CullEvalResult result;
    result.patches = n;
    result.views = options.views;
    result.methods.resize(selected.size());
    std::vector<double> seconds(selected.size(), 0.0);
    std::vector<std::uint8_t> culled(n);
    for (int view = 0; view < options.views; ++view) {
        const Camera camera = distance_views ? distance_views->next() : views.next();
        eye_distance_sum += length(camera.eye - centre) / radius;
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
    result.mean_eye_distance_radii = options.views > 0 ? eye_distance_sum / options.views : 0.0;
    for (std::size_t m = 0; m < selected.size(); ++m) {
        CullMethodResult& r = result.methods[m];
        r.name = selected[m]->name;
        r.cull_rate = options.views > 0 ? r.culled / pairs : 0.0;
        r.ns_per_patch = options.views > 0 ? seconds[m] * 1e9 / pairs : 0.0;
    }
    return result;
}

}  // namespace patchcull
