// WorkerPool: every index is called exactly once whatever the number of threads, loop after loop
// on the same pool, the calls do run on more than one thread when asked, and an exception of one
// call reaches the caller and leaves the pool usable, and a loop started from within a loop is
// refused; pinned, each thread runs on a CPU of its own.
#include "tracker/core/parallel_for.h"

#include <gtest/gtest.h>

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

namespace vtrack {
namespace {

TEST(WorkerPool, CallsEveryIndexOnceWithAWorkerBelowTheThreadCount) {
  for (const int threads : {0, 1, 2, 3, 8}) {
    WorkerPool pool(threads);
    EXPECT_EQ(pool.threads(), std::max(threads, 1));
    // Many loops in a row on one pool, of every size, as the tracker runs them scan after scan.
    for (int round = 0; round < 50; ++round) {
      for (const std::size_t n : {0u, 1u, 2u, 5u, 1000u}) {
        std::vector<std::atomic<int>> calls(n);
        std::atomic<int> bad_worker{0};
        pool.ParallelFor(n, [&](std::size_t i, int worker) {
          calls[i].fetch_add(1);
          if (worker < 0 || worker >= pool.threads()) bad_worker.fetch_add(1);
        });
        for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(calls[i].load(), 1) << "index " << i;
        ASSERT_EQ(bad_worker.load(), 0);
      }
    }
  }
}

TEST(WorkerPool, RunsOnMoreThanOneThreadWhenAsked) {
  // Each call waits until another thread has started one (or 0.2 s pass): with one thread the
  // waits time out, with two they do not.
  auto threads_seen = [](int threads) {
    WorkerPool pool(threads);
    std::mutex m;
    std::set<std::thread::id> ids;
    std::atomic<int> started{0};
    pool.ParallelFor(8, [&](std::size_t, int) {
      {
        std::lock_guard<std::mutex> lock(m);
        ids.insert(std::this_thread::get_id());
      }
      started.fetch_add(1);
      const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(200);
      while (started.load() < 2 && std::chrono::steady_clock::now() < until) std::this_thread::yield();
    });
    return ids.size();
  };
  EXPECT_EQ(threads_seen(1), 1u);
  EXPECT_EQ(threads_seen(2), 2u);
}

// The CPUs a thread may run on, as the kernel reports them.
std::vector<int> AffinityOf(pthread_t thread) {
  cpu_set_t set;
  CPU_ZERO(&set);
  EXPECT_EQ(pthread_getaffinity_np(thread, sizeof(set), &set), 0);
  std::vector<int> cpus;
  for (int c = 0; c < CPU_SETSIZE; ++c) {
    if (CPU_ISSET(c, &set)) cpus.push_back(c);
  }
  return cpus;
}

TEST(WorkerPool, PinnedThreadsEachRunOnOneCpuOfTheirOwn) {
  const pthread_t self = pthread_self();
  const std::vector<int> allowed = AffinityOf(self);
  if (allowed.size() < 2) GTEST_SKIP() << "the process may run on " << allowed.size() << " CPU";
  // Each worker's affinity as the kernel reports it, from inside its calls (each call waits for
  // the other worker to start one, so both take part).
  auto affinities = [](WorkerPool* pool) {
    std::vector<std::vector<int>> seen(2);
    std::atomic<int> started{0};
    std::mutex m;
    pool->ParallelFor(2, [&](std::size_t, int worker) {
      started.fetch_add(1);
      const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
      while (started.load() < 2 && std::chrono::steady_clock::now() < until) std::this_thread::yield();
      std::lock_guard<std::mutex> lock(m);
      seen[static_cast<std::size_t>(worker)] = AffinityOf(pthread_self());
    });
    return seen;
  };
  {
    WorkerPool pool(2, /*pin=*/false);
    const auto seen = affinities(&pool);
    EXPECT_EQ(seen[0], allowed);
    EXPECT_EQ(seen[1], allowed);
    EXPECT_FALSE(pool.pinned());
  }
  {
    WorkerPool pool(2, /*pin=*/true);
    const auto seen = affinities(&pool);
    EXPECT_EQ(seen[0], std::vector<int>{allowed[0]});  // the calling thread
    EXPECT_EQ(seen[1], std::vector<int>{allowed[1]});
    EXPECT_TRUE(pool.pinned());
    EXPECT_EQ(AffinityOf(self), std::vector<int>{allowed[0]});  // between loops too
    // A second pool made meanwhile on the pinned thread pins as the first did.
    WorkerPool second(2, /*pin=*/true);
    const auto seen_second = affinities(&second);
    EXPECT_EQ(seen_second[1], std::vector<int>{allowed[1]});
    EXPECT_TRUE(second.pinned());
  }
  EXPECT_EQ(AffinityOf(self), allowed);  // restored when the pool goes
  // Nothing is pinned where the process may not run on a CPU for each thread.
  WorkerPool many(static_cast<int>(allowed.size()) + 1, /*pin=*/true);
  EXPECT_FALSE(many.pinned());
  many.ParallelFor(4, [](std::size_t, int) {});
  EXPECT_EQ(AffinityOf(self), allowed);
}

TEST(WorkerPool, AnExceptionOfOneCallReachesTheCallerAndThePoolGoesOn) {
  for (const int threads : {1, 2}) {
    WorkerPool pool(threads);
    std::atomic<int> calls{0};
    EXPECT_THROW(pool.ParallelFor(100,
                                  [&](std::size_t i, int) {
                                    calls.fetch_add(1);
                                    if (i == 7) throw std::runtime_error("index 7");
                                  }),
                 std::runtime_error);
    EXPECT_GE(calls.load(), 8);
    // The next loop runs whole, and an earlier loop's exception is not thrown again.
    std::atomic<int> after{0};
    pool.ParallelFor(100, [&](std::size_t, int) { after.fetch_add(1); });
    EXPECT_EQ(after.load(), 100);
  }
}

TEST(WorkerPool, ALoopStartedFromWithinALoopIsRefused) {
  // Whatever the number of threads (with one the nested loop would run, with two it would
  // corrupt the running one): the nested call throws, and that reaches the outer caller.
  for (const int threads : {1, 2}) {
    WorkerPool pool(threads);
    EXPECT_THROW(pool.ParallelFor(4, [&](std::size_t, int) { pool.ParallelFor(2, [](std::size_t, int) {}); }),
                 std::logic_error);
    std::atomic<int> after{0};
    pool.ParallelFor(10, [&](std::size_t, int) { after.fetch_add(1); });
    EXPECT_EQ(after.load(), 10);
  }
}

}  // namespace
}  // namespace vtrack
