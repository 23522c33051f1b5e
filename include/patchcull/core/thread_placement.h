// patchcull/core/thread_placement.h: which CPU a process's threads run on. A software
// rasterizer (Mesa's llvmpipe, lavapipe) starts worker threads of its own and waits while they
// run a dispatch; Linux's scheduler may wake two of them onto one CPU and leave the other idle,
// which doubles the dispatch (docs/PERFORMANCE.md, "The driver's threads"). The GL and Vulkan
// contexts use these to give each such worker a CPU of its own.
//
// Linux only (/proc/self/task, sched_setaffinity); elsewhere the list is empty and nothing is
// pinned. None of these throws, except std::bad_alloc.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace patchcull {

/// What a context or device of patchcull's own (gl::GlContext, vk::HeadlessDevice) does with the
/// threads its driver starts while it is made.
enum class DriverThreads {
    /// On a software rasterizer (llvmpipe, lavapipe): pin each thread started while the context
    /// or device was made (the driver's rasterizer and compute workers, and any thread another
    /// thread of the process started meanwhile) to a CPU of its own, in turn (spread_threads).
    /// A GPU driver's threads are left alone, as is the calling thread. Threads started later,
    /// e.g. by a second context that shares the driver's screen, are not pinned.
    spread,
    /// Leave their placement to the operating system.
    os,
};

/// The ids of the calling process's threads, ascending (Linux thread ids, as gettid returns).
/// Empty where they cannot be listed.
std::vector<int> process_thread_ids();

/// The ids in `after` that are not in `before` (both ascending): the threads started between two
/// process_thread_ids() calls, whoever started them.
std::vector<int> threads_started(std::span<const int> before, std::span<const int> after);

/// Pins thread threads[i] to the ((i + pid) mod n)-th of the n CPUs the calling thread may run
/// on, so that consecutive threads share no CPU while there are CPUs left (and concurrent
/// processes start at different CPUs). Returns how many it pinned: 0 when the calling thread may
/// run on fewer than two CPUs. First waits until each thread is asleep, 1 s at most in all (a
/// thread just started may still run start-up code that sets its own CPUs, as Mesa's queue
/// threads do). An id that is no longer a thread of this process is skipped. The calling
/// thread's own placement is not changed.
std::size_t spread_threads(std::span<const int> threads);

/// The number of CPUs thread `tid` may run on (0 when it cannot be read, e.g. it has ended).
int thread_cpu_count(int tid);

}  // namespace patchcull
