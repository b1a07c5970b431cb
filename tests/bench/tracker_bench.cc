// The tracker's time per scan (Tracker::AddScan with the pose already there: preprocessing,
// segmentation, association, fitting, filters, report), at steady state, on
//  - a real KITTI HDL-64E frame sequence (../shared/data/kitti_tracking_0000; skipped with a
//    message if absent): 98k-124k returns per scan;
//  - the simulator's `stress` scenario (64-layer sensor, a large busy scene);
//  - the single-plane paper_fig4_turn scenario.
// Each iteration processes the next scan of the sequence; the tracker is rebuilt and warmed up
// (untimed) when the sequence runs out. Run with --benchmark_repetitions=N for medians.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "sensor_driver/kitti/kitti_sequence.h"
#include "sensor_driver/sim/scenario.h"
#include "sensor_driver/sim/simulator.h"
#include "tracker/config.h"
#include "tracker/core/tracker.h"
#include "tracker/lcm_convert.h"

namespace {

namespace fs = std::filesystem;
using namespace vtrack;

struct Sequence {
  std::vector<LadarScan> scans;
  std::vector<std::vector<EgoPose>> poses_before;  // poses to feed before scan i (through its end)
  std::string error;
};

TrackerParams Params() {
  const std::string path = VTRACK_SOURCE_DIR "/config/tracker.yaml";
  return fs::exists(path) ? LoadTrackerParams(path) : TrackerParams{};
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

const Sequence& Kitti() {
  static const Sequence seq = [] {
    Sequence s;
    const char* d = std::getenv("VTRACK_DATA_DIR");
    const std::string dir = (d && *d ? std::string(d) : std::string(VTRACK_SOURCE_DIR "/../shared/data")) +
                            "/kitti_tracking_0000";
    if (!fs::is_directory(dir)) {
      s.error = "KITTI data absent (" + dir + ")";
      return s;
    }
    kitti::SequenceOptions o;
    o.dir = dir;
    o.cache_dir = VTRACK_BINARY_DIR "/kitti_cache";
    const kitti::Sequence k(o);
    // Frames 1..40: the poses (interpolated at 100 Hz) start at frame 0's time, after the start
    // of frame 0's sweep.
    const int n = std::min(k.num_frames() - 1, 41);
    for (int i = 1; i < n; ++i) s.scans.push_back(ScanFromLcm(k.Scan(i)));
    AddPoses(&s, k.FrameUtime(0), 10000, [&](std::int64_t t) {
      return PoseFromLcm(k.PoseAt(std::min(t, k.FrameUtime(n))));
    });
    return s;
  }();
  return seq;
}

const Sequence& Scenario(const std::string& name, int num_scans) {
  static std::map<std::string, Sequence> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  Sequence s;
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

// Times Tracker::AddScan of each scan after a warm-up of `warmup` scans.
void RunSequence(benchmark::State& state, const Sequence& seq, int warmup) {
  if (!seq.error.empty()) {
    state.SkipWithError(seq.error.c_str());
    return;
  }
  if (static_cast<int>(seq.scans.size()) <= warmup + 1) {
    state.SkipWithError("sequence too short");
    return;
  }
  const TrackerParams params = Params();
  std::unique_ptr<Tracker> tracker;
  std::size_t i = seq.scans.size();
  std::vector<ScanOutput> out;
  std::int64_t points = 0, tracks = 0;
  for (auto _ : state) {
    state.PauseTiming();
    if (i >= seq.scans.size()) {
      tracker = std::make_unique<Tracker>(params);
      for (i = 0; i < static_cast<std::size_t>(warmup); ++i) {
        for (const auto& p : seq.poses_before[i]) tracker->AddPose(p, &out);
        LadarScan copy = seq.scans[i];
        tracker->AddScan(std::move(copy), &out);
      }
    }
    for (const auto& p : seq.poses_before[i]) tracker->AddPose(p, &out);
    LadarScan copy = seq.scans[i];
    points += static_cast<std::int64_t>(copy.size());
    out.clear();
    state.ResumeTiming();
    tracker->AddScan(std::move(copy), &out);  // processed here: its poses are in
    state.PauseTiming();
    if (out.size() != 1) state.SkipWithError("scan was not processed");
    if (!out.empty()) tracks += static_cast<std::int64_t>(out.back().tracks.size());
    ++i;
    state.ResumeTiming();
  }
  state.counters["points/scan"] = benchmark::Counter(static_cast<double>(points), benchmark::Counter::kAvgIterations);
  state.counters["tracks/scan"] = benchmark::Counter(static_cast<double>(tracks), benchmark::Counter::kAvgIterations);
}

void BM_TrackerScan_Kitti(benchmark::State& state) { RunSequence(state, Kitti(), 10); }
void BM_TrackerScan_Stress(benchmark::State& state) { RunSequence(state, Scenario("stress", 40), 10); }
void BM_TrackerScan_Fig4(benchmark::State& state) { RunSequence(state, Scenario("paper_fig4_turn", 200), 50); }

BENCHMARK(BM_TrackerScan_Kitti)->Unit(benchmark::kMillisecond)->Iterations(30);
BENCHMARK(BM_TrackerScan_Stress)->Unit(benchmark::kMillisecond)->Iterations(30);
BENCHMARK(BM_TrackerScan_Fig4)->Unit(benchmark::kMicrosecond)->Iterations(150);

}  // namespace

BENCHMARK_MAIN();
