// Cost of the motion models and the EKF step: one predict + update per model (what the tracker
// spends per hypothesis per scan), its parts, the planner's predicted trajectory, hypothesis
// conversion, and the shape histogram.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "tracker/core/ekf.h"
#include "tracker/core/shape.h"

namespace vtrack {
namespace {

// A hypothesis of a car in a turn, and a stream of measurements near its predictions.
Hypothesis TurningCar(ModelKind kind) {
  Hypothesis h;
  h.kind = kind;
  if (kind == ModelKind::kIsm) {
    h.x << 10.0, 5.0, -3.0, 2.0, 0.4, 0.3;
  } else {
    h.x << 10.0, -3.0, -1.3, 5.5, 0.4, 0.3;
  }
  h.P = Matrix6d::Identity() * 0.05;
  return h;
}

std::vector<CentreMeasurement> Measurements(const Ekf& ekf, ModelKind kind, int n) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 0.1);
  Hypothesis h = TurningCar(kind);
  std::vector<CentreMeasurement> out;
  const std::array<int, 3> idx = ekf.model(kind).PoseIndices();
  for (int i = 0; i < n; ++i) {
    ekf.Predict(0.1, 1.0, &h);
    CentreMeasurement m;
    m.z << h.x(idx[0]) + noise(rng), h.x(idx[1]) + noise(rng), h.x(idx[2]) + 0.1 * noise(rng);
    m.R = Eigen::Matrix3d::Identity() * 0.01;
    out.push_back(m);
  }
  return out;
}

void BM_PredictUpdate(benchmark::State& state, ModelKind kind) {
  const Ekf ekf;
  const std::vector<CentreMeasurement> ms = Measurements(ekf, kind, 256);
  Hypothesis h = TurningCar(kind);
  std::size_t i = 0;
  int accepted = 0;
  for (auto _ : state) {
    ekf.Predict(0.1, 1.0, &h);
    accepted += ekf.Update(ms[i], &h).accepted;
    benchmark::DoNotOptimize(h.x.data());
    if (++i == ms.size()) {
      i = 0;
      h = TurningCar(kind);
    }
  }
  state.counters["accepted"] = benchmark::Counter(accepted, benchmark::Counter::kAvgIterations);
}
BENCHMARK_CAPTURE(BM_PredictUpdate, ism, ModelKind::kIsm);
BENCHMARK_CAPTURE(BM_PredictUpdate, vasm, ModelKind::kVasm);

void BM_Predict(benchmark::State& state, ModelKind kind) {
  const Ekf ekf;
  const Hypothesis start = TurningCar(kind);
  Hypothesis h = start;
  for (auto _ : state) {
    h.x = start.x;
    ekf.Predict(0.1, 1.0, &h);
    benchmark::DoNotOptimize(h.P.data());
  }
}
BENCHMARK_CAPTURE(BM_Predict, ism, ModelKind::kIsm);
BENCHMARK_CAPTURE(BM_Predict, vasm, ModelKind::kVasm);

void BM_Update(benchmark::State& state, ModelKind kind) {
  const Ekf ekf;
  const std::vector<CentreMeasurement> ms = Measurements(ekf, kind, 1);
  Hypothesis start = TurningCar(kind);
  ekf.Predict(0.1, 1.0, &start);
  for (auto _ : state) {
    Hypothesis h = start;
    benchmark::DoNotOptimize(ekf.Update(ms[0], &h));
    benchmark::DoNotOptimize(h.P.data());
  }
}
BENCHMARK_CAPTURE(BM_Update, ism, ModelKind::kIsm);
BENCHMARK_CAPTURE(BM_Update, vasm, ModelKind::kVasm);

// The planner's trajectory: 31 poses, 0..3 s by 0.1 s.
void BM_PredictTrajectory(benchmark::State& state, ModelKind kind) {
  const Ekf ekf;
  const Hypothesis h = TurningCar(kind);
  for (auto _ : state) {
    std::vector<PredictedPose> traj = ekf.PredictTrajectory(h);
    benchmark::DoNotOptimize(traj.data());
  }
}
BENCHMARK_CAPTURE(BM_PredictTrajectory, ism, ModelKind::kIsm);
BENCHMARK_CAPTURE(BM_PredictTrajectory, vasm, ModelKind::kVasm);

void BM_ConvertIsmToVasm(benchmark::State& state) {
  const Ekf ekf;
  const Hypothesis h = TurningCar(ModelKind::kIsm);
  for (auto _ : state) {
    Hypothesis v = ekf.Convert(h, ModelKind::kVasm, 0.5 * std::acos(-1.0));
    benchmark::DoNotOptimize(v.P.data());
  }
}
BENCHMARK(BM_ConvertIsmToVasm);

// One length sample per scan and the estimate, with the default 0.05 m bins over 20 m.
void BM_ShapeAddAndEstimate(benchmark::State& state) {
  DimensionHistogram hist;
  std::mt19937_64 rng(2);
  std::normal_distribution<double> noise(4.5, 0.1);
  std::vector<double> samples(1024);
  for (double& s : samples) s = noise(rng);
  double t = 0.0;
  std::size_t i = 0;
  for (auto _ : state) {
    t += 0.1;
    hist.Add(t, samples[i]);
    i = (i + 1) % samples.size();
    benchmark::DoNotOptimize(hist.Estimate());
  }
}
BENCHMARK(BM_ShapeAddAndEstimate);

}  // namespace
}  // namespace vtrack

BENCHMARK_MAIN();
