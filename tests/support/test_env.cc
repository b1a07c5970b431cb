#include "tests/support/test_env.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>

namespace vtrack::testing {
namespace {
std::string Env(const char* name, const std::string& fallback) {
  const char* v = std::getenv(name);
  return (v && *v) ? std::string(v) : fallback;
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
