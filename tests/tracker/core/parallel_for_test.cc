// WorkerPool: every index is called exactly once whatever the number of threads, loop after loop
// on the same pool, the calls do run on more than one thread when asked, and an exception of one
// call reaches the caller and leaves the pool usable, and a loop started from within a loop is
// refused; pinned, each thread runs on a CPU of its own.
#include "tracker/core/parallel_for.h"

#include <gtest/gtest.h>

#include <pthread.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "tests/support/affinity.h"

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

TEST(WorkerPool, PinnedThreadsEachRunOnOneCpuOfTheirOwn) {
  const pthread_t self = pthread_self();
  const std::vector<int> allowed = testing::AffinityOf(self);
  const int n = static_cast<int>(allowed.size());
  if (n < 2 || n > 16 || !testing::CanPinAThread(allowed[1])) {
    GTEST_SKIP() << "the process may run on " << n << " CPUs, or may not pin a thread";
  }
  // Each worker's affinity as the kernel reports it, from inside its calls (each call waits
  // until every worker has started one, so all take part).
  auto affinities = [](WorkerPool* pool) {
    const int threads = pool->threads();
    std::vector<std::vector<int>> seen(static_cast<std::size_t>(threads));
    std::atomic<int> started{0};
    std::mutex m;
    pool->ParallelFor(static_cast<std::size_t>(threads), [&](std::size_t, int worker) {
      started.fetch_add(1);
      const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
      while (started.load() < threads && std::chrono::steady_clock::now() < until) std::this_thread::yield();
      std::lock_guard<std::mutex> lock(m);
      seen[static_cast<std::size_t>(worker)] = testing::AffinityOf(pthread_self());
    });
    return seen;
  };
  {
    WorkerPool pool(n, /*pin=*/false);
    for (const auto& cpus : affinities(&pool)) EXPECT_EQ(cpus, allowed);
    EXPECT_FALSE(pool.pinned());
  }
  {
    // As many threads as CPUs: each on its own, the calling thread (worker 0) on the first.
    auto pool = std::make_unique<WorkerPool>(n, /*pin=*/true);
    const auto seen = affinities(pool.get());
    for (int w = 0; w < n; ++w) {
      EXPECT_EQ(seen[static_cast<std::size_t>(w)], std::vector<int>{allowed[static_cast<std::size_t>(w)]});
    }
    EXPECT_TRUE(pool->pinned());
    EXPECT_EQ(testing::AffinityOf(self), std::vector<int>{allowed[0]});  // between loops too
    // A second pool on the pinned thread pins as the first did; the thread is set free when
    // the last of them goes, here the second (pools destroyed in the order they were made).
    auto second = std::make_unique<WorkerPool>(n, /*pin=*/true);
    EXPECT_EQ(affinities(second.get()).back(), std::vector<int>{allowed.back()});
    EXPECT_TRUE(second->pinned());
    {
      // An unpinned pool made on the pinned thread: its workers get the CPUs the thread had.
      WorkerPool unpinned(n, /*pin=*/false);
      const auto seen_unpinned = affinities(&unpinned);
      for (int w = 1; w < n; ++w) EXPECT_EQ(seen_unpinned[static_cast<std::size_t>(w)], allowed);
    }
    pool.reset();
    EXPECT_EQ(testing::AffinityOf(self), std::vector<int>{allowed[0]});
    second.reset();
  }
  EXPECT_EQ(testing::AffinityOf(self), allowed);  // restored when the last pinned pool goes
  // Nothing is pinned with more threads than CPUs, or fewer (the scheduler finds idle CPUs).
  for (const int threads : {n + 1, n - 1}) {
    if (threads < 2) continue;
    WorkerPool pool(threads, /*pin=*/true);
    EXPECT_FALSE(pool.pinned()) << threads << " threads";
    for (const auto& cpus : affinities(&pool)) EXPECT_EQ(cpus, allowed) << threads << " threads";
  }
  EXPECT_EQ(testing::AffinityOf(self), allowed);
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
