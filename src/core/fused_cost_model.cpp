// The fused kernel's cost model (patchcull/core/fused_cost_model.h).
#include "patchcull/core/fused_cost_model.h"

#include <algorithm>

namespace patchcull {
namespace {

unsigned stage_bit(FusedStage s) { return 1u << static_cast<unsigned>(s); }

double blend(double old_value, double new_value, double weight) { return old_value + weight * (new_value - old_value); }

}  // namespace

FusedCostModel::FusedCostModel(std::size_t objects) : FusedCostModel(objects, Config{}) {}

FusedCostModel::FusedCostModel(std::size_t objects, const Config& config) : config_(config), objects_(objects) {
    config_.profile_interval = std::max(1, config_.profile_interval);
}

bool FusedCostModel::should_profile(std::size_t object, unsigned available) const {
    const ObjectState& o = objects_[object];
    if (o.profiled_stages != available) return true;  // never profiled, or its stages changed
    // Staggered: object i is due when (frame + i) is a multiple of the interval, at least one
    // interval after its last run.
    const long long interval = config_.profile_interval;
    return frame_ - o.last_profile >= interval && (frame_ + static_cast<long long>(object)) % interval == 0;
}

double FusedCostModel::expected_seconds(std::size_t object, const FusedPlan& plan, double groups,
                                        double patches) const {
    const ObjectState& o = objects_[object];
    double per_group = 0;
    unsigned prefix = 0;
    for (int i = 0; i < plan.count; ++i) {
        per_group += stage_seconds_[static_cast<int>(plan.stages[i])] * (1.0 - (prefix ? o.decided[prefix] : 0.0));
        prefix |= stage_bit(plan.stages[i]);
    }
    double total = groups * per_group;
    if (config_.draw_seconds_per_patch != std::numeric_limits<double>::infinity()) {
        // Patches a left-out test would have culled are drawn: they cost the draw.
        const unsigned everything = o.profiled_stages ? o.profiled_stages : prefix;
        const double lost = std::max(0.0, o.culled[everything] - o.culled[prefix]);
        total += patches * lost * config_.draw_seconds_per_patch;
    }
    return total;
}

FusedPlan FusedCostModel::choose(std::size_t object, unsigned available) const {
    available &= kAllFusedStages;
    const bool may_drop = config_.draw_seconds_per_patch != std::numeric_limits<double>::infinity();
    FusedPlan best;
    double best_time = std::numeric_limits<double>::infinity();
    bool found = false;
    for (unsigned subset = available; subset != 0; subset = (subset - 1) & available) {
        if (!may_drop && subset != available) continue;
        FusedPlan plans[6];
        const int n = fused_plans_of(subset, plans);
        for (int i = 0; i < n; ++i) {
            // Per group and per patch in the same units: one group of 16 patches as the unit.
            const double t = expected_seconds(object, plans[i], 1.0, 16.0);
            if (!found || t < best_time) {
                best = plans[i];
                best_time = t;
                found = true;
            }
        }
    }
    if (!found) {
        // Only occlusion available: it needs the frustum stage's clip coordinates.
        best.stages[0] = FusedStage::frustum;
        best.stages[1] = FusedStage::occlusion;
        best.count = 2;
    }
    return best;
}

void FusedCostModel::observe(std::size_t object, const FusedPlan& plan, const FusedCullStats& stats) {
    if (stats.groups == 0) return;
    ObjectState& o = objects_[object];
    unsigned prefix = 0;
    for (int i = 0; i + 1 < plan.count; ++i) {
        prefix |= stage_bit(plan.stages[i]);
        const double decided =
            1.0 - static_cast<double>(stats.groups_entered[i + 1]) / static_cast<double>(stats.groups);
        o.decided[prefix] = blend(o.decided[prefix], decided, config_.rate_weight);
    }
}

void FusedCostModel::observe_profile(std::size_t object, unsigned available, const FusedProfile& profile,
                                     std::size_t patches) {
    ObjectState& o = objects_[object];
    const bool first = o.profiled_stages != available;
    if (profile.groups > 0) {
        for (unsigned s = 1; s < (1u << kFusedStages); ++s) {
            if ((s & ~available) != 0) continue;
            const double decided = static_cast<double>(profile.decided[s]) / static_cast<double>(profile.groups);
            const double culled =
                patches ? static_cast<double>(profile.patches_culled_by[s]) / static_cast<double>(patches) : 0.0;
            o.decided[s] = first ? decided : blend(o.decided[s], decided, config_.rate_weight);
            o.culled[s] = first ? culled : blend(o.culled[s], culled, config_.rate_weight);
        }
        for (int st = 0; st < kFusedStages; ++st) {
            if ((available & (1u << st)) == 0 || profile.ticks[st] == 0) continue;
            const double seconds = profile.seconds_per_group(static_cast<FusedStage>(st));
            // A run of few groups is a noisy measurement: it moves the average less.
            const double weight = config_.cost_weight * std::min(1.0, static_cast<double>(profile.groups) / 64.0);
            stage_seconds_[st] = stage_measured_[st] ? blend(stage_seconds_[st], seconds, weight) : seconds;
            stage_measured_[st] = true;
        }
    }
    o.profiled_stages = available;
    o.last_profile = frame_;
}

}  // namespace patchcull
