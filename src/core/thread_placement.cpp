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
// True when thread tid is not running or runnable (its state in /proc is not 'R'), or is gone.
bool thread_waits(int tid) {
    std::ifstream stat("/proc/self/task/" + std::to_string(tid) + "/stat");
    std::string line;
    if (!std::getline(stat, line)) return true;
    const std::size_t paren = line.rfind(')');
    return paren == std::string::npos || paren + 2 >= line.size() || line[paren + 2] != 'R';
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
    // (Mesa's queue threads ask for every CPU): wait until each has gone to sleep, 200 ms at most.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(200);
    for (int tid : threads)
        while (!thread_waits(tid) && std::chrono::steady_clock::now() < deadline)
            std::this_thread::sleep_for(std::chrono::microseconds(200));
    std::size_t pinned = 0;
    for (std::size_t i = 0; i < threads.size(); ++i) {
        cpu_set_t one;
        CPU_ZERO(&one);
        CPU_SET(cpus[i % cpus.size()], &one);
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
