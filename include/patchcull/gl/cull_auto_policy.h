// patchcull/gl/cull_auto_policy.h: CullAutoPolicy, the per-object culling switch of Niessner &
// Loop, "Patch-Based Occlusion Culling for Hardware Tessellation", §6.3: culling an object pays
// when its cull rate exceeds the break-even rate x = (RT0 + CT) / (RT - RT0) (RT: its render time
// unculled; RT0: with every patch culled; CT: the cull passes' time). The policy estimates these
// per patch from the pipeline's own pass times (FrameStats, gl_pipeline.h) and decides, frame by
// frame, which objects the cull passes run on. Behind the CLI's `--cull auto`. RT0 depends on the
// draw mode (FrameStats::draw): DrawMode::flags issues a culled patch at level 0 (RT0 > 0);
// DrawMode::indirect does not issue it (RT0 = 0), and charges a fixed cost per draw pass instead.
//
// Contract (one policy per patch set and run):
//   for every frame:  decide(tess factors)  ->  render with objects() and frame_cull_mode()  ->
//   observe(the frame's FrameStats).
// - It never affects conservativeness: an object it turns off is drawn whole (ObjectRange::cull =
//   false), an object it turns on gets the ordinary conservative tests. It only decides where the
//   cull passes run.
// - Bootstrap: until Config::cost_frames two-pass frames after the first are measured, every
//   object is culled ("probe"); then Config::measure_frames frames cull nothing ("measure": one
//   pass each, from which the draw cost per patch, RT - RT0, is taken, the smallest of them; the
//   two-pass frames' estimate includes pass 1's fixed costs). Then an object is culled while its cull rate exceeds x at
//   its tessellation factor, provided the frame's predicted saving exceeds the Hi-Z build plus pass 2's cost beyond the
//   culled objects (flags: the other objects' issue; indirect: the pass's fixed cost); an object
//   switched off is probed (culled for one frame) after its probe interval (Config). A frame with
//   no object culled runs as CullMode::none (one pass, no Hi-Z). An object whose cull cost per
//   patch exceeds its draw cost (x >= 1) is never culled for its rate, even a rate of 1.
// - How the costs, rates and tessellation factors are estimated, the frame rule and the limits:
//   docs/METHODS.md, "Culling only where it pays".
// No GL of its own (it reads FrameStats and decides), so it is unit-tested without a context; use
// one policy from one thread. The constructor throws patchcull::Error on a bad range or config;
// decide and observe throw std::logic_error when called out of that order or with wrong sizes.
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "patchcull/core/math.h"
#include "patchcull/core/patch.h"
#include "patchcull/gl/gl_pipeline.h"

namespace patchcull::gl {

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
        /// One-pass frames that cull nothing after them, to measure the draw cost per patch (>= 1).
        /// The smallest of their values is kept: a frame the machine slowed down can only
        /// overstate the cost, and an overstated draw cost lowers x (culls where it does not pay).
        int measure_frames = 2;
    };
    static constexpr double kUnknown = std::numeric_limits<double>::quiet_NaN();

    /// Running per-patch cost estimates in milliseconds; NaN = not measured yet.
    struct Costs {
        double issue_ms = kUnknown;      ///< RT0 per patch, one pass (flags: issued, level 0; indirect: 0)
        double cull_ms = kUnknown;       ///< CT per patch of a culled object
        double tess_unit_ms = kUnknown;  ///< (RT - RT0) per drawn patch, per unit of (c0 + t^2)
        double hiz_ms = kUnknown;        ///< the Hi-Z build, per two-pass frame
        double status_ms = 0;            ///< the status passes per patch (every frame; 0 until a one-pass frame)
        /// DrawMode::indirect (of the frames observed): pass 2's fixed cost per two-pass frame
        /// (compaction, draw call, finish: pass2_ms less its submitted patches' draw cost), charged
        /// by the frame rule instead of the other objects' issue. 0 with flags (part of issue_ms).
        double pass_ms = 0;
        bool indirect = false;
        bool known() const;  ///< issue, cull, tess_unit and hiz are all measured
    };

    /// One object's decision for a frame.
    struct Decision {
        bool cull = true;
        bool probe = false;            ///< culled to measure its rate (or the costs)
        double tess_factor = 0;        ///< t at its centroid
        double break_even = kUnknown;  ///< x at t (NaN until the costs are measured; +inf when tess(t) <= 0)
        double cull_rate = kUnknown;   ///< the average used (NaN until measured)
        std::string reason;            ///< "rate 0.41 > break-even 0.18", "probe: ...", ...
    };

    /// objects: disjoint ranges of a set of patch_count patches (their cull fields are ignored).
    /// Throws patchcull::Error when a range leaves the set or the config is out of range.
    CullAutoPolicy(const std::vector<ObjectRange>& objects, std::size_t patch_count, Config config);
    CullAutoPolicy(const std::vector<ObjectRange>& objects, std::size_t patch_count)
        : CullAutoPolicy(objects, patch_count, Config{}) {}

    /// Decides the next frame, given each object's tessellation factor (object_tess_factors).
    /// Throws std::logic_error when the previous decision was not observed or the sizes differ.
    const std::vector<Decision>& decide(const std::vector<double>& tess_factors);
    /// The last decision as PipelineParams::objects.
    std::vector<ObjectRange> objects() const;
    std::size_t culled_objects() const;  ///< of the last decision
    /// The last decision culls an object after a frame that culled none (drawn unculled, every patch
    /// tagged visible): the caller lets the frame start from no visible patch
    /// (CullPipeline::forget_visibility), or its pass 1 would draw every patch.
    bool resumes_culling() const { return resumes_culling_; }
    /// The cull mode of the frame: `tests` (the mode of the culled objects, e.g. applicable_cull_mode
    /// of all) when an object is culled, none otherwise (one pass, no Hi-Z; see the header).
    CullMode frame_cull_mode(CullMode tests) const;
    /// Takes the frame rendered with the last decision (stats.objects in the objects' order).
    /// Throws std::logic_error when there was no decision or the object count differs.
    void observe(const FrameStats& stats);

    const std::vector<Decision>& decisions() const { return decisions_; }
    const Costs& costs() const { return costs_; }
    /// Replaces the cost estimates (tests, or costs known from an earlier run); they are used at
    /// once when known() (no Config::cost_frames wait, no measure frame). Timed frames update
    /// them as after the bootstrap (tess only from one-pass frames).
    void set_costs(const Costs& costs) {
        costs_ = costs;
        cost_samples_ = config_.cost_frames;
        tess_samples_ = config_.measure_frames;
        pass_measured_ = true;
    }
    /// The costs are used: known(), averaged over Config::cost_frames two-pass frames, and the draw
    /// cost taken from Config::measure_frames one-pass frames (or set).
    bool costs_ready() const {
        return costs_.known() && cost_samples_ >= config_.cost_frames && tess_samples_ >= config_.measure_frames;
    }
    /// tess(t) of the current estimates (NaN while unknown).
    double tess_cost_ms(double tess_factor) const;
    /// The break-even rate x at tessellation factor t (NaN while the costs are not known()).
    double break_even(double tess_factor) const;
    const Config& config() const { return config_; }

private:
    struct ObjectState {
        ObjectRange range;
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
    bool previous_culled_ = true;  ///< the frame before the last decision culled an object
    bool resumes_culling_ = false;
    bool seen_one_pass_ = false, seen_two_pass_ = false, status_measured_ = false;
    int tess_samples_ = 0;        ///< one-pass frames that measured tess_unit (the two-pass value is provisional)
    bool pass_measured_ = false;  ///< Costs::pass_ms measured
};

/// One line for a frame: "auto: culling K of N objects: NAME on (REASON); NAME off (REASON); ...".
std::string auto_summary_line(const std::vector<std::string>& names,
                              const std::vector<CullAutoPolicy::Decision>& decisions);

/// The tessellation factor at each object's centroid (the mean of its patches' four corner
/// points): tess_level, or with adaptive tessellation clamp(tess_level * reference / |centroid -
/// eye|, 1, tess_level) as the TCS computes an edge's level (RenderParams::adaptive_tess).
std::vector<double> object_tess_factors(const std::vector<BezierPatch>& patches,
                                        const std::vector<ObjectRange>& objects, Vec3 eye, int tess_level,
                                        bool adaptive, float reference_distance);

/// The factors for a frame's render parameters (eye from the view matrix).
std::vector<double> object_tess_factors(const std::vector<BezierPatch>& patches,
                                        const std::vector<ObjectRange>& objects, const RenderParams& params);

}  // namespace patchcull::gl
