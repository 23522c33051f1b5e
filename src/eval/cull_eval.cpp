// Cull-method evaluation over random views with dense-sample ground truth (patchcull/eval/cull_eval.h).
// The methods run as an engine would run them: SIMD kernels over all cores, per view. The truth
// is streamed: views go in blocks, and each block is judged chunk by chunk of patches
// with the chunk's samples made in per-thread scratch and dropped, so memory does not grow with
// the patch count beyond the batch and a byte per patch.
#include "patchcull/eval/cull_eval.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <string>

#include "patchcull/core/backpatch.h"
#include "patchcull/core/backpatch_methods.h"
#include "patchcull/core/cull_view.h"
#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/core/ground_truth.h"
#include "patchcull/core/parallel.h"
#include "patchcull/import/model_loader.h"

#include <tbb/enumerable_thread_specific.h>

namespace patchcull {
namespace {

constexpr std::size_t kGrain = 1024;

/// Seeded views of the DistanceViews distribution (cull_eval.h). Its own splitmix64 stream, so
/// the contain and free distributions (camera.cpp) keep their sequences.
class DistanceViewGenerator {
public:
    DistanceViewGenerator(const Bounds& object, const DistanceViews& range, std::uint64_t seed, float aspect)
        : object_(object),
          range_(range),
          state_(seed * 0x9E3779B97F4A7C15ull + 0xD1B54A32D192ED03ull),
          aspect_(aspect) {}

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
        throw Error("distance range: min " + std::to_string(d.min) +
                    " is not in 1..1000 (below 1 the object leaves the view)");
    if (!(d.max >= d.min && d.max <= 1000.0f))
        throw Error("distance range: max " + std::to_string(d.max) + " is not in min..1000");
}

/// Which ground truth judges a method's decisions: a sample inside the view volume (frustum
/// methods), or a sampled tangent plane facing the eye (back-patch methods; Loop, Niessner & Eisenacher).
enum class Truth { frustum, backface };

struct Method {
    std::string name;
    Truth truth;
    std::function<void(const PatchBatchView&, const float*, const CullView&, std::uint8_t*)> kernel;
};

/// The frustum kernels, then every registered back-patch method (backpatch_methods.h), then ptp
/// with the Pcnt rule as "ptp-pcnt".
const std::vector<Method>& methods() {
    static std::vector<Method> table;
    if (table.size() == 2 + backpatch_methods().size() + 1) return table;
    table = {
        {"frustum", Truth::frustum,
         [](const PatchBatchView& b, const float* d, const CullView& v, std::uint8_t* out) {
             cull_frustum(b, d, v, out);
         }},
        {"frustum-disp", Truth::frustum,
         [](const PatchBatchView& b, const float* d, const CullView& v, std::uint8_t* out) {
             cull_frustum_disp(b, d, v, out);
         }},
    };
    for (BackpatchMethod id : backpatch_method_ids())
        table.push_back({backpatch_method_name(id), Truth::backface,
                         [id](const PatchBatchView& b, const float*, const CullView& v, std::uint8_t* out) {
                             cull_backpatch(id, b, v, BackpatchOptions{}, out);
                         }});
    table.push_back(
        {"ptp-pcnt", Truth::backface, [](const PatchBatchView& b, const float*, const CullView& v, std::uint8_t* out) {
             cull_backpatch(BackpatchMethod::ptp, b, v, BackpatchOptions{PtpRule::pcnt}, out);
         }});
    return table;
}

const Method* find_method(const std::string& name) {
    for (const Method& m : methods())
        if (name == m.name) return &m;
    return nullptr;
}

/// Patches judged together: their samples (64 * 289 * 44 bytes, 0.8 MB, at grid 17) stay in a
/// core's cache while every view of a block is judged. A multiple of 16 (SIMD groups).
constexpr std::size_t kChunk = 64;

/// Views judged per pass over the patches. A pass samples each culled patch once, so more views
/// per pass spread that cost over more views; fewer report progress more often (on_view_done).
/// About 2^22 patch-views per block, 16 to 256 views: 16 for 262k patches and more, 256 below
/// 16k patches.
int views_per_block(std::size_t patches, int views) {
    const std::size_t target = std::size_t{1} << 22;
    const std::size_t by_work = patches > 0 ? target / patches : 256;
    return static_cast<int>(
        std::min<std::size_t>(std::clamp<std::size_t>(by_work, 16, 256), static_cast<std::size_t>(std::max(views, 1))));
}

/// One thread's scratch for judging chunks: the window of dense samples, the chunk's decisions
/// for one view and method, and counts per method.
struct ChunkJudge {
    PatchTruthWindow window;
    std::vector<std::uint8_t> decisions;
    std::vector<std::uint64_t> culled_count, false_count;

    ChunkJudge(int grid, const DisplacementMap* displacement, bool frustum, bool backface, std::size_t methods)
        : window(kChunk, grid, displacement, frustum, backface),
          decisions(kChunk),
          culled_count(methods),
          false_count(methods) {}

    void reset_counts() {
        std::fill(culled_count.begin(), culled_count.end(), 0);
        std::fill(false_count.begin(), false_count.end(), 0);
    }

    /// Runs every method of every view in block on patches [first, first + count) and judges
    /// each culled patch against its dense samples.
    void judge(const PatchFrame& frame, const PatchBatchView& batch, const float* disp,
               const std::vector<const Method*>& methods, const std::vector<CullView>& block, std::size_t first,
               std::size_t count) {
        window.clear();
        const PatchBatchView chunk = batch.subrange(first, count);
        for (const CullView& ctx : block)
            for (std::size_t m = 0; m < methods.size(); ++m) {
                methods[m]->kernel(chunk, disp ? disp + first : nullptr, ctx, decisions.data());
                const bool backface = methods[m]->truth == Truth::backface;
                for (std::size_t i = 0; i < count; ++i) {
                    if (!decisions[i]) continue;
                    ++culled_count[m];
                    const std::size_t p = first + i;
                    const PatchInfo& info = frame.info[p];
                    const PatchTruthInput input{&frame.patches[p],
                                                info.tangent_index >= 0 ? &frame.tangents[info.tangent_index] : nullptr,
                                                info.uv};
                    const bool visible = backface ? window.faces_eye(i, input, ctx.eye)
                                                  : window.in_clip_volume(i, input, ctx.object_to_clip);
                    false_count[m] += visible ? 1 : 0;
                }
            }
    }
};

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
        throw Error(
            "--displace: back-patch methods (tcone, ncone, ptp) do not bound displaced patches "
            "(Loop, Niessner & Eisenacher §8)");
    if (options.distance) check_distance_views(*options.distance);
    const int grid = options.ground_truth_grid;
    if (grid < 1 || grid > 1024) throw Error("ground truth grid " + std::to_string(grid) + " is not in 1..1024");
    const std::size_t n = frame.patches.size();
    if (frame.info.size() != n)
        throw Error("evaluate_cull: the frame has " + std::to_string(n) + " patches but " +
                    std::to_string(frame.info.size()) + " PatchInfo entries");
    const PatchBatch batch = make_batch(frame.patches);
    std::vector<float> max_disp(n);
    float largest = 0;
    {
        const std::vector<DisplacementRange> ranges = displacement_ranges(frame, displacement);
        for (std::size_t p = 0; p < n; ++p) {
            max_disp[p] = ranges[p].max_abs();
            largest = std::max(largest, max_disp[p]);
        }
    }
    const float* disp_ptr = largest > 0 ? max_disp.data() : nullptr;

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
    const std::size_t method_count = selected.size();
    std::vector<double> seconds(method_count, 0.0);
    std::vector<std::uint64_t> timed_culled(method_count), judged_culled(method_count), judged_false(method_count);
    std::vector<std::uint8_t> culled(n);
    tbb::enumerable_thread_specific<ChunkJudge> judges(
        [&] { return ChunkJudge(grid, displacement, needs_frustum_truth, needs_backface_truth, method_count); });
    const int block_views = views_per_block(n, options.views);
    std::vector<CullView> block;
    block.reserve(static_cast<std::size_t>(std::max(block_views, 0)));
    for (int done = 0; done < options.views;) {
        const int count = std::min(block_views, options.views - done);
        // The block's views, and the timed kernel passes: each method over the whole batch on
        // all cores, as an engine runs it (ns_per_patch), its culls counted.
        block.clear();
        std::fill(timed_culled.begin(), timed_culled.end(), 0);
        for (int k = 0; k < count; ++k) {
            const Camera camera = distance_views ? distance_views->next() : views.next();
            eye_distance_sum += length(camera.eye - centre) / radius;
            const CullView ctx = make_cull_view(camera.view(), camera.projection(), ClipDepth::zero_to_one, camera.eye);
            block.push_back(ctx);
            for (std::size_t m = 0; m < method_count; ++m) {
                const auto start = std::chrono::steady_clock::now();
                parallel_for_ranges(n, kGrain, [&](std::size_t first, std::size_t last) {
                    selected[m]->kernel(batch.view().subrange(first, last - first),
                                        disp_ptr ? disp_ptr + first : nullptr, ctx, culled.data() + first);
                });
                seconds[m] += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
                timed_culled[m] += static_cast<std::uint64_t>(
                    std::count_if(culled.begin(), culled.end(), [](std::uint8_t c) { return c != 0; }));
            }
        }
        // The judgement, chunk by chunk on all cores: a chunk's dense samples are made when one of
        // its patches is first culled in this block, judged against every view and method of the
        // block, and dropped with the chunk. The kernels run again on the chunk (they are pure:
        // a patch's decision does not depend on the range it is run in), so no decision array
        // outlives a view; the counts must match the timed passes'.
        for (ChunkJudge& j : judges) j.reset_counts();
        parallel_for_ranges(n, kChunk, [&](std::size_t first, std::size_t last) {
            ChunkJudge& judge = judges.local();
            for (std::size_t chunk = first; chunk < last; chunk += kChunk)
                judge.judge(frame, batch.view(), disp_ptr, selected, block, chunk, std::min(kChunk, last - chunk));
        });
        std::fill(judged_culled.begin(), judged_culled.end(), 0);
        std::fill(judged_false.begin(), judged_false.end(), 0);
        for (const ChunkJudge& j : judges)
            for (std::size_t m = 0; m < method_count; ++m) {
                judged_culled[m] += j.culled_count[m];
                judged_false[m] += j.false_count[m];
            }
        for (std::size_t m = 0; m < method_count; ++m) {
            if (judged_culled[m] != timed_culled[m])
                throw Error(std::string("cull evaluation: ") + selected[m]->name + " culled " +
                            std::to_string(timed_culled[m]) + " patch-views in the timed pass but " +
                            std::to_string(judged_culled[m]) +
                            " when judged chunk by chunk (a kernel whose "
                            "decisions depend on the range it runs in)");
            result.methods[m].culled += judged_culled[m];
            result.methods[m].false_culls += judged_false[m];
        }
        done += count;
        if (options.on_view_done) options.on_view_done(done);
    }
    const double pairs = static_cast<double>(n) * std::max(1, options.views);
    result.mean_eye_distance_radii = options.views > 0 ? eye_distance_sum / options.views : 0.0;
    for (std::size_t m = 0; m < method_count; ++m) {
        CullMethodResult& r = result.methods[m];
        r.name = selected[m]->name;
        r.cull_rate = options.views > 0 ? r.culled / pairs : 0.0;
        r.ns_per_patch = options.views > 0 ? seconds[m] * 1e9 / pairs : 0.0;
    }
    return result;
}

}  // namespace patchcull
