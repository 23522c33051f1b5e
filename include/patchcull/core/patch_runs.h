// patchcull/core/patch_runs.h: spans of a patch set, and the runs a cull pass that skips some
// patches is dispatched on. A software rasterizer (Mesa's llvmpipe and lavapipe) spends as long on
// a patch a pass returns from at once as on one it tests, so a pass that skips displaced patches
// (the back-patch tests, the Hi-Z test of the occlusion pass) or undisplaced ones (the displaced
// bounds) should not be dispatched on them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "patchcull/core/displacement.h"

namespace patchcull {

/// Patches [first, first + count) of a set.
struct PatchSpan {
    std::size_t first = 0;
    std::size_t count = 0;
    bool operator==(const PatchSpan&) const = default;
};

/// The ascending runs of the patches p with keep[p] != 0, a gap shorter than min_gap between two
/// runs joined into one (the result covers every kept patch and some others; min_gap 0 or 1:
/// exactly the kept ones).
std::vector<PatchSpan> kept_runs(const std::vector<std::uint8_t>& keep, std::size_t min_gap);

/// Appends to out the nonempty parts of span inside runs (ascending and disjoint, as kept_runs
/// returns them), ascending.
void clip_to_runs(const PatchSpan& span, const std::vector<PatchSpan>& runs, std::vector<PatchSpan>& out);

/// Sorts disjoint spans by first and joins those that touch (a.first + a.count == b.first), in
/// place: the fewest dispatches that cover the same patches.
void join_adjacent(std::vector<PatchSpan>& spans);

/// The shortest gap displacement_runs leaves out between two runs: a shorter one costs less to
/// test than a dispatch around it (on llvmpipe a dispatch costs tens of microseconds, a patch in
/// the cone pass about 0.2).
inline constexpr std::size_t kMinSkippedRun = 256;

/// The runs of a set for the passes that skip displaced or undisplaced patches.
struct DisplacementRuns {
    /// Every patch whose margin is not > 0: the back-patch passes and the occlusion pass's Hi-Z
    /// test run on these. Without margins, one run of the whole set.
    std::vector<PatchSpan> undisplaced;
    /// Every patch with a displacement range other than (0, 0): the displaced-bound pass with
    /// only_displaced runs on these. Without ranges, none.
    std::vector<PatchSpan> displaced;
};

/// displacement_runs for n patches with margins (empty, or one per patch) and ranges (empty, or
/// one per patch), gaps shorter than kMinSkippedRun kept inside a run.
DisplacementRuns displacement_runs(std::size_t n, const std::vector<float>& margins,
                                   const std::vector<DisplacementRange>& ranges);

}  // namespace patchcull
