// CullAutoPolicy: the per-object culling switch of Niessner & Loop §6.3
// (patchcull/gl/cull_auto_policy.h; its estimates: docs/METHODS.md, "Culling only where it pays").
#include "patchcull/gl/cull_auto_policy.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "patchcull/core/error.h"

namespace patchcull::gl {
namespace {

double average(double old_value, double new_value, double weight) {
    return std::isnan(old_value) ? new_value : weight * new_value + (1 - weight) * old_value;
}

std::string format(const char* pattern, double a) {
    char text[160];
    std::snprintf(text, sizeof text, pattern, a);
    return text;
}

std::string format(const char* pattern, double a, double b) {
    char text[160];
    std::snprintf(text, sizeof text, pattern, a, b);
    return text;
}

}  // namespace

bool CullAutoPolicy::Costs::known() const {
    return !std::isnan(issue_ms) && !std::isnan(cull_ms) && !std::isnan(tess_unit_ms) && !std::isnan(hiz_ms);
}

CullAutoPolicy::CullAutoPolicy(const std::vector<ObjectRange>& objects, std::size_t patch_count, Config config)
    : config_(config), patch_count_(patch_count) {
    if (config.probe_interval < 1) throw Error("cull auto: probe_interval must be >= 1");
    if (config.max_probe_interval < config.probe_interval)
        throw Error("cull auto: max_probe_interval must be >= probe_interval");
    if (!(config.rate_weight > 0 && config.rate_weight <= 1) || !(config.cost_weight > 0 && config.cost_weight <= 1))
        throw Error("cull auto: the average weights must be in (0, 1]");
    if (!(config.tess_cost_offset >= 0)) throw Error("cull auto: tess_cost_offset must be >= 0");
    if (config.cost_frames < 1) throw Error("cull auto: cost_frames must be >= 1");
    if (config.measure_frames < 1) throw Error("cull auto: measure_frames must be >= 1");
    for (const ObjectRange& o : objects) {
        if (o.first > patch_count || o.count > patch_count - o.first)
            throw Error("cull auto: an object leaves the set of " + std::to_string(patch_count) + " patches");
        ObjectState s;
        s.range = o;
        s.range.cull = true;
        objects_.push_back(s);
    }
}

double CullAutoPolicy::tess_cost_ms(double tess_factor) const {
    return costs_.tess_unit_ms * (config_.tess_cost_offset + tess_factor * tess_factor);
}

double CullAutoPolicy::break_even(double tess_factor) const {
    if (!costs_.known()) return kUnknown;
    const double tess = tess_cost_ms(tess_factor);
    if (!(tess > 0)) return std::numeric_limits<double>::infinity();
    return (costs_.issue_ms + costs_.cull_ms) / tess;
}

const std::vector<CullAutoPolicy::Decision>& CullAutoPolicy::decide(const std::vector<double>& tess_factors) {
    if (pending_) throw std::logic_error("CullAutoPolicy::decide: the previous decision was not observed");
    if (tess_factors.size() != objects_.size())
        throw std::logic_error("CullAutoPolicy::decide: one tessellation factor per object expected");
    const bool known = costs_ready();
    // The bootstrap's last frames: the two-pass costs are measured, the draw cost per patch is not
    // (it comes from one-pass frames, docs/METHODS.md): nothing is culled.
    // tess_unit may still be unknown there: when the two-pass frames drew too few patches to
    // estimate it (a scene almost wholly culled), the measuring frames give it.
    const bool measure = !known && !std::isnan(costs_.issue_ms) && !std::isnan(costs_.cull_ms) &&
                         !std::isnan(costs_.hiz_ms) && cost_samples_ >= config_.cost_frames &&
                         tess_samples_ < config_.measure_frames;
    decisions_.assign(objects_.size(), Decision{});
    bool any_probe = false;
    for (std::size_t i = 0; i < objects_.size(); ++i) {
        const ObjectState& o = objects_[i];
        Decision& d = decisions_[i];
        d.tess_factor = tess_factors[i];
        d.cull_rate = o.rate;
        if (measure) {
            d.cull = false;
            d.reason = "measure: one unculled pass (the draw cost per patch)";
        } else if (!known) {
            d.cull = d.probe = true;
            d.reason = "probe: costs not measured yet";
        } else {
            d.break_even = break_even(d.tess_factor);
            const long since = frame_ - o.last_culled;
            const long wait = o.wait > 0 ? o.wait : config_.probe_interval;
            if (!(d.break_even < 1)) {
                // No rate can pay (Niessner & Loop §6.3: low tess factor, no culling). Probed only rarely:
                // the issue and cull costs are measured in two-pass frames alone.
                d.reason = std::isinf(d.break_even)
                               ? format("tess factor %.1f: no measured tessellation cost to save", d.tess_factor)
                               : format("tess factor %.1f: break-even %.2f >= 1, culling cannot pay", d.tess_factor,
                                        d.break_even);
                d.cull = d.probe = since >= 4L * wait;
                if (d.probe) d.reason = "probe (costs): " + d.reason;
            } else if (std::isnan(o.rate)) {
                d.cull = d.probe = true;
                d.reason = "probe: no cull rate yet";
            } else if (o.rate > d.break_even) {
                d.cull = true;
                d.reason = format("rate %.2f > break-even %.2f", o.rate, d.break_even);
            } else if (since >= wait) {
                d.cull = d.probe = true;
                d.reason = format("probe: rate %.2f <= break-even %.2f", o.rate, d.break_even) + ", measured " +
                           std::to_string(since) + " frames ago";
            } else {
                d.cull = false;
                d.reason = format("rate %.2f <= break-even %.2f", o.rate, d.break_even);
            }
        }
        any_probe = any_probe || d.probe;
    }
    if (known && any_probe) {
        // The probe makes this a two-pass frame anyway: the objects off for half their interval come along.
        for (std::size_t i = 0; i < objects_.size(); ++i) {
            Decision& d = decisions_[i];
            const long wait = objects_[i].wait > 0 ? objects_[i].wait : config_.probe_interval;
            const long half = std::max(1L, wait / 2);
            const long since = frame_ - objects_[i].last_culled;
            if (d.cull || !(d.break_even < 1) || std::isnan(objects_[i].rate) || since < half) continue;
            d.cull = d.probe = true;
            d.reason = format("probe (with another): rate %.2f <= break-even %.2f", objects_[i].rate, d.break_even) +
                       ", measured " + std::to_string(since) + " frames ago";
        }
    } else if (known) {
        // The frame rule (docs/METHODS.md): culling anything costs the Hi-Z build and pass 2: with
        // DrawMode::flags its issue of every other patch, with indirect its fixed cost (the culled
        // objects' patches are not issued); the culled objects must save more than that.
        double saving = 0;
        std::size_t culled_patches = 0;
        for (std::size_t i = 0; i < objects_.size(); ++i) {
            if (!decisions_[i].cull) continue;
            const double n = static_cast<double>(objects_[i].range.count);
            saving +=
                n * (objects_[i].rate * tess_cost_ms(decisions_[i].tess_factor) - costs_.issue_ms - costs_.cull_ms);
            culled_patches += objects_[i].range.count;
        }
        const double fixed =
            costs_.hiz_ms +
            (costs_.indirect ? costs_.pass_ms : static_cast<double>(patch_count_ - culled_patches) * costs_.issue_ms);
        if (culled_patches > 0 && !(saving > fixed)) {
            for (Decision& d : decisions_) {
                if (!d.cull) continue;
                d.cull = false;
                d.reason +=
                    format(costs_.indirect ? "; the frame would save %.2f ms <= %.2f ms (Hi-Z build, pass 2)"
                                           : "; the frame would save %.2f ms <= %.2f ms (Hi-Z build, pass-2 issue)",
                           saving, fixed);
            }
        }
    }
    factors_ = tess_factors;
    pending_ = true;
    const bool culls = culled_objects() > 0;
    resumes_culling_ = culls && !previous_culled_;
    previous_culled_ = culls;
    return decisions_;
}

std::vector<ObjectRange> CullAutoPolicy::objects() const {
    std::vector<ObjectRange> ranges;
    for (std::size_t i = 0; i < objects_.size(); ++i) {
        ObjectRange r = objects_[i].range;
        r.cull = i < decisions_.size() ? decisions_[i].cull : true;
        ranges.push_back(r);
    }
    return ranges;
}

std::size_t CullAutoPolicy::culled_objects() const {
    return static_cast<std::size_t>(
        std::count_if(decisions_.begin(), decisions_.end(), [](const Decision& d) { return d.cull; }));
}

CullMode CullAutoPolicy::frame_cull_mode(CullMode tests) const { return culled_objects() > 0 ? tests : CullMode::none; }

void CullAutoPolicy::observe(const FrameStats& stats) {
    if (!pending_) throw std::logic_error("CullAutoPolicy::observe: no decision to observe");
    if (stats.objects.size() != objects_.size())
        throw std::logic_error("CullAutoPolicy::observe: the frame has " + std::to_string(stats.objects.size()) +
                               " objects, the policy " + std::to_string(objects_.size()));
    pending_ = false;
    // (b) cull rates of the objects culled in this frame.
    std::size_t culled_patches = 0;
    double weighted = 0, weights = 0;  // (c0 + t^2) over the patches that passed (drawn this frame or the next)
    for (std::size_t i = 0; i < objects_.size(); ++i) {
        ObjectState& o = objects_[i];
        const ObjectStats& s = stats.objects[i];
        const double w = config_.tess_cost_offset + factors_[i] * factors_[i];
        weighted += w * static_cast<double>(s.visible);
        weights += static_cast<double>(s.visible);
        if (!decisions_[i].cull || s.patches == 0) continue;
        culled_patches += s.patches;
        const double rate = static_cast<double>(s.frustum_culled + s.backpatch_culled + s.occlusion_culled) /
                            static_cast<double>(s.patches);
        const bool retest = decisions_[i].probe && !std::isnan(o.rate);  // not its first measurement
        o.rate = decisions_[i].probe ? rate : average(o.rate, rate, config_.rate_weight);
        o.last_culled = frame_;
        // Probe back-off: a re-test that finds the object still not paying doubles its wait.
        const double x = decisions_[i].break_even;
        if (retest && !std::isnan(x)) {
            const long wait = o.wait > 0 ? o.wait : config_.probe_interval;
            o.wait = rate > x ? config_.probe_interval : std::min<long>(2 * wait, config_.max_probe_interval);
        }
    }
    ++frame_;

    // (a) costs, from the pass times.
    if (stats.timing == TimingMethod::off || stats.patches == 0) return;
    // Program compilation: the first two-pass frame (the cull passes), and a one-pass frame when it
    // is the run's first (its draw and status programs are the two-pass frames' own).
    const bool compiles = stats.two_pass ? !seen_two_pass_ : !(seen_one_pass_ || seen_two_pass_);
    (stats.two_pass ? seen_two_pass_ : seen_one_pass_) = true;
    if (compiles) return;
    // DrawMode::indirect issues only the patches a pass draws: a culled patch costs no draw work
    // (RT0 = 0), what is left is each draw pass's fixed cost (compaction, draw call, finish).
    costs_.indirect = stats.draw == DrawMode::indirect;
    const double n = static_cast<double>(stats.patches);
    // Nothing passed (everything culled): the objects' mean weight.
    double wbar = weights > 0 ? weighted / weights : 0;
    if (!(wbar > 0)) {
        wbar = config_.tess_cost_offset + 1;
        if (!factors_.empty()) {
            wbar = 0;
            for (double t : factors_) wbar += (config_.tess_cost_offset + t * t) / static_cast<double>(factors_.size());
        }
    }
    // A running mean over the first frames, then the exponential average.
    const double cw = std::max(config_.cost_weight, 1.0 / (cost_samples_ + 1));
    if (stats.two_pass) {
        costs_.hiz_ms = average(costs_.hiz_ms, stats.hiz_ms, cw);
        const double a1 = static_cast<double>(stats.pass1_drawn), a2 = static_cast<double>(stats.pass2_drawn);
        // Provisional, until a one-pass frame: pass 1 - pass 2 includes pass 1's clear and occluders
        // and the cost of visible patches, so it overstates what a culled patch would have cost.
        if (tess_samples_ == 0 && a1 - a2 >= 0.1 * n) {
            const double tess = (stats.pass1_ms - stats.pass2_ms) / (a1 - a2);
            if (tess > 0) costs_.tess_unit_ms = average(costs_.tess_unit_ms, tess / wbar, cw);
        }
        // Without a draw cost yet (too few patches drawn to estimate it), pass 2's patches are
        // counted as costing nothing: the pass's fixed cost and the issue are then overstated
        // (the frame rule stricter) until the measuring frames give the draw cost.
        const double drawn2_ms = std::isnan(costs_.tess_unit_ms) ? 0.0 : costs_.tess_unit_ms * wbar;
        if (costs_.indirect) {
            costs_.issue_ms = 0;
            const double pass = std::max(0.0, stats.pass2_ms - drawn2_ms * static_cast<double>(stats.pass2_submitted));
            costs_.pass_ms = pass_measured_ ? average(costs_.pass_ms, pass, cw) : pass;
            pass_measured_ = true;
        } else {
            const double issue = std::max(0.0, (stats.pass2_ms - drawn2_ms * a2) / n);
            costs_.issue_ms = average(costs_.issue_ms, issue, cw);
        }
        if (culled_patches > 0) {
            const double cull =
                std::max(0.0, stats.cull_ms - costs_.status_ms * n) / static_cast<double>(culled_patches);
            costs_.cull_ms = average(costs_.cull_ms, cull, cw);
        }
        ++cost_samples_;
    } else if (culled_patches == 0) {
        costs_.status_ms = status_measured_ ? average(costs_.status_ms, stats.cull_ms / n, cw) : stats.cull_ms / n;
        status_measured_ = true;
        // The draw cost per patch, from the frame that draws every patch: flags, minus the issue of
        // each; indirect, minus the pass's fixed cost (the pass drew pass1_submitted patches).
        if (!std::isnan(costs_.issue_ms) && stats.pass1_drawn > 0) {
            const double tess = costs_.indirect
                                    ? (stats.pass1_ms - costs_.pass_ms) / static_cast<double>(stats.pass1_submitted)
                                    : (stats.pass1_ms - costs_.issue_ms * n) / static_cast<double>(stats.pass1_drawn);
            if (tess > 0 && std::isfinite(tess)) {
                // The first one-pass value replaces the provisional two-pass one; the bootstrap's
                // measuring frames keep their smallest (noise only adds time); later frames average.
                const double unit = tess / wbar;
                if (tess_samples_ == 0)
                    costs_.tess_unit_ms = unit;
                else if (tess_samples_ < config_.measure_frames)
                    costs_.tess_unit_ms = std::min(costs_.tess_unit_ms, unit);
                else
                    costs_.tess_unit_ms = average(costs_.tess_unit_ms, unit, cw);
            }
        }
        // A failed measurement keeps the value it had (the provisional one at first).
        if (tess_samples_ < config_.measure_frames) ++tess_samples_;
    }
}

std::string auto_summary_line(const std::vector<std::string>& names,
                              const std::vector<CullAutoPolicy::Decision>& decisions) {
    const auto on = std::count_if(decisions.begin(), decisions.end(), [](const auto& d) { return d.cull; });
    std::string line = "auto: culling " + std::to_string(on) + " of " + std::to_string(decisions.size()) + " objects";
    for (std::size_t i = 0; i < decisions.size(); ++i) {
        line += i == 0 ? ": " : "; ";
        line += (i < names.size() ? names[i] : "object " + std::to_string(i)) +
                (decisions[i].cull ? " on (" : " off (") + decisions[i].reason + ")";
    }
    return line;
}

std::vector<double> object_tess_factors(const std::vector<BezierPatch>& patches,
                                        const std::vector<ObjectRange>& objects, Vec3 eye, int tess_level,
                                        bool adaptive, float reference_distance) {
    std::vector<double> factors;
    const double level = static_cast<double>(tess_level);
    for (const ObjectRange& o : objects) {
        if (!adaptive || o.count == 0) {
            factors.push_back(level);
            continue;
        }
        double sum[3] = {0, 0, 0}, k = 0;
        for (std::size_t p = o.first; p < o.first + o.count && p < patches.size(); ++p)
            for (int corner : {0, 3, 12, 15}) {
                const Vec3 c = cartesian(patches[p].cp[corner]);
                sum[0] += c.x, sum[1] += c.y, sum[2] += c.z;
                k += 1;
            }
        if (k == 0) {
            factors.push_back(level);
            continue;
        }
        const double dx = sum[0] / k - eye.x, dy = sum[1] / k - eye.y, dz = sum[2] / k - eye.z;
        const double distance = std::max(std::sqrt(dx * dx + dy * dy + dz * dz), 1e-20);
        factors.push_back(std::clamp(level * static_cast<double>(reference_distance) / distance, 1.0, level));
    }
    return factors;
}

std::vector<double> object_tess_factors(const std::vector<BezierPatch>& patches,
                                        const std::vector<ObjectRange>& objects, const RenderParams& params) {
    return object_tess_factors(patches, objects, eye_of_view(params.view), std::clamp(params.tess_level, 1, 64),
                               params.adaptive_tess, params.tess_reference_distance);
}

}  // namespace patchcull::gl
