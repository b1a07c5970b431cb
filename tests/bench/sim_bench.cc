// Simulator speed (Google Benchmark): one LADAR sweep of the 64-layer scenes (urban_intersection,
// and stress with ~300 vehicles), the single-plane paper scene, a whole scan + ground truth built
// and encoded as vtrack-sim-log does, and loading a scenario file. Counters: points per scan and
// scans per second.
//   <build>/bench/sim_bench [--benchmark_filter=Sweep]
#include <benchmark/benchmark.h>

#include <string>

#include "sensor_driver/sim/scenario.h"
#include "sensor_driver/sim/simulator.h"

namespace vtrack::sim {
namespace {

Scenario Load(const std::string& name) {
  return LoadScenario(ResolveScenarioPath(std::string(VTRACK_SOURCE_DIR) + "/config/scenarios/" + name + ".yaml"));
}

// args: scenario, sensor ("" = the scenario's default), scenario time of the sweep [s].
void BM_Sweep(benchmark::State& state, const std::string& name, const std::string& sensor, double t) {
  const Scenario sc = Load(name);
  LadarSimulator ladar(sc.Sensor(sensor));
  vtrack::ladar_scan_t scan;
  std::vector<int> hits;
  std::uint64_t seed = 1;
  for (auto _ : state) {
    ladar.Sweep(sc.scene, t, seed++, &scan, &hits);
    benchmark::DoNotOptimize(scan.x.data());
  }
  state.counters["points"] = scan.npoints;
  state.counters["objects"] = static_cast<double>(sc.scene.objects.size());
  state.counters["scans/s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK_CAPTURE(BM_Sweep, urban_intersection_velodyne64, "urban_intersection", "", 30.0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Sweep, stress_velodyne64, "stress", "", 10.0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Sweep, fig6_single_plane_noisy, "paper_fig6_noisy_follow", "", 12.0)->Unit(benchmark::kMicrosecond);

// What vtrack-sim-log does per scan: sweep, ground truth, and LCM encoding of both.
void BM_ScanTruthEncode(benchmark::State& state, const std::string& name) {
  Simulator sim(Load(name));
  vtrack::ladar_scan_t scan;
  vtrack::object_list_t truth;
  std::string buf;
  int i = 0;
  for (auto _ : state) {
    sim.MakeScan(i, 0, i, &scan, &truth);
    i = (i + 1) % sim.NumScans();
    buf.resize(scan.getEncodedSize() + truth.getEncodedSize());
    scan.encode(buf.data(), 0, scan.getEncodedSize());
    truth.encode(buf.data(), scan.getEncodedSize(), truth.getEncodedSize());
    benchmark::DoNotOptimize(buf.data());
  }
  state.counters["points"] = scan.npoints;
  state.counters["MB/scan"] = buf.size() / 1e6;
}
BENCHMARK_CAPTURE(BM_ScanTruthEncode, urban_intersection_velodyne64, "urban_intersection")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ScanTruthEncode, stress_velodyne64, "stress")->Unit(benchmark::kMillisecond);

void BM_LoadScenario(benchmark::State& state, const std::string& name) {
  for (auto _ : state) benchmark::DoNotOptimize(Load(name).scene.objects.size());
}
BENCHMARK_CAPTURE(BM_LoadScenario, stress, "stress")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LoadScenario, urban_intersection, "urban_intersection")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace vtrack::sim

BENCHMARK_MAIN();
