// Writes a seed corpus for the decoder fuzzers: encoded random messages of each type (bodies
// without the fingerprint, which the harness prepends), small and large.
//   usage: vtrack_fuzz_seeds OUT_DIR
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/lcmtypes/random_messages.h"

namespace {
template <class T>
void Write(const std::filesystem::path& dir, const std::string& name, const T& m) {
  const auto bytes = vtrack::testing::Encode(m);
  std::filesystem::create_directories(dir);
  std::ofstream f(dir / name, std::ios::binary);
  f.write(reinterpret_cast<const char*>(bytes.data()) + 8, static_cast<std::streamsize>(bytes.size() - 8));
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR\n", argv[0]);
    return 2;
  }
  const std::filesystem::path out(argv[1]);
  vtrack::testing::RandomMessages r(2024);
  for (int i = 0; i < 4; ++i) {
    const std::string n = "seed" + std::to_string(i);
    Write(out / "pose_t", n, r.Pose());
    Write(out / "ladar_scan_t", n, r.Scan(i * 7));
    Write(out / "object_list_t", n, r.ObjectList(i));
    Write(out / "track_list_t", n, r.TrackList(i));
    Write(out / "track_debug_t", n, r.Debug(i));
    Write(out / "tracker_status_t", n, r.Status());
  }
  return 0;
}
