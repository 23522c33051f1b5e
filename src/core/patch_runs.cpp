// kept_runs, clip_to_runs, join_adjacent and displacement_runs (patchcull/core/patch_runs.h).
#include "patchcull/core/patch_runs.h"

#include <algorithm>

namespace patchcull {

std::vector<PatchSpan> kept_runs(const std::vector<std::uint8_t>& keep, std::size_t min_gap) {
    std::vector<PatchSpan> runs;
    for (std::size_t p = 0; p < keep.size();) {
        if (!keep[p]) {
            ++p;
            continue;
        }
        std::size_t end = p + 1;
        while (end < keep.size() && keep[end]) ++end;
        if (!runs.empty() && p - (runs.back().first + runs.back().count) < min_gap)
            runs.back().count = end - runs.back().first;
        else
            runs.push_back({p, end - p});
        p = end;
    }
    return runs;
}

void clip_to_runs(const PatchSpan& span, const std::vector<PatchSpan>& runs, std::vector<PatchSpan>& out) {
    const std::size_t span_end = span.first + span.count;
    // The first run that ends after the span starts.
    auto it = std::upper_bound(runs.begin(), runs.end(), span.first,
                               [](std::size_t first, const PatchSpan& r) { return first < r.first + r.count; });
    for (; it != runs.end() && it->first < span_end; ++it) {
        const std::size_t a = std::max(span.first, it->first), b = std::min(span_end, it->first + it->count);
        if (a < b) out.push_back({a, b - a});
    }
}

void join_adjacent(std::vector<PatchSpan>& spans) {
    std::sort(spans.begin(), spans.end(), [](const PatchSpan& a, const PatchSpan& b) { return a.first < b.first; });
    std::size_t joined = 0;
    for (const PatchSpan& s : spans) {
        if (joined > 0 && spans[joined - 1].first + spans[joined - 1].count == s.first)
            spans[joined - 1].count += s.count;
        else
            spans[joined++] = s;
    }
    spans.resize(joined);
}

DisplacementRuns displacement_runs(std::size_t n, const std::vector<float>& margins,
                                   const std::vector<DisplacementRange>& ranges) {
    DisplacementRuns runs;
    std::vector<std::uint8_t> keep(n, 1);
    for (std::size_t p = 0; p < std::min(n, margins.size()); ++p) keep[p] = !(margins[p] > 0.0f);
    runs.undisplaced = kept_runs(keep, kMinSkippedRun);
    keep.assign(std::min(n, ranges.size()), 0);
    for (std::size_t p = 0; p < keep.size(); ++p) keep[p] = ranges[p].d_min != 0.0f || ranges[p].d_max != 0.0f;
    runs.displaced = kept_runs(keep, kMinSkippedRun);
    return runs;
}

}  // namespace patchcull
