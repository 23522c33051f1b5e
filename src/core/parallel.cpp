// Multi-core range splitting over oneTBB (patchcull/core/parallel.h).
#include "patchcull/core/parallel.h"

#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>

namespace patchcull {

void parallel_for_ranges(std::size_t count, std::size_t grain, RangeBody body) {
    if (count == 0) return;
    if (grain == 0) grain = 1;
    const std::size_t chunks = (count + grain - 1) / grain;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks), [&](const tbb::blocked_range<std::size_t>& r) {
        const std::size_t first = r.begin() * grain;
        const std::size_t last = std::min(count, r.end() * grain);
        body(first, last);
    });
}

int hardware_threads() { return tbb::info::default_concurrency(); }

}  // namespace patchcull
