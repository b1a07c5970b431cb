// The CPUs a thread may run on, as the kernel reports them, for the tests of thread pinning
// (tracker/core/parallel_for.h).
#pragma once

#include <pthread.h>
#include <sched.h>

#include <thread>
#include <vector>

namespace vtrack::testing {

// The CPUs `thread` may run on, ascending; empty if the kernel does not say.
inline std::vector<int> AffinityOf(pthread_t thread) {
  cpu_set_t set;
  CPU_ZERO(&set);
  std::vector<int> cpus;
  if (pthread_getaffinity_np(thread, sizeof(set), &set) != 0) return cpus;
  for (int c = 0; c < CPU_SETSIZE; ++c) {
    if (CPU_ISSET(c, &set)) cpus.push_back(c);
  }
  return cpus;
}

// Whether a thread of this process may be pinned to `cpu` (a container may refuse it); tried on
// a thread of its own, which then ends.
inline bool CanPinAThread(int cpu) {
  bool ok = false;
  std::thread([&] {
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(cpu, &one);
    ok = pthread_setaffinity_np(pthread_self(), sizeof(one), &one) == 0;
  }).join();
  return ok;
}

}  // namespace vtrack::testing
