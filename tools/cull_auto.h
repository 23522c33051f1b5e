// `--cull auto` (render, view, the main job's `auto` row): the per-object switch of Niessner &
// Loop, "Patch-Based Occlusion Culling for Hardware Tessellation", §6.3 ("Payoff",
// "Adaptive tessellation"): culling an object pays when its cull rate exceeds the break-even rate
//   x = (RT0 + CT) / (RT - RT0)
// RT: render time of the object unculled; RT0: its render time with every patch culled (patches
// still issued, the TCS gives them level 0: the second pass's cost); CT: the cull passes' time.
// Per patch, x = (issue + cull) / tess with
//   issue = RT0 per patch, cull = CT per culled patch, tess = (RT - RT0) per drawn patch,
// so x does not depend on the object's size, only on its tessellation factor (through tess).
//
// Contract of CullAutoPolicy (one per patch set and run; no GL, so it is unit-tested alone):
//   for every frame:  decide(tess factors)  ->  render with objects() and frame_cull_mode()  ->
//   observe(the frame's gl::FrameStats).
// It never affects conservativeness: an object it turns off is drawn whole (ObjectRange::cull =
// false), an object it turns on gets the ordinary conservative tests. It only decides where the
// cull passes run.
//
// Inputs of a decision (all measured on this machine, in this run):
//  (a) the per-patch costs, running estimates (a mean over the first frames, then exponential
//      averages of weight Config::cost_weight) from the pipeline's own pass times (FrameStats;
//      wall clock around glFinish on llvmpipe):
//      - two-pass frame: pass1_ms = issue * N + tess * pass1_drawn (+ clear and occluders),
//        pass2_ms = issue * N + tess * pass2_drawn (every patch is issued in both passes, N = all
//        patches), so tess = (pass1 - pass2) / (pass1_drawn - pass2_drawn) (used when the two
//        draws differ by at least N/10 patches) and issue = (pass2 - tess * pass2_drawn) / N;
//        cull = (cull_ms - status * N) / (patches of culled objects); hiz = hiz_ms.
//      - one-pass frame (no object culled: the frame runs as --cull none): status = cull_ms / N
//        (the status passes run on every frame, culled or not, so they are not part of CT), and,
//        once issue is known, tess = (pass1_ms - issue * N) / pass1_drawn.
//      The clear and occluder draw of pass 1 (a fraction of a ms at 640x360 on llvmpipe) are
//      counted in tess, which makes culling look slightly cheaper than it is. The times of the
//      first frame of each kind (one-pass, two-pass) are ignored: they include the compilation of
//      the pass programs. Frames timed with TimingMethod::off leave the costs alone.
//  (b) the object's cull rate (frustum + back-patch + occlusion culled / its patches), an
//      exponential average (Config::rate_weight) over the frames it was culled in; a probe's
//      measurement replaces the average (the old one is stale). An object switched off because its
//      rate is below x is probed (culled for one frame, which measures its rate) once it has been
//      off for its probe interval (Config::probe_interval, doubled by every probe that finds the
//      rate still below break-even, up to Config::max_probe_interval, and reset by one that finds
//      it above: a steady object that does not pay costs a two-pass frame ever more rarely); when
//      any object is probed, every object off for at least half its own interval is probed in the
//      same frame, so probes share their two-pass frames.
//  (c) the tessellation factor t at the object's centroid (mean of its patches' corner points):
//      uniform tessellation: the level; adaptive: clamp(level * reference / distance(eye,
//      centroid), 1, level), as the TCS computes an edge's level (object_tess_factors). The
//      tessellated cost of a patch is modelled as tess(t) = tess_unit * (c0 + t^2) (t^2: the
//      triangles; c0 = Config::tess_cost_offset: the per-patch part that does not grow with t),
//      tess_unit measured from the frames' drawn patches weighted by their objects' (c0 + t^2).
//      With uniform tessellation every object has the frame's t, so c0 cancels out. When x >= 1
//      at the object's t, no cull rate can pay (Niessner & Loop: a model small on screen, or at a low
//      tess factor, is not culled): off, probed only every 4 * Config::probe_interval frames, which
//      refreshes the issue and cull costs (measured in two-pass frames only; tess is also measured
//      in the one-pass frames).
// Frame rule (beyond the seed's per-object rule): the pipeline's second pass issues every patch of
// the set, and the Hi-Z build runs once, as soon as one object is culled; a frame with no object
// culled runs as --cull none (one pass, no Hi-Z). So when no object is probed, the objects whose
// rate exceeds x are culled only if their predicted saving, sum of n * (rate * tess - issue -
// cull), exceeds the Hi-Z build plus the issue cost of the other objects' patches in pass 2;
// otherwise none is.
// Until the costs are measured (Config::cost_frames two-pass frames after the first), every object
// is culled ("probe").
// Limits: issue, cull and tess_unit are averages over all patches of the set. A displaced object's
// patches cost more to cull (DisplacedPass's bound against the frustum and the Hi-Z) and to draw
// (the TES samples the map) than an undisplaced one's; FrameStats times whole passes, not objects,
// so the policy does not tell them apart.
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"

namespace patchcull::cli {

class CullAutoPolicy {
public:
    struct Config {
        /// Frames an object switched off (rate below break-even) waits before it is probed (>= 1).
        /// Each probe that finds the rate still below break-even doubles the object's wait, up to
        /// max_probe_interval; a probe that finds it above resets the wait to probe_interval.
        int probe_interval = 8;
        int max_probe_interval = 64;
        /// Weight of the newest frame in the cull-rate average, in (0, 1].
        double rate_weight = 0.5;
        /// Weight of the newest frame in the cost averages, in (0, 1].
        double cost_weight = 0.25;
        /// c0 of tess(t) = tess_unit * (c0 + t^2), >= 0 (only matters when the objects' factors differ;
        /// 4: none's per-patch time on llvmpipe at levels 1-8, docs/PERFORMANCE.md).
        double tess_cost_offset = 4;
        /// Two-pass frames whose times are averaged before the costs are used (>= 1; the first
        /// two-pass frame, compilation, is not one of them).
        int cost_frames = 2;
    };
    static constexpr double kUnknown = std::numeric_limits<double>::quiet_NaN();

    /// Running per-patch cost estimates in milliseconds; NaN = not measured yet.
    struct Costs {
        double issue_ms = kUnknown;      ///< RT0 per patch (issued, level 0), one pass
        double cull_ms = kUnknown;       ///< CT per patch of a culled object
        double tess_unit_ms = kUnknown;  ///< (RT - RT0) per drawn patch, per unit of (c0 + t^2)
        double hiz_ms = kUnknown;        ///< the Hi-Z build, per two-pass frame
        double status_ms = 0;            ///< the status passes per patch (every frame; 0 until a one-pass frame)
        bool known() const;              ///< issue, cull, tess_unit and hiz are all measured
    };

    /// One object's decision for a frame.
    struct Decision {
        bool cull = true;
        bool probe = false;               ///< culled to measure its rate (or the costs)
        double tess_factor = 0;           ///< t at its centroid
        double break_even = kUnknown;     ///< x at t (NaN until the costs are measured; +inf when tess(t) <= 0)
        double cull_rate = kUnknown;      ///< the average used (NaN until measured)
        std::string reason;               ///< "rate 0.41 > break-even 0.18", "probe: ...", ...
    };

    /// objects: disjoint ranges of a set of patch_count patches (their cull fields are ignored).
    /// Throws patchcull::Error when a range leaves the set or the config is out of range.
    CullAutoPolicy(std::vector<gl::ObjectRange> objects, std::size_t patch_count, Config config);
    CullAutoPolicy(std::vector<gl::ObjectRange> objects, std::size_t patch_count)
        : CullAutoPolicy(std::move(objects), patch_count, Config{}) {}

    /// Decides the next frame, given each object's tessellation factor (object_tess_factors).
    /// Throws std::logic_error when the previous decision was not observed or the sizes differ.
    const std::vector<Decision>& decide(const std::vector<double>& tess_factors);
    /// The last decision as PipelineParams::objects.
    std::vector<gl::ObjectRange> objects() const;
    std::size_t culled_objects() const;  ///< of the last decision
    /// The cull mode of the frame: `tests` (the mode of the culled objects, e.g. applicable_cull_mode
    /// of all) when an object is culled, none otherwise (one pass, no Hi-Z; see the header).
    gl::CullMode frame_cull_mode(gl::CullMode tests) const;
    /// Takes the frame rendered with the last decision (stats.objects in the objects' order).
    /// Throws std::logic_error when there was no decision or the object count differs.
    void observe(const gl::FrameStats& stats);

    const std::vector<Decision>& decisions() const { return decisions_; }
    const Costs& costs() const { return costs_; }
    /// Replaces the cost estimates (tests, or costs known from an earlier run); they are used at
    /// once when known() (no Config::cost_frames wait).
    void set_costs(const Costs& costs) {
        costs_ = costs;
        cost_samples_ = config_.cost_frames;
    }
    /// The costs are used: known() and averaged over Config::cost_frames two-pass frames (or set).
    bool costs_ready() const { return costs_.known() && cost_samples_ >= config_.cost_frames; }
    /// tess(t) of the current estimates (NaN while unknown).
    double tess_cost_ms(double tess_factor) const;
    /// The break-even rate x at tessellation factor t (NaN while the costs are not known()).
    double break_even(double tess_factor) const;
    const Config& config() const { return config_; }

private:
    struct ObjectState {
        gl::ObjectRange range;
        double rate = kUnknown;
        long last_culled = -1;  ///< frame index of the last frame it was culled, -1 never
        long wait = 0;          ///< its current probe interval (0: Config::probe_interval)
    };
    Config config_;
    std::size_t patch_count_;
    std::vector<ObjectState> objects_;
    std::vector<Decision> decisions_;
    std::vector<double> factors_;
    Costs costs_;
    long frame_ = 0;
    int cost_samples_ = 0;  ///< two-pass frames measured
    bool pending_ = false;
    bool seen_one_pass_ = false, seen_two_pass_ = false, status_measured_ = false;
};

/// One line for a frame: "auto: culling K of N objects: NAME on (REASON); NAME off (REASON); ...".
std::string auto_summary_line(const std::vector<std::string>& names,
                              const std::vector<CullAutoPolicy::Decision>& decisions);

/// The tessellation factor at each object's centroid (the mean of its patches' four corner
/// points): tess_level, or with adaptive tessellation clamp(tess_level * reference / |centroid -
/// eye|, 1, tess_level) as the TCS computes an edge's level (gl::RenderParams::adaptive_tess).
std::vector<double> object_tess_factors(const std::vector<BezierPatch>& patches,
                                        const std::vector<gl::ObjectRange>& objects, Vec3 eye, int tess_level,
                                        bool adaptive, float reference_distance);

/// The factors for a frame's render parameters (eye from the view matrix).
std::vector<double> object_tess_factors(const std::vector<BezierPatch>& patches,
                                        const std::vector<gl::ObjectRange>& objects, const gl::RenderParams& params);

}  // namespace patchcull::cli
