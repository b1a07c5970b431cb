// Memory over a long run: the tracker on a 10-minute simulated `stress` log, as fast as
// possible. The scenario (20 s: a dense avenue, ~300 vehicles, 64 layers) is simulated scan by
// scan and replayed back to back with message time running on (a 10-minute log is 6000 scans of
// 2.8 MB: generating them on the fly keeps 17 GB off the disk); at every restart the vehicles
// and the ego jump back, so the tracker also deletes and creates tracks in bulk.
// Reports the process's resident set (VmRSS; the simulator's part is fixed: a scene and one scan
// buffer) and malloc's bytes in use at the first minute (start: the track count has settled), at
// the end and the peak, and rss_growth_pct = (end - start) / start. The resident set follows
// the heap's high-water mark (freed memory is kept as vtrack-tracker keeps it, KeepFreedMemory,
// lcmtypes/util/process.h), which the scene's busiest moments may raise after the first minute;
// a leak grows on and on. So also the RSS at half time and rss_growth_second_half_pct =
// (end - half) / half: a working set reached grows no more, a leak grows in the second half too.
//
//   build/bench/tracker_soak [--minutes 10] [--json F]
#include <malloc.h>

#include <boost/program_options.hpp>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>

#include "lcmtypes/util/process.h"
#include "tests/bench/bench_data.h"
#include "tests/bench/bench_options.h"

namespace po = boost::program_options;

namespace {

double RssMb() {
  std::ifstream is("/proc/self/status");
  std::string line;
  while (std::getline(is, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // kB
  }
  return -1.0;
}

double HeapMb() { return static_cast<double>(mallinfo2().uordblks) / (1024.0 * 1024.0); }

}  // namespace

int main(int argc, char** argv) {
  std::string scenario = "stress", json;
  double minutes = 10.0;
  po::options_description desc("tracker_soak: tracker memory over a long simulated log\nOptions");
  desc.add_options()("help,h", "show this help")(
      "scenario", po::value(&scenario)->default_value(scenario), "scenario name or file")(
      "minutes", po::value(&minutes)->default_value(minutes), "simulated length [min]")(
      "json", po::value(&json), "write the figures here");
  if (const auto status = vtrack::bench::ParseOptions("tracker_soak", desc, argc, argv)) return *status;
  // The memory settings of vtrack-tracker, so that its resident size is what is measured.
  if (!vtrack::lcm_util::KeepFreedMemory()) std::fprintf(stderr, "tracker_soak: glibc refused to keep freed memory\n");
  if (!(minutes >= 2.0 && minutes <= 120.0)) {
    std::cerr << "tracker_soak: --minutes " << minutes << " must be in [2, 120]\n";
    return 2;
  }
  using namespace vtrack;
  std::unique_ptr<sim::Simulator> simu;
  try {
    simu = std::make_unique<sim::Simulator>(sim::LoadScenario(sim::ResolveScenarioPath(scenario)));
  } catch (const std::exception& e) {
    std::cerr << "tracker_soak: scenario " << scenario << ": " << e.what() << "\n";
    return 1;
  }
  Tracker tracker(bench::ShippedParams());
  const std::int64_t start = 1'700'000'000'000'000;
  const int scans_per_run = simu->NumScans();
  const std::int64_t run_us = simu->RunDurationUs();
  const std::int64_t total_us = static_cast<std::int64_t>(minutes * 60e6);
  std::vector<ScanOutput> out;
  ladar_scan_t msg;
  object_list_t truth;
  pose_t pose;
  double rss_start = -1, heap_start = -1, rss_half = -1, rss_peak = 0, heap_peak = 0;
  std::int64_t scans = 0, tracks_sum = 0;
  int next_pose = 0, run = 0;
  for (;;) {
    const std::int64_t run_start = start + run * run_us;
    bool done = false;
    next_pose = 0;
    for (int i = 0; i < scans_per_run; ++i) {
      if (simu->ScanOffsetUs(i) + run * run_us >= total_us) {
        done = true;
        break;
      }
      simu->MakeScan(i, run_start, scans, &msg, &truth);
      LadarScan scan = ScanFromLcm(std::move(msg));
      while (next_pose < simu->NumPoses() &&
             run_start + simu->PoseOffsetUs(next_pose) <= scan.end_utime() + 20'000) {
        simu->MakePose(next_pose++, run_start, &pose);
        tracker.AddPose(PoseFromLcm(pose), &out);
      }
      out.clear();
      tracker.AddScan(std::move(scan), &out);
      for (const ScanOutput& o : out) tracks_sum += static_cast<std::int64_t>(o.tracks.size());
      ++scans;
      const double t_s = static_cast<double>(simu->ScanOffsetUs(i) + run * run_us) * 1e-6;
      const double rss = RssMb(), heap = HeapMb();
      if (rss_start < 0 && t_s >= 60.0) {
        rss_start = rss;
        heap_start = heap;
      }
      if (rss_half < 0 && t_s >= 30.0 * minutes) rss_half = rss;
      rss_peak = std::max(rss_peak, rss);
      heap_peak = std::max(heap_peak, heap);
      if (scans % 500 == 0) {
        std::fprintf(stderr, "tracker_soak: %.0f s simulated, %lld scans, RSS %.1f MB, heap %.1f MB, %zu tracks\n",
                     t_s, static_cast<long long>(scans), rss, heap, tracker.manager().tracks().size());
      }
    }
    if (done) break;
    ++run;
  }
  tracker.Flush(&out);
  const double rss_end = RssMb(), heap_end = HeapMb();
  const double growth = 100.0 * (rss_end - rss_start) / rss_start;
  const double growth_second_half = 100.0 * (rss_end - rss_half) / rss_half;
  std::printf("tracker memory over %.1f simulated minutes of %s (%lld scans, %.0f tracks/scan, %lld resets): "
              "RSS start %.1f MB, half time %.1f MB, end %.1f MB, peak %.1f MB (growth %+.2f%%, over the second "
              "half %+.2f%%); heap in use start %.1f MB, end %.1f MB, peak %.1f MB\n",
              minutes, scenario.c_str(), static_cast<long long>(scans),
              static_cast<double>(tracks_sum) / std::max<std::int64_t>(1, scans),
              static_cast<long long>(tracker.resets()), rss_start, rss_half, rss_end, rss_peak, growth,
              growth_second_half, heap_start, heap_end, heap_peak);
  if (!json.empty()) {
    std::ofstream os(json);
    os << "{\"rss_growth_pct\": " << growth << ", \"rss_growth_second_half_pct\": " << growth_second_half
       << ", \"rss_start_mb\": " << rss_start << ", \"rss_half_mb\": " << rss_half
       << ", \"rss_end_mb\": " << rss_end << ", \"rss_peak_mb\": " << rss_peak
       << ", \"heap_start_mb\": " << heap_start << ", \"heap_end_mb\": " << heap_end
       << ", \"heap_peak_mb\": " << heap_peak << ", \"soak_scans\": " << scans
       << ", \"soak_minutes\": " << minutes << "}\n";
  }
  return 0;
}
