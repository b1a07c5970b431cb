// Runs the calls of an index loop on a few threads at once.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace vtrack {

// Calls fn(i, worker) once for every i in [0, n), on `threads` threads: the calling one (worker
// 0) and threads - 1 started for this call (workers 1 ...), which take the next index from a
// shared counter as they finish one. worker lets fn use per-thread scratch; fn must not touch
// what another index's call touches. Returns when every call has returned; the first exception
// a call threw is rethrown here (after the others have finished). threads <= 1 or n <= 1: a
// plain loop on the calling thread.
//
// Written with std::thread rather than OpenMP: the tracker's builds include clang's sanitizer
// and fuzzing builds, where OpenMP needs another runtime (libomp) and is opaque to
// ThreadSanitizer; two workers over an index range need no more than this.
template <class Fn>
void ParallelFor(std::size_t n, int threads, Fn&& fn) {
  if (threads <= 1 || n <= 1) {
    for (std::size_t i = 0; i < n; ++i) fn(i, 0);
    return;
  }
  std::atomic<std::size_t> next{0};
  const std::size_t num_workers = std::min<std::size_t>(static_cast<std::size_t>(threads), n);
  std::vector<std::exception_ptr> errors(num_workers);
  auto work = [&](std::size_t worker) {
    try {
      for (std::size_t i = next.fetch_add(1); i < n; i = next.fetch_add(1)) {
        fn(i, static_cast<int>(worker));
      }
    } catch (...) {
      errors[worker] = std::current_exception();
      next.store(n);  // the others stop after their current call
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(num_workers - 1);
  for (std::size_t w = 1; w < num_workers; ++w) pool.emplace_back(work, w);
  work(0);
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

}  // namespace vtrack
