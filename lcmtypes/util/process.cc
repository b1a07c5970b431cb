#include "lcmtypes/util/process.h"

#include <malloc.h>
#include <sys/select.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <string>
#include <stdexcept>

namespace vtrack::lcm_util {
namespace {
std::atomic<bool> g_stop{false};
extern "C" void OnStopSignal(int) { g_stop.store(true); }
}  // namespace

void InstallStopHandlers() {
  struct sigaction sa {};
  sa.sa_handler = OnStopSignal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

bool StopRequested() { return g_stop.load(); }
void RequestStop() { g_stop.store(true); }

std::unique_ptr<lcm::LCM> OpenLcm(const std::string& url) {
  auto lcm = std::make_unique<lcm::LCM>(url);
  if (!lcm->good()) {
    // The likely cause by provider: a udpm:// bus needs a multicast route; other providers,
    // a URL LCM can open (memq://, file://PATH?mode=r|w with a readable or writable PATH).
    const bool udpm = url.empty() || url.rfind("udpm://", 0) == 0;
    throw std::runtime_error(
        "cannot open LCM at '" + (url.empty() ? "<default>" : url) + "' (" +
        (udpm ? "no multicast route? see README: private network namespace"
              : "LCM's providers are udpm://, memq:// and file://PATH?mode=r|w; for file://, the "
                "file must be readable (mode=r) or its folder writable (mode=w)") +
        ")");
  }
  return lcm;
}

bool HandleUntilStopped(lcm::LCM& lcm, std::chrono::steady_clock::time_point deadline) {
  const bool has_deadline = deadline != std::chrono::steady_clock::time_point{};
  while (!StopRequested()) {
    if (has_deadline && std::chrono::steady_clock::now() >= deadline) break;
    // handleTimeout lets the loop notice the stop flag at least every 100 ms.
    if (lcm.handleTimeout(100) < 0) return false;
  }
  return true;
}

bool InPrivateLoopbackNamespace() {
  // /proc/self/net/dev lists the interfaces of this process's network namespace (/sys/class/net
  // would show the namespace that mounted sysfs, i.e. the host's).
  std::ifstream dev("/proc/self/net/dev");
  if (!dev) return false;
  std::string line;
  int count = 0;
  bool has_lo = false;
  int lineno = 0;
  while (std::getline(dev, line)) {
    if (++lineno <= 2) continue;  // two header lines
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const auto first = line.find_first_not_of(' ');
    const std::string name = line.substr(first, colon - first);
    ++count;
    if (name == "lo") has_lo = true;
  }
  return has_lo && count == 1;
}

std::int64_t WallUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

void RateLimitedLog::Warn(const std::string& key, const std::string& message) {
  auto& e = entries_[key];
  const auto now = std::chrono::steady_clock::now();
  if (e.printed && now - e.last < interval_) {
    ++e.suppressed;
    return;
  }
  if (e.suppressed > 0) {
    std::fprintf(stderr, "%s: %s (%lld similar suppressed)\n", prefix_.c_str(), message.c_str(),
                 static_cast<long long>(e.suppressed));
  } else {
    std::fprintf(stderr, "%s: %s\n", prefix_.c_str(), message.c_str());
  }
  e.printed = true;
  e.last = now;
  e.suppressed = 0;
}

bool KeepFreedMemory() {
  const bool threshold = mallopt(M_MMAP_THRESHOLD, 32 << 20) == 1;  // [bytes] glibc's largest on 64-bit
  const bool trim = mallopt(M_TRIM_THRESHOLD, 256 << 20) == 1;      // [bytes]
  return threshold && trim;
}

}  // namespace vtrack::lcm_util
