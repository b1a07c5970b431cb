// Small pieces every vtrack process needs: clean stop on SIGINT/SIGTERM, an LCM handle that is
// checked, a loop that handles messages until stopped, and warnings limited in rate.
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <string>

namespace vtrack::lcm_util {

// Installs SIGINT/SIGTERM handlers that set a flag (and nothing else: async-signal-safe).
void InstallStopHandlers();
bool StopRequested();
void RequestStop();  // for tests and for loops that end on their own

// Opens LCM on url ("" = LCM's default, which honours $LCM_DEFAULT_URL). Throws
// std::runtime_error naming the URL if LCM cannot be initialised.
std::unique_ptr<lcm::LCM> OpenLcm(const std::string& url);

// Handles messages until StopRequested() or until deadline (if not zero). Returns false if
// lcm.handle reported an error.
bool HandleUntilStopped(lcm::LCM& lcm, std::chrono::steady_clock::time_point deadline = {});

// True if this process is in a network namespace whose only interface is loopback: where udpm://
// traffic cannot leave the machine. Tests that open udpm:// refuse to run otherwise.
bool InPrivateLoopbackNamespace();

// Wall clock in microseconds since the Unix epoch (for latency and status, never for estimation).
std::int64_t WallUtime();

// Keeps the memory the process frees for its next allocations (glibc mallopt): blocks up to
// 32 MB come from the heap instead of fresh mappings, and up to 256 MB of free memory stays at the
// heap's top. With glibc's defaults a block of 128 KB or more is first mapped afresh, the
// threshold then rises to the largest block freed, and the heap's top is given back once twice
// that is free, so a sweep's arrays (0.5 MB each) keep faulting in fresh pages; on a virtual
// machine that made a sweep put together from its slices ready 3-4 ms after its last slice,
// against under 1 ms with the pages kept (docs/speed.md). The resident size stays at
// its peak instead of falling back. Returns false if glibc refused either setting.
bool KeepFreedMemory();

// Prints "<prefix>: <message>" to stderr at most once per interval per key, and says how many
// were suppressed in between. Bad sensor input is reported through this.
class RateLimitedLog {
 public:
  explicit RateLimitedLog(std::string prefix, double interval_s = 1.0)
      : prefix_(std::move(prefix)), interval_(interval_s) {}
  void Warn(const std::string& key, const std::string& message);

 private:
  struct Entry {
    std::chrono::steady_clock::time_point last{};
    std::int64_t suppressed = 0;
    bool printed = false;
  };
  std::string prefix_;
  std::chrono::duration<double> interval_;
  std::map<std::string, Entry> entries_;
};

}  // namespace vtrack::lcm_util
