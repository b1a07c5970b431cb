// Writes a seed corpus for the decoder fuzzers: encoded random messages of each type (bodies
// without the fingerprint, which the harness prepends), small and large.
//   usage: vtrack_fuzz_seeds OUT_DIR
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "lcmtypes/util/ladar_slices.h"
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

// One event of an LCM log file (lcm-logger format): big-endian header of sync word, event number,
// timestamp, channel and data lengths, then the channel and the data.
void AppendEvent(std::vector<std::uint8_t>* log, std::int64_t eventnum, std::int64_t utime,
                 const std::string& channel, const std::vector<std::uint8_t>& data) {
  auto put = [&](std::uint64_t v, int n) {
    for (int i = n - 1; i >= 0; --i) log->push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  };
  put(0xEDA1DA01u, 4);
  put(static_cast<std::uint64_t>(eventnum), 8);
  put(static_cast<std::uint64_t>(utime), 8);
  put(channel.size(), 4);
  put(data.size(), 4);
  log->insert(log->end(), channel.begin(), channel.end());
  log->insert(log->end(), data.begin(), data.end());
}

// Log-reader seeds: a small whole log of poses and a scan, and the kinds of damage the reader
// skips (garbage between events, an impossible length, a cut last event, a lone sync word).
void WriteLogSeeds(const std::filesystem::path& dir, vtrack::testing::RandomMessages* r) {
  std::vector<std::uint8_t> whole;
  std::int64_t n = 0;
  for (int i = 0; i < 3; ++i) {
    AppendEvent(&whole, n++, 1'700'000'000'000'000 + i * 10'000, "EGO_POSE", vtrack::testing::Encode(r->Pose()));
  }
  AppendEvent(&whole, n++, 1'700'000'000'030'000, "LADAR_SCAN", vtrack::testing::Encode(r->Scan(3)));
  AppendEvent(&whole, n++, 1'700'000'000'040'000, "EMPTY", {});
  WriteBytes(dir, "whole", whole);
  std::vector<std::uint8_t> garbage = whole;
  const std::uint8_t junk[] = {0xED, 0xA1, 0xDA, 0x01, 0x00, 0x13, 0x37, 0xff, 0xff};
  garbage.insert(garbage.begin() + 40, junk, junk + sizeof(junk));
  WriteBytes(dir, "garbage_between_events", garbage);
  std::vector<std::uint8_t> inflated = whole;
  inflated[24] = 0x7f;  // the first event's data length ~2^31
  WriteBytes(dir, "impossible_length", inflated);
  WriteBytes(dir, "cut_last_event", std::vector<std::uint8_t>(whole.begin(), whole.end() - 7));
  WriteBytes(dir, "lone_sync_word", {0xED, 0xA1, 0xDA, 0x01});
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
    Write(out / "ladar_slice_t", n, vtrack::lcm_util::SliceSweep(r.Scan(8 + i * 7), 2)[0]);
  }
  WriteLogSeeds(out / "log_reader", &r);
  WriteBytes(out / "tracker", "mht_plane", TrackerProgram(0, 1, 0));
  WriteBytes(out / "tracker", "ism_cloud", TrackerProgram(1, 16, 0));
  WriteBytes(out / "tracker", "vasm_plane", TrackerProgram(2, 1, 0));
  WriteBytes(out / "tracker", "cv_plane", TrackerProgram(3, 1, 0));
  WriteBytes(out / "tracker", "mht_plane_bad_returns", TrackerProgram(0, 1, 3));
  WriteBytes(out / "tracker", "mht_cloud_bad_returns", TrackerProgram(0, 16, 2));
  return 0;
}
