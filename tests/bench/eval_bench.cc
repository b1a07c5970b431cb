// Speed of the evaluator's pieces: the gated assignment per scan, CLEAR MOT and HOTA over a log.
// Scoring a long log must take seconds, not minutes (HOTA solves 19 assignments per scan).
#include <benchmark/benchmark.h>

#include <limits>
#include <random>
#include <vector>

#include "log_tools/eval/clear_mot.h"
#include "log_tools/eval/gated_assignment.h"

namespace {

using vtrack::eval::ScoringFrame;

// n truth objects per scan doing random walks in a 60 m square, tracked with noise, misses and
// false positives; ids persistent.
std::vector<ScoringFrame> RandomFrames(int scans, int n) {
  std::mt19937 rng(3);
  std::normal_distribution<double> step(0.0, 0.3), noise(0.0, 0.4);
  std::uniform_real_distribution<double> pos(0.0, 60.0), unit(0.0, 1.0);
  std::vector<Eigen::Vector2d> p(static_cast<std::size_t>(n));
  for (auto& q : p) q = {pos(rng), pos(rng)};
  std::vector<ScoringFrame> frames(static_cast<std::size_t>(scans));
  for (int t = 0; t < scans; ++t) {
    ScoringFrame& f = frames[static_cast<std::size_t>(t)];
    f.utime = t;
    for (int i = 0; i < n; ++i) {
      p[i] += Eigen::Vector2d(step(rng), step(rng));
      f.gt_ids.push_back(i);
      f.gt_xy.push_back(p[i]);
      if (unit(rng) < 0.9) {
        f.track_ids.push_back(1000 + i);
        f.track_xy.push_back(p[i] + Eigen::Vector2d(noise(rng), noise(rng)));
      }
    }
    for (int k = 0; k < n / 5; ++k) {
      f.track_ids.push_back(100000 + t * n + k);
      f.track_xy.emplace_back(pos(rng), pos(rng));
    }
  }
  return frames;
}

void BM_GatedAssignment(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> d(0.0, 4.0);
  Eigen::MatrixXd cost(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double v = d(rng);
      cost(i, j) = v < 2.0 ? v : std::numeric_limits<double>::infinity();
    }
  }
  for (auto _ : state) benchmark::DoNotOptimize(vtrack::eval::GatedAssignment(cost));
}
BENCHMARK(BM_GatedAssignment)->Arg(10)->Arg(50)->Arg(200);

// score(frames) over 1000 random frames of state.range(0) objects each; items are frames.
template <class Score>
void ScoreRandomFrames(benchmark::State& state, Score score) {
  const auto frames = RandomFrames(1000, static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(score(frames));
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(frames.size()));
}

void BM_ClearMot(benchmark::State& state) {
  const vtrack::eval::ClearMotParams p;
  ScoreRandomFrames(state,
                    [&](const auto& frames) { return vtrack::eval::ComputeClearMot(frames, p); });
}
BENCHMARK(BM_ClearMot)->Arg(10)->Arg(50)->Unit(benchmark::kMillisecond);

void BM_Hota(benchmark::State& state) {
  const vtrack::eval::HotaParams p;
  ScoreRandomFrames(state,
                    [&](const auto& frames) { return vtrack::eval::ComputeHota(frames, p); });
}
BENCHMARK(BM_Hota)->Arg(10)->Arg(50)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
