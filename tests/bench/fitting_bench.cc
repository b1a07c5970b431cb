// Robust edge / corner fitting (paper Section 2.4) of one segment: time per Fit for clusters of
// 50 to 2000 points, an L-shape (two faces seen) and a single edge (rear face only), 10 %
// spurious returns, shape known and a predicted heading (a confirmed track's case) or a new
// object. The 500-point L-shape is the figure quoted in tracker/core/README.md.
//
//   build/bench/fitting_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "tests/tracker/core/synthetic_scan.h"
#include "base/angle.h"
#include "tracker/core/fitting.h"

namespace vtrack {
namespace {

// A scan of `truth` from the origin with about `points` returns: the beam step is the box's
// bearing span divided by the wanted count.
testing::SyntheticScan ScanWithPoints(const OrientedBox& truth, int points, std::uint32_t seed) {
  double lo = INFINITY, hi = -INFINITY;
  for (const Eigen::Vector2d& c : truth.Corners()) {
    const double b = std::atan2(c.y(), c.x());
    lo = std::min(lo, b);
    hi = std::max(hi, b);
  }
  testing::ScanSpec spec;
  spec.truth = truth;
  spec.range_sigma_m = 0.03;
  spec.outlier_fraction = 0.1;
  spec.outlier_kind = testing::OutlierKind::kSpurious;
  spec.angular_step_rad = (hi - lo) / points;
  std::mt19937 rng(seed);
  return testing::MakeScan(spec, rng);
}

FitRequest Request(const testing::SyntheticScan& scan, const OrientedBox& truth, bool track) {
  FitRequest req;
  req.x = scan.x;
  req.y = scan.y;
  req.length_m = truth.length;
  req.width_m = truth.width;
  req.shape_known = track;
  if (track) req.predicted_theta = truth.theta + DegToRad(3.0);
  req.range_sigma_m = 0.03;
  req.min_inside_fraction = 0.5;
  req.seed = 7;
  return req;
}

void Run(benchmark::State& state, const OrientedBox& truth, bool track) {
  const testing::SyntheticScan scan = ScanWithPoints(truth, static_cast<int>(state.range(0)), 11);
  const FitRequest req = Request(scan, truth, track);
  SegmentFitter fitter;
  FitResult fit;
  fitter.Fit(req, &fit);
  if (fit.kind == FitKind::kNone) {
    state.SkipWithError(ToString(fit.failure));
    return;
  }
  for (auto _ : state) {
    fitter.Fit(req, &fit);
    benchmark::DoNotOptimize(fit.z);
  }
  state.counters["points"] = static_cast<double>(scan.size());
  state.counters["kind"] = static_cast<double>(fit.kind);
}

// Rear-left corner towards the sensor: left and rear faces seen (an L).
const OrientedBox kLShape{{9.0, -3.0}, DegToRad(30.0), 4.6, 1.9};
// Straight ahead: only the rear face.
const OrientedBox kRearOnly{{12.0, 0.3}, DegToRad(1.0), 4.6, 1.9};

void BM_FitLShapeTrack(benchmark::State& s) { Run(s, kLShape, true); }
void BM_FitLShapeNewObject(benchmark::State& s) { Run(s, kLShape, false); }
void BM_FitSingleEdgeTrack(benchmark::State& s) { Run(s, kRearOnly, true); }

BENCHMARK(BM_FitLShapeTrack)->Arg(50)->Arg(100)->Arg(500)->Arg(2000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FitLShapeNewObject)->Arg(500)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FitSingleEdgeTrack)->Arg(100)->Arg(500)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace vtrack

BENCHMARK_MAIN();
