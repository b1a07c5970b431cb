// The whole tracker's time per scan (Tracker::AddScan with the scan's poses already in:
// compensation, ground, segmentation, association, fitting, filters, hypotheses, report), at
// steady state, measured as the process's CPU time per scan, over all its threads (so other
// processes on the machine do not inflate it; wall time is reported too). One thread
// (compute.threads = 1) unless the name says otherwise:
//  - BM_TrackerScan_Kitti: the real KITTI HDL-64E sequence 0000, frames 11-100 after 10 frames of
//    warm-up (98k-124k returns per scan); skipped with a message if the data is absent;
//  - BM_TrackerScan_Stress: the simulator's `stress` scenario (64 layers, ~300 vehicles);
//  - BM_TrackerScan_Fig4: the single-plane paper_fig4_turn scenario;
//  - BM_TrackerScan_Kitti_2Threads: KITTI with compute.threads = 2 (the shipped configuration):
//    wall time, the latency a user sees, beside the CPU time of both threads; scans back to
//    back, threads not pinned (as vtrack-tracker --input runs);
//  - BM_TrackerScan_Kitti_2Threads_10Hz and ..._10Hz_Unpinned: the same with each scan started
//    100 ms after the one before, as a live tracker gets them (it sleeps in between), with the
//    pool's threads pinned to CPUs of their own (compute.pin_threads, shipped) and not.
// Counters per benchmark: median_ms / p99_ms / wall_median_ms over the timed scans and, for the
// 3-D sequences, where the time goes (median ms of the process's CPU time per stage, read in the
// timed run itself at the stages' ends, Tracker::SetStageClock): pre_ms (compensation + ground),
// seg_ms (segmentation and grazing pieces, beside the range profile and the tracks' prediction),
// assoc_ms (association), upd_ms (every track's update: outline, fit, filters, hypotheses,
// evidence), new_ms (new tracks), life_ms (life cycle and report), and rest_ms = total - pre_ms -
// seg_ms - assoc_ms (the last three and the sequencing around the pipeline).
//  - BM_CopyFloor_Kitti: the physical floor, a plain copy of each scan's point arrays (x, y, z,
//    intensity, dt_us, ring) into buffers allocated once.
//  - BM_DecodeSweep_Kitti/0, /1 and /2: decoding each KITTI scan's ladar_scan_t (2.2-2.7 MB)
//    into the core's LadarScan: /0 with LCM's generated decode() into fresh arrays, /1 as
//    lcm_util::Decode does (array by array) into fresh arrays, /2 as vtrack-tracker does when a
//    sweep arrives whole, lcm_util::Decode into the arrays of the scan decoded before (LendArrays,
//    as the tracker lends those of the scan it is done with, Tracker::TakeSpareScan). CPU time of
//    the thread, which counts the page faults of fresh memory.
//  - BM_EncodeSweep_Kitti/0 and /1: encoding each KITTI scan as a sensor driver publishes it: /0
//    as lcm::LCM::publish(channel, &msg) does (the generated encoder, into a buffer allocated per
//    message), /1 as vtrack-ladar-driver does (lcm_util::Encode into a buffer kept between sweeps).
//  - BM_PointsScaling/N: KITTI frames resampled to N = 10k..1M returns per scan (every k-th return
//    below the native count; above it, each return repeated with a seeded 2 cm jitter: a denser
//    sensor seeing the same scene).
//  - BM_ObjectsScaling/N: a synthetic 3-D scene of N = 10..1000 cars (half of the rows moving)
//    on a lattice around a stationary sensor, faces sampled at 0.2 deg of bearing on 7 rings,
//    plus a fixed 29k-return ground; no occlusion.
// The growth exponents are fitted by scripts/bench.sh (least squares in log-log).
//
//   build/bench/tracker_bench [--benchmark_filter=Kitti]
#include <benchmark/benchmark.h>

#include <time.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/encode.h"
#include "tests/bench/bench_data.h"
#include "tests/support/encode.h"
#include "base/angle.h"

namespace {

using namespace vtrack;
using bench::Sequence;

double ThreadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Every thread's: the tracker's worker threads included.
double ProcessCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double WallSeconds() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// The shipped parameters with compute.threads = n.
TrackerParams Threads(int n) {
  TrackerParams p = bench::ShippedParams();
  p.compute.threads = n;
  return p;
}

// Times Tracker::AddScan of each scan after a warm-up of `warmup` scans; one iteration per scan
// (the tracker is rebuilt and warmed up, untimed, when the sequence runs out).
// period_ms > 0: each scan, warm-up scans too, starts that long after the one before (the wait
// untimed), so that the first timed scan comes as long after the warm-up as on the bus.
void RunSequence(benchmark::State& state, const Sequence& seq, int warmup, bool breakdown,
                 const TrackerParams& params = Threads(1), int period_ms = 0) {
  if (!seq.error.empty()) {
    state.SkipWithError(seq.error.c_str());
    return;
  }
  if (static_cast<int>(seq.scans.size()) <= warmup + 1) {
    state.SkipWithError("sequence too short");
    return;
  }
  std::unique_ptr<Tracker> tracker;
  std::size_t i = seq.scans.size();
  std::vector<ScanOutput> out;
  std::vector<double> cpu_ms, wall_ms;
  // Per stage (ScanOutput::stages): pre, seg, assoc, upd, new, life; then rest.
  constexpr int kStages = 7;
  static const char* const kStageCounter[kStages] = {"pre_ms", "seg_ms", "assoc_ms", "upd_ms",
                                                     "new_ms", "life_ms", "rest_ms"};
  std::vector<double> stage_ms[kStages];
  double points = 0, tracks = 0;
  auto next_start = std::chrono::steady_clock::now();
  const auto wait_for_start = [&] {
    if (period_ms <= 0) return;
    std::this_thread::sleep_until(next_start);
    next_start = std::chrono::steady_clock::now() + std::chrono::milliseconds(period_ms);
  };
  for (auto _ : state) {
    if (i >= seq.scans.size()) {
      tracker = std::make_unique<Tracker>(params);
      if (breakdown) tracker->SetStageClock(ProcessCpuSeconds);
      for (i = 0; i < static_cast<std::size_t>(warmup); ++i) {
        for (const auto& p : seq.poses_before[i]) tracker->AddPose(p, &out);
        LadarScan copy = seq.scans[i];
        wait_for_start();
        tracker->AddScan(std::move(copy), &out);
      }
    }
    for (const auto& p : seq.poses_before[i]) tracker->AddPose(p, &out);
    LadarScan copy = seq.scans[i];
    points += static_cast<double>(copy.size());
    out.clear();
    wait_for_start();
    const double w0 = WallSeconds(), c0 = ProcessCpuSeconds();
    tracker->AddScan(std::move(copy), &out);  // processed here: its poses are in
    const double c1 = ProcessCpuSeconds(), w1 = WallSeconds();
    state.SetIterationTime(c1 - c0);
    if (out.size() != 1) {
      state.SkipWithError("scan was not processed");
      return;
    }
    tracks += static_cast<double>(out.back().tracks.size());
    cpu_ms.push_back(1e3 * (c1 - c0));
    wall_ms.push_back(1e3 * (w1 - w0));
    if (breakdown) {
      const ScanOutput::StageSeconds& s = out.back().stages;
      const double ms[kStages - 1] = {s.preprocess, s.segment, s.associate,
                                      s.update,     s.create,  s.life_cycle};
      for (int k = 0; k + 1 < kStages; ++k) stage_ms[k].push_back(1e3 * ms[k]);
      stage_ms[kStages - 1].push_back(cpu_ms.back() - 1e3 * (ms[0] + ms[1] + ms[2]));
    }
    ++i;
  }
  const double n = static_cast<double>(cpu_ms.size());
  state.counters["points_per_scan"] = points / n;
  state.counters["tracks_per_scan"] = tracks / n;
  state.counters["median_ms"] = bench::Percentile(cpu_ms, 50);
  state.counters["p99_ms"] = bench::Percentile(cpu_ms, 99);
  state.counters["max_ms"] = bench::Percentile(cpu_ms, 100);
  state.counters["wall_median_ms"] = bench::Percentile(wall_ms, 50);
  state.counters["wall_p99_ms"] = bench::Percentile(wall_ms, 99);
  if (breakdown) {
    for (int k = 0; k < kStages; ++k) {
      state.counters[kStageCounter[k]] = bench::Percentile(stage_ms[k], 50);
    }
  }
}

const Sequence& StressSeq() { return bench::Scenario("stress", 100); }

void BM_TrackerScan_Kitti(benchmark::State& state) { RunSequence(state, bench::Kitti(), 10, true); }
void BM_TrackerScan_Stress(benchmark::State& state) { RunSequence(state, StressSeq(), 10, true); }
void BM_TrackerScan_Fig4(benchmark::State& state) {
  RunSequence(state, bench::Scenario("paper_fig4_turn", 200), 50, false);
}

void BM_TrackerScan_Kitti_2Threads(benchmark::State& state) {
  TrackerParams params = Threads(2);
  params.compute.pin_threads = false;  // as vtrack-tracker --input runs
  RunSequence(state, bench::Kitti(), 10, false, params);
}
void BM_TrackerScan_Kitti_2Threads_10Hz(benchmark::State& state) {
  // Pinned as the live vtrack-tracker (the permission taken back however the run ends).
  struct Allowed {
    Allowed() { Tracker::AllowThreadPinning(true); }
    ~Allowed() { Tracker::AllowThreadPinning(false); }
  } allowed;
  RunSequence(state, bench::Kitti(), 10, false, Threads(2), 100);
}
void BM_TrackerScan_Kitti_2Threads_10Hz_Unpinned(benchmark::State& state) {
  TrackerParams params = Threads(2);
  params.compute.pin_threads = false;
  RunSequence(state, bench::Kitti(), 10, false, params, 100);
}

BENCHMARK(BM_TrackerScan_Kitti)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(90);
BENCHMARK(BM_TrackerScan_Stress)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(90);
BENCHMARK(BM_TrackerScan_Fig4)->UseManualTime()->Unit(benchmark::kMicrosecond)->Iterations(150);
BENCHMARK(BM_TrackerScan_Kitti_2Threads)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(90);
BENCHMARK(BM_TrackerScan_Kitti_2Threads_10Hz)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(90);
BENCHMARK(BM_TrackerScan_Kitti_2Threads_10Hz_Unpinned)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(90);

// A plain copy of every point array of each scan, into buffers allocated once.
void BM_CopyFloor_Kitti(benchmark::State& state) {
  const Sequence& seq = bench::Kitti();
  if (!seq.error.empty()) {
    state.SkipWithError(seq.error.c_str());
    return;
  }
  LadarScan dst;
  auto copy_into = [](const auto& src, auto* d) {
    d->resize(src.size());
    std::memcpy(d->data(), src.data(), src.size() * sizeof(src[0]));
  };
  std::size_t i = 0;
  std::vector<double> ms;
  double bytes = 0;
  for (auto _ : state) {
    const LadarScan& s = seq.scans[i];
    const double c0 = ThreadCpuSeconds();
    copy_into(s.x, &dst.x);
    copy_into(s.y, &dst.y);
    copy_into(s.z, &dst.z);
    copy_into(s.intensity, &dst.intensity);
    copy_into(s.dt_us, &dst.dt_us);
    copy_into(s.ring, &dst.ring);
    benchmark::ClobberMemory();
    const double c1 = ThreadCpuSeconds();
    state.SetIterationTime(c1 - c0);
    ms.push_back(1e3 * (c1 - c0));
    bytes += static_cast<double>(s.size() * (4 * sizeof(float) + sizeof(std::int32_t) + sizeof(std::int16_t)));
    i = (i + 1) % seq.scans.size();
  }
  state.counters["median_ms"] = bench::Percentile(ms, 50);
  state.SetBytesProcessed(static_cast<std::int64_t>(bytes));
}
BENCHMARK(BM_CopyFloor_Kitti)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(400);

// Each scan as the LCM message a sensor sends (mounting left at identity: coding does not depend
// on it).
std::vector<ladar_scan_t> ScanMessages(const Sequence& seq) {
  std::vector<ladar_scan_t> out;
  for (const LadarScan& s : seq.scans) {
    ladar_scan_t m{};
    m.utime = s.utime;
    m.seq = s.seq;
    m.sensor_id = s.sensor_id;
    m.sensor_orientation[0] = 1.0;
    m.sweep_duration_us = s.sweep_duration_us;
    m.max_range = s.max_range;
    m.num_rings = s.num_rings;
    m.npoints = static_cast<std::int32_t>(s.size());
    m.x = s.x;
    m.y = s.y;
    m.z = s.z;
    m.intensity = s.intensity;
    m.dt_us = s.dt_us;
    m.ring = s.ring;
    out.push_back(std::move(m));
  }
  return out;
}

std::vector<std::vector<std::uint8_t>> EncodedScans(const Sequence& seq) {
  std::vector<std::vector<std::uint8_t>> out;
  for (const ladar_scan_t& m : ScanMessages(seq)) out.push_back(testing::Encode(m));
  return out;
}

void BM_DecodeSweep_Kitti(benchmark::State& state) {
  const Sequence& seq = bench::Kitti();
  if (!seq.error.empty()) {
    state.SkipWithError(seq.error.c_str());
    return;
  }
  const bool generated = state.range(0) == 0;
  const bool lend = state.range(0) == 2;
  const auto encoded = EncodedScans(seq);
  LadarScan held;
  std::size_t i = 0;
  std::vector<double> ms;
  for (auto _ : state) {
    const std::vector<std::uint8_t>& b = encoded[i];
    const double c0 = ThreadCpuSeconds();
    ladar_scan_t msg;
    if (lend) {
      LendArrays(std::move(held), &msg);
    }
    const bool ok = generated ? msg.decode(b.data(), 0, static_cast<int>(b.size())) ==
                                    static_cast<int>(b.size())
                              : lcm_util::Decode(b.data(), b.size(), &msg) ==
                                    lcm_util::DecodeError::kNone;
    if (!ok) {
      state.SkipWithError("a scan did not decode");
      return;
    }
    held = ScanFromLcm(std::move(msg));
    benchmark::ClobberMemory();
    const double c1 = ThreadCpuSeconds();
    state.SetIterationTime(c1 - c0);
    ms.push_back(1e3 * (c1 - c0));
    i = (i + 1) % encoded.size();
  }
  state.counters["median_ms"] = bench::Percentile(ms, 50);
  state.counters["p99_ms"] = bench::Percentile(ms, 99);
}
BENCHMARK(BM_DecodeSweep_Kitti)->Arg(0)->Arg(1)->Arg(2)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(400);

void BM_EncodeSweep_Kitti(benchmark::State& state) {
  const Sequence& seq = bench::Kitti();
  if (!seq.error.empty()) {
    state.SkipWithError(seq.error.c_str());
    return;
  }
  const bool kept_buffer = state.range(0) != 0;
  const std::vector<ladar_scan_t> messages = ScanMessages(seq);
  std::vector<std::uint8_t> buffer;
  std::size_t i = 0;
  std::vector<double> ms;
  for (auto _ : state) {
    const ladar_scan_t& m = messages[i];
    const double c0 = ThreadCpuSeconds();
    int n = -1;
    if (kept_buffer) {
      n = lcm_util::Encode(m, &buffer);
    } else {
      // What lcm::LCM::publish(channel, &msg) does before sending.
      const int size = m.getEncodedSize();
      std::unique_ptr<std::uint8_t[]> fresh(new std::uint8_t[static_cast<std::size_t>(size)]);
      n = m.encode(fresh.get(), 0, size);
      benchmark::DoNotOptimize(fresh.get());
    }
    benchmark::ClobberMemory();
    const double c1 = ThreadCpuSeconds();
    if (n < 0) {
      state.SkipWithError("a scan did not encode");
      return;
    }
    state.SetIterationTime(c1 - c0);
    ms.push_back(1e3 * (c1 - c0));
    i = (i + 1) % messages.size();
  }
  state.counters["median_ms"] = bench::Percentile(ms, 50);
  state.counters["p99_ms"] = bench::Percentile(ms, 99);
}
BENCHMARK(BM_EncodeSweep_Kitti)->Arg(0)->Arg(1)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(400);

// KITTI frames 1..20 resampled to n returns per scan (one size cached at a time).
const Sequence& Resampled(std::size_t n) {
  static std::size_t cached_n = 0;
  static Sequence s;
  if (cached_n == n) return s;
  const Sequence& k = bench::Kitti();
  s = Sequence{};
  s.name = "kitti_resampled";
  cached_n = n;
  if (!k.error.empty()) {
    s.error = k.error;
    return s;
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> jitter(-0.02f, 0.02f);
  const std::size_t num = std::min<std::size_t>(20, k.scans.size());
  for (std::size_t f = 0; f < num; ++f) {
    const LadarScan& src = k.scans[f];
    LadarScan dst = src;
    dst.x.clear(), dst.y.clear(), dst.z.clear(), dst.intensity.clear(), dst.dt_us.clear(), dst.ring.clear();
    const std::size_t m = src.size();
    for (std::size_t j = 0; j < n; ++j) {
      // Below the native count: every k-th return; above: return j % m (jittered repeats).
      const std::size_t i = n <= m ? j * m / n : j % m;
      const float e = (n > m && j >= m) ? 1.0f : 0.0f;
      dst.x.push_back(src.x[i] + e * jitter(rng));
      dst.y.push_back(src.y[i] + e * jitter(rng));
      dst.z.push_back(src.z[i] + e * jitter(rng));
      dst.intensity.push_back(src.intensity[i]);
      dst.dt_us.push_back(src.dt_us[i]);
      dst.ring.push_back(src.ring[i]);
    }
    s.scans.push_back(std::move(dst));
    s.poses_before.push_back(k.poses_before[f]);
  }
  return s;
}

void BM_PointsScaling(benchmark::State& state) {
  TrackerParams p = Threads(1);
  p.preprocess.max_points = 2'000'000;
  RunSequence(state, Resampled(static_cast<std::size_t>(state.range(0))), 5, true, p);
}
BENCHMARK(BM_PointsScaling)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(15)
    ->Arg(10'000)
    ->Arg(30'000)
    ->Arg(100'000)
    ->Arg(300'000)
    ->Arg(1'000'000);

// n cars on a 6 m x 3 m lattice around a stationary sensor (nearest lattice nodes beyond 5 m),
// every other row driving along +x at 3 m/s; 30 scans at 10 Hz.
const Sequence& Cars(int n) {
  static std::map<int, Sequence> cache;
  auto it = cache.find(n);
  if (it != cache.end()) return it->second;
  Sequence s;
  s.name = "cars";
  struct Car {
    double x, y, v;
  };
  std::vector<Car> cars;
  for (int r = -30; r <= 30; ++r) {
    for (int c = -15; c <= 15; ++c) {
      const double x = 6.0 * c + (r % 2 ? 3.0 : 0.0), y = 3.0 * r;
      if (std::hypot(x, y) < 5.0) continue;
      cars.push_back({x, y, (r % 2) ? 3.0 : 0.0});
    }
  }
  std::sort(cars.begin(), cars.end(), [](const Car& a, const Car& b) {
    return std::hypot(a.x, a.y) < std::hypot(b.x, b.y);
  });
  cars.resize(std::min<std::size_t>(cars.size(), static_cast<std::size_t>(n)));
  const double kMount = 1.73, kLength = 4.5, kWidth = 1.8, kBeam = DegToRad(0.2);
  const std::int64_t t0 = 1'700'000'000'000'000, sweep = 100'000;
  for (int k = 0; k < 30; ++k) {
    LadarScan scan;
    scan.utime = t0 + k * sweep;
    scan.seq = k;
    scan.sweep_duration_us = sweep;
    scan.max_range = 120.0f;
    scan.num_rings = 64;
    scan.body_from_sensor.translation() = Eigen::Vector3d(0, 0, kMount);
    auto add = [&](double x, double y, double z, int ring) {
      scan.x.push_back(static_cast<float>(x));
      scan.y.push_back(static_cast<float>(y));
      scan.z.push_back(static_cast<float>(z - kMount));
      scan.intensity.push_back(0.5f);
      const double az = std::atan2(y, x) + M_PI;  // [0, 2 pi]
      scan.dt_us.push_back(static_cast<std::int32_t>(std::min<double>(sweep, az / (2 * M_PI) * sweep)));
      scan.ring.push_back(static_cast<std::int16_t>(ring));
    };
    // Ground: 16 range rings x 1800 bearings.
    for (int r = 0; r < 16; ++r) {
      const double range = 4.0 + 2.4 * r;
      for (int b = 0; b < 1800; ++b) {
        const double a = 2 * M_PI * b / 1800;
        add(range * std::cos(a), range * std::sin(a), 0.0, 63 - r);
      }
    }
    for (const Car& car : cars) {
      const double cx = car.x + car.v * 0.1 * k, cy = car.y;
      const std::array<Eigen::Vector2d, 4> corner = {Eigen::Vector2d(cx + kLength / 2, cy + kWidth / 2),
                                                     Eigen::Vector2d(cx - kLength / 2, cy + kWidth / 2),
                                                     Eigen::Vector2d(cx - kLength / 2, cy - kWidth / 2),
                                                     Eigen::Vector2d(cx + kLength / 2, cy - kWidth / 2)};
      for (int f = 0; f < 4; ++f) {
        const Eigen::Vector2d a = corner[static_cast<std::size_t>(f)], b = corner[static_cast<std::size_t>((f + 1) % 4)];
        const Eigen::Vector2d mid = 0.5 * (a + b), normal = (mid - Eigen::Vector2d(cx, cy)).normalized();
        if (normal.dot(-mid) <= 0.0) continue;  // faces away from the sensor
        const double span = std::abs(std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b)));
        const int samples = std::max(2, static_cast<int>(span / kBeam));
        for (int q = 0; q <= samples; ++q) {
          const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(q) / samples);
          for (int ring = 0; ring < 7; ++ring) add(p.x(), p.y(), 0.3 + 0.2 * ring, 20 + ring);
        }
      }
    }
    s.scans.push_back(std::move(scan));
  }
  bench::AddPoses(&s, t0 - 20'000, 10'000, [](std::int64_t t) { return EgoPose{t, Eigen::Isometry3d::Identity()}; });
  return cache.emplace(n, std::move(s)).first->second;
}

void BM_ObjectsScaling(benchmark::State& state) {
  RunSequence(state, Cars(static_cast<int>(state.range(0))), 10, true);
  state.counters["objects"] = static_cast<double>(state.range(0));
}
BENCHMARK(BM_ObjectsScaling)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(20)
    ->Arg(10)
    ->Arg(30)
    ->Arg(100)
    ->Arg(300)
    ->Arg(1000);

}  // namespace

BENCHMARK_MAIN();
