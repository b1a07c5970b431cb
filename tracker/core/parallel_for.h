// Runs the calls of an index loop on a few threads at once.
#pragma once

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <type_traits>
#include <vector>

namespace vtrack {

// A fixed set of threads, started once, that share the calls of index loops (ParallelFor).
// Started once rather than per loop: starting and joining a thread costs about 60 us of system
// time on a 2-core virtual machine (median of 2,000), and the tracker runs several such loops
// per scan (docs/design.md, section 9).
//
// Written with std::thread rather than OpenMP: the tracker's builds include clang's sanitizer
// and fuzzing builds, where OpenMP needs another runtime (libomp) and is opaque to
// ThreadSanitizer; two workers over an index range need no more than this.
//
// Pinning (pin = true), where the process may use exactly as many CPUs as the pool has threads
// (a machine of that size, or the CPUs chosen with taskset): worker w runs on the w-th of them,
// and the first thread that calls ParallelFor on the first, until the last pinned pool it
// called is destroyed on it (its affinity is then restored). Unpinned, a tracker that sleeps
// between sweeps gets little from its second thread on a 2-CPU machine: the worker, woken after
// ~90 ms asleep, is placed on the CPU of the thread that woke it (Linux's wake-affine
// placement), and the two run one after the other until the scheduler moves one
// (docs/speed.md). With more CPUs than threads nothing is pinned: the scheduler then
// finds an idle CPU, and pinning to fixed ones (CPU 0 takes most interrupts) could only hurt.
// A refused pin is ignored, and so is another thread calling later.
class WorkerPool {
 public:
  // threads: the calling thread (worker 0) and threads - 1 started here (workers 1 ...); 1 or
  // less: every loop runs on the calling thread.
  // If a thread cannot be started, those started are stopped and the error is thrown.
  explicit WorkerPool(int threads, bool pin = false) {
    const int started = std::max(threads, 1) - 1;
    if (pin && started > 0) cpus_ = AllowedCpus(started + 1);  // empty: not pinned
    pinned_ = !cpus_.empty();
    // Threads start with their creator's affinity: on a thread a pinned pool holds to one CPU,
    // an unpinned pool's workers get the CPUs that thread had before.
    const CallerPin& creator = CallerPinOfThisThread();
    if (cpus_.empty() && creator.pools > 0) {
      free_mask_ = creator.mask;
      free_workers_ = true;
    }
    threads_.reserve(static_cast<std::size_t>(started));
    try {
      for (int w = 1; w <= started; ++w) threads_.emplace_back([this, w] { Serve(w); });
    } catch (...) {
      Stop();
      throw;
    }
  }
  ~WorkerPool() {
    Stop();
    if (pinned_caller_ == std::this_thread::get_id()) {
      CallerPin& pin = CallerPinOfThisThread();
      if (pin.pools > 0 && --pin.pools == 0) {
        pthread_setaffinity_np(pthread_self(), sizeof(pin.mask), &pin.mask);
      }
    }
  }
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int threads() const { return static_cast<int>(threads_.size()) + 1; }
  // Whether the pool's threads are pinned, each to a CPU of its own (its first caller too, from
  // its first parallel loop on).
  bool pinned() const { return pinned_; }

  // Calls fn(i, worker) once for every i in [0, n); each worker takes the next index from a
  // shared counter as it finishes one, so which worker runs which index is not fixed. worker (in
  // [0, threads())) lets fn use per-thread scratch; fn must not touch what another index's call
  // touches. Returns when every call has returned. If calls threw, one of their exceptions (that
  // of the lowest-numbered worker that threw) is rethrown here, after the others have finished;
  // the workers stop taking indices once one has thrown. One loop at a time: a call from within
  // fn, or from another thread while a loop runs, throws std::logic_error.
  template <class Fn>
  void ParallelFor(std::size_t n, Fn&& fn) {
    if (running_.exchange(true)) {
      throw std::logic_error("WorkerPool::ParallelFor called while one of its loops runs");
    }
    struct Done {
      std::atomic<bool>* running;
      ~Done() { running->store(false); }
    } done{&running_};
    if (threads_.empty() || n <= 1) {
      for (std::size_t i = 0; i < n; ++i) fn(i, 0);
      return;
    }
    if (!cpus_.empty() && caller_ != std::this_thread::get_id()) PinCaller();
    std::atomic<std::size_t> next{0};
    errors_.assign(threads_.size() + 1, nullptr);
    Loop loop{n, &next, const_cast<void*>(static_cast<const void*>(&fn)),
              [](void* f, std::size_t i, int worker) {
                (*static_cast<std::remove_reference_t<Fn>*>(f))(i, worker);
              }};
    {
      std::lock_guard<std::mutex> lock(mutex_);
      loop_ = &loop;
      busy_ = threads_.size();
      ++generation_;
    }
    wake_.notify_all();
    Work(loop, 0);
    {
      // The started workers hold `loop` (on this stack) until they report back.
      std::unique_lock<std::mutex> lock(mutex_);
      done_.wait(lock, [this] { return busy_ == 0; });
      loop_ = nullptr;
    }
    for (const std::exception_ptr& e : errors_) {
      if (e) std::rethrow_exception(e);
    }
  }

 private:
  // One ParallelFor call: its range, its counter and its function (type-erased).
  struct Loop {
    std::size_t n;
    std::atomic<std::size_t>* next;
    void* fn;
    void (*call)(void* fn, std::size_t i, int worker);
  };

  void Work(const Loop& loop, int worker) {
    try {
      for (std::size_t i = loop.next->fetch_add(1); i < loop.n; i = loop.next->fetch_add(1)) {
        loop.call(loop.fn, i, worker);
      }
    } catch (...) {
      errors_[static_cast<std::size_t>(worker)] = std::current_exception();
      loop.next->store(loop.n);  // the others stop after their current call
    }
  }

  void Stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : threads_) t.join();
  }

  // The affinity a thread had before the pools it called pinned it, and how many of those
  // pools are alive (several trackers may be driven from one thread).
  struct CallerPin {
    int pools = 0;
    cpu_set_t mask{};
  };
  static CallerPin& CallerPinOfThisThread() {
    thread_local CallerPin pin;
    return pin;
  }

  // Pins the calling thread to cpus_[0] if it is the first to call; another thread that calls
  // later is left as it is.
  void PinCaller() {
    const bool first = caller_ == std::thread::id();
    caller_ = std::this_thread::get_id();
    if (!first) {
      pinned_ = false;
      return;
    }
    CallerPin& pin = CallerPinOfThisThread();
    if (pin.pools == 0 &&
        (pthread_getaffinity_np(pthread_self(), sizeof(pin.mask), &pin.mask) != 0 ||
         !PinTo(cpus_[0]))) {
      pinned_ = false;
      return;
    }
    ++pin.pools;  // pinned to cpus_[0] already by another pool (the same set: AllowedCpus)
    pinned_caller_ = caller_;
  }

  // The CPUs the process may run on if there are exactly n, else none. Read once, when the
  // first pool is made, from the calling thread's affinity (the process's, before any pool
  // pinned a thread): a later pool made on a pinned thread must see the same set.
  static std::vector<int> AllowedCpus(int n) {
    static const std::vector<int> allowed = [] {
      std::vector<int> cpus;
      cpu_set_t set;
      CPU_ZERO(&set);
      if (sched_getaffinity(0, sizeof(set), &set) != 0) return cpus;
      for (int c = 0; c < CPU_SETSIZE; ++c) {
        if (CPU_ISSET(c, &set)) cpus.push_back(c);
      }
      return cpus;
    }();
    if (static_cast<int>(allowed.size()) != n) return {};
    return allowed;
  }

  // Pins the calling thread to cpu; false if refused.
  static bool PinTo(int cpu) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    return pthread_setaffinity_np(pthread_self(), sizeof(set), &set) == 0;
  }

  void Serve(int worker) {
    if (!cpus_.empty() && !PinTo(cpus_[static_cast<std::size_t>(worker)])) pinned_ = false;
    if (free_workers_) pthread_setaffinity_np(pthread_self(), sizeof(free_mask_), &free_mask_);
    std::uint64_t seen = 0;
    for (;;) {
      const Loop* loop = nullptr;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
        if (stop_) return;
        seen = generation_;
        loop = loop_;
      }
      Work(*loop, worker);
      bool last = false;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        last = --busy_ == 0;
      }
      if (last) done_.notify_one();
    }
  }

  std::vector<int> cpus_;            // pinned: the CPU of each worker (0: the caller); else empty
  std::atomic<bool> pinned_{false};
  std::thread::id caller_;          // the last thread that called ParallelFor (pinning only)
  std::thread::id pinned_caller_;   // the first caller, if pinned (its CallerPin counts this pool)
  bool free_workers_ = false;       // unpinned pool made on a pinned thread: workers get free_mask_
  cpu_set_t free_mask_{};
  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const Loop* loop_ = nullptr;      // the loop being run (guarded by mutex_)
  std::size_t busy_ = 0;            // started workers not done with it (guarded by mutex_)
  std::uint64_t generation_ = 0;    // loops started so far (guarded by mutex_)
  bool stop_ = false;               // guarded by mutex_
  std::atomic<bool> running_{false};  // a ParallelFor call is under way
  std::vector<std::exception_ptr> errors_;  // per worker: what its call threw, for the caller
};

}  // namespace vtrack
