// thread_placement.h: the threads a process starts are found, and spread_threads gives each a CPU
// of its own in turn, leaving the calling thread where it may run.
#include "patchcull/core/thread_placement.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#ifdef __linux__
#include <sched.h>
#include <unistd.h>
#endif

using namespace patchcull;

namespace {

#ifdef __linux__
// The one CPU a thread may run on, or -1 when it may run on several.
int only_cpu(int tid) {
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(tid, sizeof set, &set) != 0 || CPU_COUNT(&set) != 1) return -1;
    for (int c = 0; c < CPU_SETSIZE; ++c)
        if (CPU_ISSET(c, &set)) return c;
    return -1;
}
#endif

// Threads that wait until released, with their Linux thread ids.
class WaitingThreads {
public:
    explicit WaitingThreads(int n) {
        for (int i = 0; i < n; ++i)
            threads_.emplace_back([this] {
                std::unique_lock<std::mutex> lock(mutex_);
#ifdef __linux__
                ids_.push_back(static_cast<int>(gettid()));
#endif
                started_.notify_all();
                release_.wait(lock, [this] { return released_; });
            });
        std::unique_lock<std::mutex> lock(mutex_);
        started_.wait(lock, [&] { return ids_.size() == static_cast<std::size_t>(n); });
        std::sort(ids_.begin(), ids_.end());
    }
    ~WaitingThreads() {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            released_ = true;
        }
        release_.notify_all();
        for (std::thread& t : threads_) t.join();
    }
    const std::vector<int>& ids() const { return ids_; }

private:
    std::mutex mutex_;
    std::condition_variable started_, release_;
    bool released_ = false;
    std::vector<int> ids_;
    std::vector<std::thread> threads_;
};

}  // namespace

TEST(ThreadPlacement, ThreadsStartedAreTheNewIds) {
    const std::vector<int> before{3, 5, 9};
    const std::vector<int> after{3, 4, 9, 12};
    EXPECT_EQ(threads_started(before, after), (std::vector<int>{4, 12}));
    EXPECT_TRUE(threads_started(after, after).empty());
}

#ifdef __linux__
TEST(ThreadPlacement, ListsTheThreadsAProcessStarts) {
    const std::vector<int> before = process_thread_ids();
    ASSERT_FALSE(before.empty());
    EXPECT_TRUE(std::is_sorted(before.begin(), before.end()));
    EXPECT_TRUE(std::binary_search(before.begin(), before.end(), static_cast<int>(gettid())));
    WaitingThreads waiting(3);
    const std::vector<int> started = threads_started(before, process_thread_ids());
    for (int id : waiting.ids()) EXPECT_TRUE(std::count(started.begin(), started.end(), id)) << id;
}

TEST(ThreadPlacement, SpreadGivesEachThreadOneCpuInTurn) {
    const int cpus = thread_cpu_count(static_cast<int>(gettid()));
    ASSERT_GE(cpus, 1);
    WaitingThreads waiting(3);
    const std::size_t pinned = spread_threads(waiting.ids());
    if (cpus < 2) {
        EXPECT_EQ(pinned, 0u);
        GTEST_SKIP() << "one CPU: nothing to spread";
    }
    EXPECT_EQ(pinned, 3u);
    std::vector<int> placed;
    for (int id : waiting.ids()) {
        EXPECT_EQ(thread_cpu_count(id), 1) << id;
        placed.push_back(only_cpu(id));
    }
    // Consecutive threads on different CPUs; with two CPUs the third shares the first's.
    EXPECT_NE(placed[0], placed[1]);
    if (cpus == 2) {
        EXPECT_EQ(placed[2], placed[0]);
    } else {
        EXPECT_NE(placed[2], placed[1]);
    }
    // The calling thread may still run anywhere it could.
    EXPECT_EQ(thread_cpu_count(static_cast<int>(gettid())), cpus);
}

TEST(ThreadPlacement, AThreadThatIsGoneIsSkipped) {
    std::vector<int> gone;
    {
        WaitingThreads waiting(1);
        gone = waiting.ids();
    }
    // A joined thread's id is no longer one of this process's threads: neither listed nor pinned,
    // even if another process's new thread got the id meanwhile.
    const std::vector<int> now = process_thread_ids();
    ASSERT_FALSE(std::binary_search(now.begin(), now.end(), gone[0]));
    EXPECT_EQ(spread_threads(gone), 0u);
}
#endif
