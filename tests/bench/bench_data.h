// Input shared by the tracker benchmarks: scan sequences with the ego poses each scan needs, read
// once per program and kept in memory (so that no file or simulator time is measured).
//  - Kitti(): frames 1..100 of the real KITTI sequence 0000 (../shared/data, or $VTRACK_DATA_DIR;
//    98k-124k returns per HDL-64E scan). Absent data gives a Sequence with `error` set.
//  - Scenario(name, n): the first n scans of a simulator scenario (e.g. "stress": 64 layers, a
//    dense avenue with ~300 vehicles).
// Needs VTRACK_SOURCE_DIR and VTRACK_BINARY_DIR defined by the build (tests/bench/CMakeLists.txt).
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "sensor_driver/kitti/kitti_sequence.h"
#include "sensor_driver/sim/scenario.h"
#include "sensor_driver/sim/simulator.h"
#include "tracker/config.h"
#include "base/pose.h"
#include "tracker/core/tracker.h"
#include "tracker/lcm_convert.h"

namespace vtrack::bench {

struct Sequence {
  std::vector<LadarScan> scans;
  std::vector<std::vector<EgoPose>> poses_before;  // poses to feed before scan i (through its end)
  std::string error;
  std::string name;
};

// The shipped configuration (the defaults of the Params structs if the file is missing).
inline TrackerParams ShippedParams() {
  const std::string path = VTRACK_SOURCE_DIR "/config/tracker.yaml";
  return std::filesystem::exists(path) ? LoadTrackerParams(path) : TrackerParams{};
}

inline std::string KittiDir() {
  const char* d = std::getenv("VTRACK_DATA_DIR");
  return (d && *d ? std::string(d) : std::string(VTRACK_SOURCE_DIR "/../shared/data")) +
         "/kitti_tracking_0000";
}

// Poses up to each scan's end, from a pose function sampled every pose_dt_us.
template <class PoseAt>
void AddPoses(Sequence* s, std::int64_t first, std::int64_t pose_dt_us, PoseAt pose_at) {
  std::int64_t next = first;
  for (const LadarScan& scan : s->scans) {
    std::vector<EgoPose> v;
    while (next <= scan.end_utime() + pose_dt_us) {
      v.push_back(pose_at(next));
      next += pose_dt_us;
    }
    s->poses_before.push_back(std::move(v));
  }
}

inline const Sequence& Kitti() {
  static const Sequence seq = [] {
    Sequence s;
    s.name = "kitti_0000";
    const std::string dir = KittiDir();
    if (!std::filesystem::is_directory(dir)) {
      s.error = "KITTI data absent (" + dir + ")";
      return s;
    }
    try {
      kitti::SequenceOptions o;
      o.dir = dir;
      o.cache_dir = VTRACK_BINARY_DIR "/kitti_cache";
      const kitti::Sequence k(o);
      // Frames 1..100: the poses (interpolated at 100 Hz) start at frame 0's time, after the
      // start of frame 0's sweep.
      const int n = std::min(k.num_frames() - 1, 101);
      for (int i = 1; i < n; ++i) s.scans.push_back(ScanFromLcm(k.Scan(i)));
      AddPoses(&s, k.FrameUtime(0), 10000, [&](std::int64_t t) {
        return PoseFromLcm(k.PoseAt(std::min(t, k.FrameUtime(n))));
      });
    } catch (const std::exception& e) {
      s.error = e.what();
    }
    return s;
  }();
  return seq;
}

inline const Sequence& Scenario(const std::string& name, int num_scans) {
  static std::map<std::string, Sequence> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  Sequence s;
  s.name = name;
  try {
    sim::Simulator simu(sim::LoadScenario(sim::ResolveScenarioPath(name)));
    const std::int64_t start = 1'700'000'000'000'000;
    const int n = std::min(simu.NumScans(), num_scans);
    for (int i = 0; i < n; ++i) {
      ladar_scan_t msg;
      object_list_t truth;
      simu.MakeScan(i, start, i, &msg, &truth);
      s.scans.push_back(ScanFromLcm(std::move(msg)));
    }
    int k = 0;
    for (const LadarScan& scan : s.scans) {
      std::vector<EgoPose> v;
      while (k < simu.NumPoses() && start + simu.PoseOffsetUs(k) <= scan.end_utime() + 20000) {
        pose_t p;
        simu.MakePose(k++, start, &p);
        v.push_back(PoseFromLcm(p));
      }
      s.poses_before.push_back(std::move(v));
    }
  } catch (const std::exception& e) {
    s.error = e.what();
  }
  return cache.emplace(name, std::move(s)).first->second;
}

// Every pose of the sequence in one history (for running single stages on any of its scans).
inline PoseHistory AllPoses(const Sequence& seq) {
  PoseHistory h(3'600'000'000);
  for (const auto& v : seq.poses_before) {
    for (const EgoPose& p : v) h.Add(p.utime, p.world_from_body);
  }
  return h;
}

// Percentile (0..100) of a sample by linear interpolation between order statistics.
inline double Percentile(std::vector<double> v, double pct) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = pct / 100.0 * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(pos);
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

}  // namespace vtrack::bench
