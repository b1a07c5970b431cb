// The tracker's stages one by one on the real KITTI sequence 0000 (frames 11-40, shipped
// configuration), each iteration one scan (time per scan):
//  - BM_Compensation: per-return ego-motion compensation and range checks (ground: none);
//  - BM_CompensationGround: the same plus the grid ground removal (the tracker's preprocessing);
//  - BM_Segmentation: grid connected components of the preprocessed returns;
//  - BM_Association: prediction of every track to mid-sweep + association (gates, visible faces,
//    split, Hungarian per component, merge) with the tracks of a tracker run up to that scan;
//  - BM_RangeProfile: the per-ring range profile of the preprocessed returns (free space beyond a
//    face's end, for the fit);
//  - BM_Outlines: the outline of every track's associated returns and of every new object (the
//    returns the fit sees), from that scan's association;
//  - BM_HypothesisManagement: TrackManager::EndScan (confirmation, coasting, deletion,
//    duplicates) + Report (selected hypothesis of every track predicted, planner trajectory),
//    0.1 s after the scan, on a copy of the tracker's track manager after that scan.
// Per-track fitting is in fitting_bench, EKF predict + update per model in models_bench.
//
//   build/bench/stages_bench
#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>
#include <vector>

#include "tests/bench/bench_data.h"

namespace {

using namespace vtrack;

// Per scan: the tracker's state just before it (predictions) and just after its updates.
struct StageInput {
  const LadarScan* scan = nullptr;
  WorldPoints points;
  Segments segments;
  Eigen::Vector2d sensor_xy;
  std::vector<PredictedObject> predicted;
  AssociationResult association;        // of predicted with segments
  std::unique_ptr<TrackManager> after;  // copy of the manager after the scan
};

struct Inputs {
  std::unique_ptr<Tracker> tracker;  // owns the Ekf the manager copies refer to
  std::vector<StageInput> frames;
  PoseHistory poses;
  std::string error;
};

const Inputs& GetInputs() {
  static const Inputs in = [] {
    Inputs r;
    const bench::Sequence& seq = bench::Kitti();
    if (!seq.error.empty()) {
      r.error = seq.error;
      return r;
    }
    const TrackerParams params = bench::ShippedParams();
    r.poses = bench::AllPoses(seq);
    r.tracker = std::make_unique<Tracker>(params);
    Preprocessor pre(params.preprocess);
    Segmenter seg(params.segmentation);
    Associator assoc(params.association);
    std::vector<ScanOutput> out;
    const std::size_t last = std::min<std::size_t>(40, seq.scans.size());
    for (std::size_t i = 0; i < last; ++i) {
      for (const auto& p : seq.poses_before[i]) r.tracker->AddPose(p, &out);
      if (i >= 10) {
        StageInput f;
        f.scan = &seq.scans[i];
        f.sensor_xy = pre.Run(seq.scans[i], r.poses, 0, &f.points).sensor_xy;
        seg.Run(f.points, false, f.sensor_xy, &f.segments);
        r.tracker->manager().Predict(seq.scans[i].utime + seq.scans[i].sweep_duration_us / 2,
                                     &f.predicted);
        assoc.Run(f.predicted, f.points, f.segments, f.sensor_xy, &f.association);
        r.frames.push_back(std::move(f));
      }
      LadarScan copy = seq.scans[i];
      r.tracker->AddScan(std::move(copy), &out);
      if (i >= 10) r.frames.back().after = std::make_unique<TrackManager>(r.tracker->manager());
    }
    return r;
  }();
  return in;
}

template <class Body>
void ForEachScan(benchmark::State& state, Body body) {
  const Inputs& in = GetInputs();
  if (!in.error.empty()) {
    state.SkipWithError(in.error.c_str());
    return;
  }
  std::size_t i = 0;
  for (auto _ : state) {
    body(in, in.frames[i]);
    i = (i + 1) % in.frames.size();
  }
}

// ForEachScan whose body returns a count: the counter `name` is its mean per iteration.
template <class Body>
void ForEachScanCounting(benchmark::State& state, const char* name, Body body) {
  double total = 0;
  ForEachScan(state, [&](const Inputs& in, const StageInput& f) { total += body(in, f); });
  state.counters[name] = benchmark::Counter(total, benchmark::Counter::kAvgIterations);
}

void Preprocess(benchmark::State& state, PreprocessParams::Ground ground) {
  PreprocessParams p = bench::ShippedParams().preprocess;
  p.ground = ground;
  Preprocessor pre(p);
  WorldPoints out;
  ForEachScanCounting(state, "kept", [&](const Inputs& in, const StageInput& f) {
    pre.Run(*f.scan, in.poses, 0, &out);
    return static_cast<double>(out.size());
  });
}
void BM_Compensation(benchmark::State& state) { Preprocess(state, PreprocessParams::Ground::kNone); }
void BM_CompensationGround(benchmark::State& state) { Preprocess(state, PreprocessParams::Ground::kGrid); }
BENCHMARK(BM_Compensation)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CompensationGround)->Unit(benchmark::kMillisecond);

void BM_Segmentation(benchmark::State& state) {
  Segmenter seg(bench::ShippedParams().segmentation);
  Segments out;
  ForEachScanCounting(state, "segments", [&](const Inputs&, const StageInput& f) {
    seg.Run(f.points, false, f.sensor_xy, &out);
    return static_cast<double>(out.segments.size());
  });
}
BENCHMARK(BM_Segmentation)->Unit(benchmark::kMillisecond);

void BM_Association(benchmark::State& state) {
  Associator assoc(bench::ShippedParams().association);
  AssociationResult out;
  ForEachScanCounting(state, "tracks", [&](const Inputs&, const StageInput& f) {
    assoc.Run(f.predicted, f.points, f.segments, f.sensor_xy, &out);
    return static_cast<double>(f.predicted.size());
  });
}
BENCHMARK(BM_Association)->Unit(benchmark::kMillisecond);

void BM_RangeProfile(benchmark::State& state) {
  const double bin_deg = std::max(kMinRangeProfileBinDeg, bench::ShippedParams().outline.bin_deg);
  RangeProfile profile;
  ForEachScanCounting(state, "returns", [&](const Inputs&, const StageInput& f) {
    profile.Build(f.sensor_xy, f.points.x, f.points.y, f.points.ring, bin_deg);
    return static_cast<double>(f.points.size());
  });
}
BENCHMARK(BM_RangeProfile)->Unit(benchmark::kMillisecond);

void BM_Outlines(benchmark::State& state) {
  OutlineExtractor outline(bench::ShippedParams().outline);
  PointSet ps;
  ForEachScanCounting(state, "outlines", [&](const Inputs&, const StageInput& f) {
    int n = 0;
    for (const auto* lists : {&f.association.track_points, &f.association.new_objects}) {
      for (const auto& idx : *lists) {
        if (idx.empty()) continue;
        outline.Extract(f.points, idx, *f.scan, f.sensor_xy, &ps);
        ++n;
      }
    }
    return static_cast<double>(n);
  });
}
BENCHMARK(BM_Outlines)->Unit(benchmark::kMillisecond);

void BM_HypothesisManagement(benchmark::State& state) {
  std::vector<TrackReport> reports;
  ForEachScanCounting(state, "tracks", [&](const Inputs&, const StageInput& f) {
    state.PauseTiming();
    TrackManager m(*f.after);
    state.ResumeTiming();
    m.EndScan(f.scan->utime + 100'000);
    m.Report(f.scan->utime + 100'000, &reports);
    return static_cast<double>(reports.size());
  });
}
BENCHMARK(BM_HypothesisManagement)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
