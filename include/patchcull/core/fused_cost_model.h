// patchcull/core/fused_cost_model.h: chooses, per object and frame, which plan the fused cull kernel
// (fused_cull.h) runs: which of its tests, in what order.
//
// The expected time of a plan s_1 .. s_k on one group of patches is
//   T = c(s_1) + (1 - P{s_1}) * (c(s_2) + (1 - P{s_1,s_2} | ...) ...)
//     = sum_i c(s_i) * (1 - P(S_{i-1})),   S_i = {s_1 .. s_i}, P(S_0) = 0,
// where c(s) is stage s's measured cost per group and P(S) the fraction of the object's groups
// that the stages of S together decide (every patch of the group culled by one of them): the
// group leaves the kernel there. This is the expected-time rule T(A) = t_C + (1 - P(A)) R(A) that
// G. Zachmann's lecture "Advanced Visibility Computations" gives for clustered back-face culling
// (t_C the test's time, P(A) the probability that it culls cluster A, R(A) the time of what
// follows; the lecture uses it to decide whether merging two clusters pays), applied recursively
// with R the rest of the plan. When the caller gives a cost per
// surviving patch (draw_seconds_per_patch, finite), plans that leave tests out are candidates too
// and pay draw_seconds_per_patch for every patch that a left-out test would have culled:
// T_total = groups * T + survivors * draw_seconds_per_patch. By default it is infinite: every
// available test always runs, and only the order is chosen (the decisions, and so what is drawn,
// are then the same whatever the choice).
//
// Where the numbers come from (measured in the caller's run, nothing assumed):
// - P(S) for every subset S: a profiling run of the object (cull_fused_profile_simd: every stage on
//   every group, no early exit) counts the groups each subset decides. Between profiling runs,
//   every ordinary run refreshes P of its own plan's prefixes from the groups that entered each
//   stage (FusedCullStats). Objects are profiled on their first frame and then every
//   Config::profile_interval frames (staggered by object index), or when their stages change.
// - c(s): exponential averages over all profiling runs of the seconds per group of each stage
//   (FusedProfile::seconds_per_group), shared by all objects: a stage costs the same per group
//   whatever the object (the Hi-Z stage's texel loads vary a little with the rectangles).
//   Until a stage has been measured, it is given kUnmeasuredStageSeconds.
// Estimates change only through observe*(); choose() is a pure function of them.
//
// Contract: objects are indices 0 .. objects-1 fixed at construction; stages are bit masks over
// FusedStage (bit 1 << stage); choose() returns a valid plan over a non-empty subset of the
// available stages (all of them with an infinite draw cost), never allocates.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "patchcull/core/fused_cull.h"

namespace patchcull {

inline constexpr unsigned kAllFusedStages = 7u;  ///< frustum | backpatch | occlusion

class FusedCostModel {
public:
    struct Config {
        int profile_interval = 16;  ///< frames between an object's profiling runs (>= 1)
        double rate_weight = 0.5;   ///< weight of a new observation of P(S) (exponential average)
        double cost_weight = 0.25;  ///< weight of a new profiling run's stage costs
        double draw_seconds_per_patch = std::numeric_limits<double>::infinity();
    };
    static constexpr double kUnmeasuredStageSeconds = 1e-7;

    explicit FusedCostModel(std::size_t objects);
    FusedCostModel(std::size_t objects, const Config& config);

    /// The plan for object this frame over the available stages (a bit mask; displaced objects
    /// leave out backpatch, frames without a pyramid leave out occlusion). Never empty when
    /// available is not 0.
    FusedPlan choose(std::size_t object, unsigned available) const;
    /// Whether this frame's run of object should be the profiling variant.
    bool should_profile(std::size_t object, unsigned available) const;
    /// Expected seconds for the object's `groups` groups and `patches` patches under plan.
    double expected_seconds(std::size_t object, const FusedPlan& plan, double groups, double patches) const;

    /// After an ordinary run of plan on object.
    void observe(std::size_t object, const FusedPlan& plan, const FusedCullStats& stats);
    /// After a profiling run of plan (all of `available`'s stages) on object, of `patches` patches.
    void observe_profile(std::size_t object, unsigned available, const FusedProfile& profile, std::size_t patches);
    /// Advances the frame counter (profiling schedule).
    void next_frame() { ++frame_; }

    /// Current estimates, for reports and tests.
    double stage_seconds(FusedStage s) const { return stage_seconds_[static_cast<int>(s)]; }
    double decided_fraction(std::size_t object, unsigned subset) const { return objects_[object].decided[subset]; }
    double culled_fraction(std::size_t object, unsigned subset) const { return objects_[object].culled[subset]; }

private:
    struct ObjectState {
        double decided[1u << kFusedStages] = {};  ///< P(S): fraction of groups decided by S
        double culled[1u << kFusedStages] = {};   ///< fraction of patches culled by some stage of S
        unsigned profiled_stages = 0;             ///< the stages of the last profiling run (0: never)
        long long last_profile = 0;
    };
    Config config_;
    std::vector<ObjectState> objects_;
    double stage_seconds_[kFusedStages] = {kUnmeasuredStageSeconds, kUnmeasuredStageSeconds, kUnmeasuredStageSeconds};
    bool stage_measured_[kFusedStages] = {};
    long long frame_ = 0;
};

}  // namespace patchcull
