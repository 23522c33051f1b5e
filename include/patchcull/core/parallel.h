// patchcull/core/parallel.h: multi-core execution of kernels over patch ranges (oneTBB underneath).
#pragma once

#include <cstddef>
#include <functional>

namespace patchcull {

/// Calls body(first, last) over disjoint ranges covering [0, count), in parallel. Range starts
/// are multiples of grain (grain a multiple of 16 keeps SIMD loads aligned in batches).
void parallel_for_ranges(std::size_t count, std::size_t grain,
                         const std::function<void(std::size_t, std::size_t)>& body);

/// Number of worker threads parallel_for_ranges may use.
int hardware_threads();

}  // namespace patchcull
