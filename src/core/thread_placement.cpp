// Thread placement on Linux: /proc/self/task lists the threads, sched_setaffinity pins one.
#include "patchcull/core/thread_placement.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>

#ifdef __linux__
#include <dirent.h>
#include <sched.h>
#include <unistd.h>
#endif

namespace patchcull {

std::vector<int> process_thread_ids() {
    std::vector<int> ids;
#ifdef __linux__
    DIR* dir = opendir("/proc/self/task");
    if (!dir) return ids;
    while (const dirent* e = readdir(dir)) {
        char* end = nullptr;
        const long id = std::strtol(e->d_name, &end, 10);
        if (end != e->d_name && *end == '\0' && id > 0) ids.push_back(static_cast<int>(id));
    }
    closedir(dir);
    std::sort(ids.begin(), ids.end());
#endif
    return ids;
}

std::vector<int> threads_started(std::span<const int> before, std::span<const int> after) {
    std::vector<int> started;
    std::set_difference(after.begin(), after.end(), before.begin(), before.end(), std::back_inserter(started));
    return started;
}

namespace {

#ifdef __linux__
// Thread tid's state letter in /proc ('R' running or runnable, 'S' asleep, ...), 0 when it is not
// a thread of this process (any more).
char thread_state(int tid) {
    std::ifstream stat("/proc/self/task/" + std::to_string(tid) + "/stat");
    std::string line;
    if (!std::getline(stat, line)) return 0;
    const std::size_t paren = line.rfind(')');
    return paren == std::string::npos || paren + 2 >= line.size() ? 0 : line[paren + 2];
}
#endif

}  // namespace

std::size_t spread_threads(std::span<const int> threads) {
#ifdef __linux__
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) return 0;
    std::vector<int> cpus;
    for (int c = 0; c < CPU_SETSIZE; ++c)
        if (CPU_ISSET(c, &allowed)) cpus.push_back(c);
    if (cpus.size() < 2) return 0;
    // A thread just started may still be running its start-up code, which can set its own CPUs
    // (Mesa's queue threads ask for every CPU): wait until each has gone to sleep, 1 s at most.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
    for (int tid : threads)
        while (thread_state(tid) == 'R' && std::chrono::steady_clock::now() < deadline)
            std::this_thread::sleep_for(std::chrono::microseconds(200));
    // Concurrent processes start at different CPUs.
    const std::size_t offset = static_cast<std::size_t>(getpid()) % cpus.size();
    std::size_t pinned = 0;
    for (std::size_t i = 0; i < threads.size(); ++i) {
        if (thread_state(threads[i]) == 0) continue;  // ended: its id is not ours any more
        cpu_set_t one;
        CPU_ZERO(&one);
        CPU_SET(cpus[(offset + i) % cpus.size()], &one);
        if (sched_setaffinity(threads[i], sizeof one, &one) == 0) ++pinned;
    }
    return pinned;
#else
    (void)threads;
    return 0;
#endif
}

int thread_cpu_count(int tid) {
#ifdef __linux__
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(tid, sizeof set, &set) != 0) return 0;
    return CPU_COUNT(&set);
#else
    (void)tid;
    return 0;
#endif
}

}  // namespace patchcull
