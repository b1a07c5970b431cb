// Writes a seed corpus for the decoder fuzzers: encoded random messages of each type (bodies
// without the fingerprint, which the harness prepends), small and large.
//   usage: vtrack_fuzz_seeds OUT_DIR
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/fuzz/tracker_program.h"
#include "tests/lcmtypes/random_messages.h"

namespace {
template <class T>
void Write(const std::filesystem::path& dir, const std::string& name, const T& m) {
  const auto bytes = vtrack::testing::Encode(m);
  std::filesystem::create_directories(dir);
  std::ofstream f(dir / name, std::ios::binary);
  f.write(reinterpret_cast<const char*>(bytes.data()) + 8, static_cast<std::streamsize>(bytes.size() - 8));
}
void WriteBytes(const std::filesystem::path& dir, const std::string& name, const std::vector<std::uint8_t>& b) {
  std::filesystem::create_directories(dir);
  std::ofstream f(dir / name, std::ios::binary);
  f.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

// A tracker-fuzzer program (tests/fuzz/tracker_program.h): a parked and a moving box, the ego
// driving at 5 m/s, a pose every 50 ms and a 100 ms sweep every other pose; `flags_every` > 0
// puts scan flag bit (i / flags_every) % 8 on every flags_every-th scan.
std::vector<std::uint8_t> TrackerProgram(int mode, int rings, int flags_every) {
  using namespace vtrack::fuzz;
  std::vector<std::uint8_t> b = {static_cast<std::uint8_t>(mode), static_cast<std::uint8_t>(rings > 1), 2};
  const std::uint8_t parked[] = {20, 8, 0, 64, 30, 0, 0};            // 10 m ahead, 4 m left
  const std::uint8_t mover[] = {0xf0, 0xf8, 0, 96, 24, 24, 10};       // behind-right, 6 m/s, turning
  b.insert(b.end(), parked, parked + 7);
  b.insert(b.end(), mover, mover + 7);
  for (int i = 0; i < kMaxOps / 2; ++i) {
    b.insert(b.end(), {kOpPose, 0x01, 0xf4, 20, 0, 0});                 // +50 ms, 5 m/s, straight
    const std::uint8_t flags = flags_every > 0 && i % flags_every == flags_every - 1
                                   ? static_cast<std::uint8_t>(1u << ((i / flags_every) % 8)) : 0;
    // Sweep from 100 ms before the pose (int16 -1000 x 100 us), seq + 1, 100 ms, 24 returns per box.
    b.insert(b.end(), {kOpScan, 0xfc, 0x18, 1, 100, 24, flags, static_cast<std::uint8_t>(7 * i), 0});
  }
  return b;
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
    Write(out / "detection_list_t", n, r.DetectionList(i * 3));
    Write(out / "detection_t", n, r.Detection());
  }
  WriteBytes(out / "tracker", "mht_plane", TrackerProgram(0, 1, 0));
  WriteBytes(out / "tracker", "ism_cloud", TrackerProgram(1, 16, 0));
  WriteBytes(out / "tracker", "vasm_plane", TrackerProgram(2, 1, 0));
  WriteBytes(out / "tracker", "cv_plane", TrackerProgram(3, 1, 0));
  WriteBytes(out / "tracker", "mht_plane_bad_returns", TrackerProgram(0, 1, 3));
  WriteBytes(out / "tracker", "mht_cloud_bad_returns", TrackerProgram(0, 16, 2));
  return 0;
}
