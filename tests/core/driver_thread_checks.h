// The checks of DriverThreads (core/thread_placement.h) shared by the GL context's and the Vulkan
// device's tests: after a context or device was made with `spread` (and two CPUs or more), each
// thread started meanwhile runs on one CPU and every one was counted as pinned; left alone, each
// runs where the driver lets it (Mesa starts its threads on every CPU, whatever the caller's set).
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <vector>

#include "patchcull/core/thread_placement.h"

namespace patchcull::placement_test {

/// started: the threads started while the context or device was made; pinned: what it reports;
/// spread: pinning was asked for and possible; cpus: the calling thread's CPU count.
inline void expect_driver_threads_placed(const std::vector<int>& started, std::size_t pinned, bool spread, int cpus) {
    ASSERT_FALSE(started.empty()) << "the driver starts its worker threads with the context or device";
    EXPECT_EQ(pinned, spread ? started.size() : 0u);
    for (int id : started) {
        if (spread) {
            EXPECT_EQ(thread_cpu_count(id), 1) << id;
        } else {
            EXPECT_GE(thread_cpu_count(id), cpus) << id;
        }
    }
}

}  // namespace patchcull::placement_test
