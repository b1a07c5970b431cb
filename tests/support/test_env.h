// Paths and guards shared by the tests (set by tests/CMakeLists.txt through the environment).
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "lcmtypes/util/process.h"

namespace vtrack::testing {

std::string SourceDir();   // repository root
std::string BinDir();      // built executables
std::string DataDir();     // ../shared/data (may not exist)
std::string JarPath();     // the message types' jar, "" if not built
// A fresh empty directory under the system temp dir (named after name and the process), removed
// when the test process exits if every test passed, kept for inspection if one failed.
std::string ScratchDir(const std::string& name);
// The KITTI tracking sequence 0000 directory if present, else "".
std::string KittiDir();

// True when this build is instrumented with AddressSanitizer (CI's sanitizer tree): its programs
// run several times slower, so tests that feed a live process in real time slow the feed down.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitizedBuild = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kSanitizedBuild = true;
#else
inline constexpr bool kSanitizedBuild = false;
#endif
#else
inline constexpr bool kSanitizedBuild = false;
#endif

// The pace at which live tests publish data too heavy for a slow build in real time (64-layer
// scans), in data seconds per wall second (the live processes' --rate): $VTRACK_LIVE_RATE if set
// (a slow machine), else 1 (real time), or 1/5 in a sanitized build. The data, and so every
// assertion on them, are the same at any pace.
double LiveRate();

}  // namespace vtrack::testing

// Refuses to open udpm:// outside a private loopback-only network namespace: multicast must never
// leave the machine. ctest runs such tests through scripts/vtrack-netns.
#define VTRACK_REQUIRE_PRIVATE_NETNS()                                                    \
  do {                                                                                    \
    if (!::vtrack::lcm_util::InPrivateLoopbackNamespace()) {                              \
      GTEST_SKIP() << "not in a private loopback-only network namespace; run through "    \
                      "scripts/vtrack-netns (ctest does) so multicast stays on this machine"; \
    }                                                                                     \
  } while (0)
