#include "tests/support/test_env.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <string>
#include <system_error>
#include <vector>

namespace vtrack::testing {
namespace {
std::string Env(const char* name, const std::string& fallback) {
  const char* v = std::getenv(name);
  return (v && *v) ? std::string(v) : fallback;
}

// The scratch directories of this test process, removed when it exits if every test passed
// (some hold logs of hundreds of MB; left behind, repeated runs fill the disk), kept and named
// when one failed. Only the process that made them removes them: a forked child that exits
// normally runs this destructor too.
class ScratchRegistry {
 public:
  ~ScratchRegistry() {
    if (::getpid() != owner_) return;
    const bool passed = ::testing::UnitTest::GetInstance()->Passed();
    for (const std::string& d : dirs_) {
      if (passed) {
        std::error_code ec;
        std::filesystem::remove_all(d, ec);
      } else {
        std::fprintf(stderr, "scratch directory kept for inspection: %s\n", d.c_str());
      }
    }
  }
  void Add(const std::string& dir) {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (const std::string& d : dirs_) {
      if (d == dir) return;
    }
    dirs_.push_back(dir);
  }

 private:
  const pid_t owner_ = ::getpid();
  std::mutex mutex_;
  std::vector<std::string> dirs_;
};

ScratchRegistry& Scratch() {
  // Made after gtest's UnitTest (ScratchDir runs inside tests), so destroyed before it.
  static ScratchRegistry registry;
  return registry;
}
}  // namespace

std::string SourceDir() { return Env("VTRACK_SOURCE_DIR", "."); }
std::string BinDir() { return Env("VTRACK_BIN_DIR", "./bin"); }
std::string DataDir() { return Env("VTRACK_DATA_DIR", SourceDir() + "/../shared/data"); }
std::string JarPath() { return Env("VTRACK_JAR", ""); }

std::string ScratchDir(const std::string& name) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() /
                       ("vtrack-test-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  Scratch().Add(dir.string());
  return dir.string();
}

std::string KittiDir() {
  const std::string d = DataDir() + "/kitti_tracking_0000";
  return std::filesystem::is_directory(d) ? d : std::string();
}

double LiveRate() {
  if (const char* v = std::getenv("VTRACK_LIVE_RATE"); v != nullptr && *v != '\0') {
    char* end = nullptr;
    const double r = std::strtod(v, &end);
    if (end != v && *end == '\0' && r > 0.0 && r <= 1.0) return r;
    ADD_FAILURE() << "VTRACK_LIVE_RATE = '" << v << "': must be a number in (0, 1]";
  }
  return kSanitizedBuild ? 0.2 : 1.0;
}

}  // namespace vtrack::testing
