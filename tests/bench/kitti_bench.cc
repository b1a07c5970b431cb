// Reading and converting one KITTI frame: the .bin read, the scan message (per-return time and
// ring), the ground truth with its point counts, and the LCM encoding of the scan; and putting
// the frame's sweep back together from its slices (BM_AssembleSweep). Uses frame 0 of
// ../shared/data/kitti_tracking_0000 (unpacked into <build>/kitti_cache); without it, a synthetic
// sweep of the same size (64 lasers x 1900 returns) laid out like a KITTI file.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "lcmtypes/util/ladar_slices.h"
#include "sensor_driver/kitti/kitti_scan.h"
#include "sensor_driver/kitti/kitti_sequence.h"

namespace {

namespace fs = std::filesystem;
using vtrack::kitti::Sequence;
using vtrack::kitti::SequenceOptions;
using vtrack::kitti::VelodyneFrame;

std::string DataDir() {
  const char* d = std::getenv("VTRACK_DATA_DIR");
  return (d && *d ? std::string(d) : std::string(VTRACK_SOURCE_DIR "/../shared/data")) + "/kitti_tracking_0000";
}

// The real sequence, opened once (nullptr if the data is absent).
const Sequence* RealSequence() {
  static const std::unique_ptr<Sequence> seq = []() -> std::unique_ptr<Sequence> {
    if (!fs::is_directory(DataDir())) return nullptr;
    SequenceOptions o;
    o.dir = DataDir();
    o.cache_dir = VTRACK_BINARY_DIR "/kitti_cache";
    return std::make_unique<Sequence>(o);
  }();
  return seq.get();
}

// RealSequence() for a benchmark that needs the real data: when it is absent, the benchmark is
// skipped, saying so, and nullptr is returned.
const Sequence* RealSequenceOrSkip(benchmark::State& state) {
  const Sequence* seq = RealSequence();
  if (!seq) state.SkipWithError("KITTI data not found (../shared/data/kitti_tracking_0000)");
  return seq;
}

// A .bin file of frame 0, real or synthetic.
std::string FramePath() {
  if (const Sequence* s = RealSequence()) return s->paths().velodyne_dir + "/000000.bin";
  const std::string path = (fs::temp_directory_path() / "vtrack_kitti_bench_000000.bin").string();
  if (!fs::exists(path)) {
    std::vector<float> raw;
    for (int l = 0; l < 64; ++l) {
      const double elevation = 0.035 - 0.4 * l / 64;
      for (int k = 0; k < 1900; ++k) {
        const double az = 0.01 + (2 * M_PI - 0.02) * k / 1899;
        const double r = 8.0 + 20.0 * std::abs(std::sin(3 * az));
        raw.insert(raw.end(), {static_cast<float>(r * std::cos(elevation) * std::cos(az)),
                               static_cast<float>(r * std::cos(elevation) * std::sin(az)),
                               static_cast<float>(r * std::sin(elevation)), 0.3f});
      }
    }
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(raw.data()),
                                                static_cast<std::streamsize>(raw.size() * 4));
  }
  return path;
}

void BM_ReadVelodyneBin(benchmark::State& state) {
  const std::string path = FramePath();
  std::size_t n = 0;
  for (auto _ : state) {
    const VelodyneFrame f = vtrack::kitti::ReadVelodyneBin(path);
    n = f.size();
    benchmark::DoNotOptimize(f.x.data());
  }
  state.counters["points"] = static_cast<double>(n);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
}
BENCHMARK(BM_ReadVelodyneBin)->Unit(benchmark::kMillisecond);

void BM_MakeScan(benchmark::State& state) {
  const VelodyneFrame f = vtrack::kitti::ReadVelodyneBin(FramePath());
  const vtrack::kitti::VelodyneParams params;
  for (auto _ : state) {
    const auto scan = vtrack::kitti::MakeScan(f, 1'000'000, 0, params);
    benchmark::DoNotOptimize(scan.ring.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(f.size()));
}
BENCHMARK(BM_MakeScan)->Unit(benchmark::kMillisecond);

void BM_EncodeScan(benchmark::State& state) {
  const auto scan = vtrack::kitti::MakeScan(vtrack::kitti::ReadVelodyneBin(FramePath()), 1'000'000, 0, {});
  std::vector<char> buf(static_cast<std::size_t>(scan.getEncodedSize()));
  for (auto _ : state) {
    scan.encode(buf.data(), 0, static_cast<int>(buf.size()));
    benchmark::DoNotOptimize(buf.data());
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(buf.size()));
}
BENCHMARK(BM_EncodeScan)->Unit(benchmark::kMillisecond);

// A sweep put back together from its slices as the tracker receives them (SweepAssembler, the
// slices of vtrack-ladar-driver's --slices auto): the work between a sweep's last slice arriving
// and the tracker having the whole sweep. The copies of the slices handed in are made outside
// the timed part.
void BM_AssembleSweep(benchmark::State& state) {
  const auto scan = vtrack::kitti::MakeScan(vtrack::kitti::ReadVelodyneBin(FramePath()), 1'000'000, 0, {});
  const std::vector<vtrack::ladar_slice_t> slices = vtrack::lcm_util::SliceSweep(scan, 0);
  vtrack::lcm_util::SweepAssembler assembler;
  std::vector<vtrack::lcm_util::AssembledSweep> out;
  std::int64_t seq = 0;
  for (auto _ : state) {
    state.PauseTiming();
    std::vector<vtrack::ladar_slice_t> copies = slices;
    for (vtrack::ladar_slice_t& c : copies) c.seq = seq, c.utime += seq * 100'000;
    ++seq;
    out.clear();
    state.ResumeTiming();
    for (vtrack::ladar_slice_t& c : copies) assembler.Add(std::move(c), &out);
    benchmark::DoNotOptimize(out.data());
  }
  if (out.size() != 1 || out[0].scan.npoints != scan.npoints) state.SkipWithError("the sweep was not put back whole");
  state.counters["slices"] = static_cast<double>(slices.size());
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(scan.getEncodedSize()));
}
BENCHMARK(BM_AssembleSweep)->Unit(benchmark::kMillisecond);

// Real data only: labels are needed.
void BM_GroundTruthWithPointCounts(benchmark::State& state) {
  const Sequence* seq = RealSequenceOrSkip(state);
  if (!seq) return;
  const VelodyneFrame f = seq->ReadFrame(0);
  for (auto _ : state) {
    const auto gt = seq->GroundTruth(0, f);
    benchmark::DoNotOptimize(gt.objects.data());
  }
}
BENCHMARK(BM_GroundTruthWithPointCounts)->Unit(benchmark::kMillisecond);

// The whole per-frame conversion as vtrack-kitti2lcm does it (read, scan, truth, encode).
void BM_ConvertOneFrame(benchmark::State& state) {
  const Sequence* seq = RealSequenceOrSkip(state);
  if (!seq) return;
  std::vector<char> buf;
  for (auto _ : state) {
    const VelodyneFrame f = seq->ReadFrame(0);
    const auto scan = seq->Scan(0, f);
    const auto gt = seq->GroundTruth(0, f);
    buf.resize(static_cast<std::size_t>(scan.getEncodedSize()));
    scan.encode(buf.data(), 0, static_cast<int>(buf.size()));
    benchmark::DoNotOptimize(buf.data());
    benchmark::DoNotOptimize(gt.objects.data());
  }
}
BENCHMARK(BM_ConvertOneFrame)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
