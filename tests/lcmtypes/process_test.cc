// KeepFreedMemory (lcmtypes/util/process.h) against the kernel's own count of page faults: a
// block of a sweep's size, freed and taken again, faults its pages in afresh each time under
// glibc's mapping of large blocks, and not once they are kept.
#include "lcmtypes/util/process.h"

#include <gtest/gtest.h>

#include <malloc.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <memory>

// AddressSanitizer and ThreadSanitizer bring their own allocator, which mallopt does not steer.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define VTRACK_SANITIZED_ALLOCATOR 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define VTRACK_SANITIZED_ALLOCATOR 1
#endif
#endif

namespace vtrack::lcm_util {
namespace {

long MinorFaults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}

// Minor page faults while taking, touching and freeing a block of `bytes` `rounds` times.
long FaultsOfRounds(std::size_t bytes, int rounds) {
  const long page = sysconf(_SC_PAGESIZE);
  const long before = MinorFaults();
  for (int r = 0; r < rounds; ++r) {
    std::unique_ptr<char[]> block(new char[bytes]);
    for (std::size_t i = 0; i < bytes; i += static_cast<std::size_t>(page)) block[i] = static_cast<char>(r);
    volatile char sink = block[bytes / 2];
    (void)sink;
  }
  return MinorFaults() - before;
}

TEST(KeepFreedMemoryTest, ABlockOfASweepsSizeFreedAndTakenAgainFaultsInNoNewPages) {
#ifdef VTRACK_SANITIZED_ALLOCATOR
  GTEST_SKIP() << "the sanitizer's allocator replaces glibc's malloc: mallopt does not apply";
#else
  constexpr std::size_t kBytes = 3u << 20;  // a KITTI sweep's six arrays together: ~2.7 MB
  constexpr int kRounds = 20;
  const long pages = static_cast<long>(kBytes) / sysconf(_SC_PAGESIZE);
  // glibc's fixed threshold for mapping a block afresh (128 KB) and for giving back the heap's
  // top: every round maps, faults in and unmaps the whole block.
  ASSERT_EQ(mallopt(M_MMAP_THRESHOLD, 128 << 10), 1);
  ASSERT_EQ(mallopt(M_TRIM_THRESHOLD, 128 << 10), 1);
  const long fresh = FaultsOfRounds(kBytes, kRounds);
  EXPECT_GE(fresh, kRounds * pages * 9 / 10) << "the control does not fault: the test would prove nothing";
  ASSERT_TRUE(KeepFreedMemory());
  FaultsOfRounds(kBytes, 1);  // the first round may still grow the heap
  const long kept = FaultsOfRounds(kBytes, kRounds);
  EXPECT_LT(kept, pages / 10) << "faults over " << kRounds << " rounds with freed memory kept, against "
                              << fresh << " without";
#endif
}

}  // namespace
}  // namespace vtrack::lcm_util
