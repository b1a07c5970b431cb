// vtrack-soak: a long run of the tracker on a simulated scenario, as fast as the machine allows,
// that watches for what only shows over time: memory growth, track-id reuse, per-scan time that
// creeps up, counters that stop adding up. Not a CI test (30 simulated minutes of a 64-layer
// scene take ~15 minutes of CPU); run it with scripts/soak.sh, see docs/reliability.md.
//
// The scenario's run repeats lap after lap on one continuous clock (lap k starts at
// U + k * duration, seq counts on), exactly as vtrack-ladar-driver / vtrack-ego-pose publish it
// live with --laps: the scene starts over, the clock does not, so the tracker never resets.
// Messages are generated on the fly (a 60 s urban_intersection log is 1.7 GB), encoded, and
// handed to the same TrackerNode that vtrack-tracker runs (decode, convert, track, encode).
//
// Output: one line per --report-every simulated seconds, then the verdict (exit 0 = pass,
// 1 = a check failed, 2 = bad option).
#include <boost/program_options.hpp>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/process.h"
#include "sensor_driver/driver/sim_cli.h"
#include "tests/support/encode.h"
#include "tracker/config.h"
#include "tracker/tracker_node.h"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/object_list_t.hpp"
#include "vtrack/pose_t.hpp"
#include "vtrack/track_list_t.hpp"

namespace po = boost::program_options;

namespace vtrack {
namespace {

double ThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + ts.tv_nsec * 1e-9;
}

// [MB] resident set size and its peak, from /proc/self/status.
void Rss(double* rss_mb, double* peak_mb) {
  std::ifstream f("/proc/self/status");
  std::string key;
  *rss_mb = *peak_mb = 0;
  while (f >> key) {
    long kb = 0;
    if (key == "VmRSS:" && f >> kb) *rss_mb = kb / 1024.0;
    else if (key == "VmHWM:" && f >> kb) *peak_mb = kb / 1024.0;
    else f.ignore(1 << 20, '\n');
  }
}

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

using testing::Encode;

struct Window {
  std::vector<double> scan_cpu_ms;  // tracker CPU per processed scan
  double sim_cpu_s = 0;             // simulator (ray casting) CPU
  int scans = 0;
};

int Run(const po::variables_map& vm) {
  const double minutes = vm["minutes"].as<double>();
  const double every_s = vm["report-every"].as<double>();
  const double max_growth_mb = vm["max-rss-growth-mb"].as<double>();
  const double max_slowdown = vm["max-slowdown"].as<double>();
  if (!(minutes > 0)) throw po::error("--minutes = " + std::to_string(minutes) + ": must be > 0");
  if (!(every_s > 0)) throw po::error("--report-every = " + std::to_string(every_s) + ": must be > 0");
  if (!(max_growth_mb >= 0)) throw po::error("--max-rss-growth-mb = " + std::to_string(max_growth_mb) + ": must be >= 0");
  if (!(max_slowdown >= 1)) throw po::error("--max-slowdown = " + std::to_string(max_slowdown) + ": must be >= 1");
  TrackerParams params = LoadTrackerParams(vm["config"].as<std::string>());
  if (vm.count("mode") && !FromName(vm["mode"].as<std::string>(), &params.manager.mode)) {
    throw po::error("--mode = " + vm["mode"].as<std::string>() + ": must be mht, ism or vasm");
  }
  const sim::SimCli cli = sim::ReadSimCli(vm);
  auto sim = sim::MakeSimulator(cli);

  const std::int64_t lap_us = sim->RunDurationUs();
  const std::int64_t start = cli.start_utime.value_or(sim->scenario().start_utime);
  const std::int64_t end = start + static_cast<std::int64_t>(minutes * 60e6);
  const std::int64_t every_us = static_cast<std::int64_t>(every_s * 1e6);

  // Ids: a track id that leaves the report must never come back; ids must never repeat.
  std::set<std::int64_t> live, gone;
  std::int64_t id_reuse = 0, max_id = -1, tracks_msgs = 0, bad_tracks = 0;
  int live_confirmed = 0;
  TrackerNode node(params, NodeOptions{}, [&](std::int64_t, const std::string& channel, const void* data, std::size_t size) {
    if (channel != "TRACKS") return;
    ++tracks_msgs;
    track_list_t m;
    if (lcm_util::Decode(data, size, &m) != lcm_util::DecodeError::kNone) { ++bad_tracks; return; }
    std::set<std::int64_t> ids;
    live_confirmed = 0;
    for (const track_t& t : m.tracks) {
      ids.insert(t.id);
      if (gone.count(t.id)) ++id_reuse;
      max_id = std::max(max_id, t.id);
      if (t.status == track_t::STATUS_CONFIRMED) ++live_confirmed;
      if (!std::isfinite(t.x) || !std::isfinite(t.y)) ++bad_tracks;
    }
    for (std::int64_t id : live) if (!ids.count(id)) gone.insert(id);
    live.swap(ids);
  });

  std::printf("vtrack-soak: %s (%s), lap %.0f s, %.1f simulated minutes, mode %s, %d scans/lap\n",
              cli.scenario.c_str(), sim->sensor().name.c_str(), lap_us * 1e-6, minutes,
              ToString(params.manager.mode), sim->NumScans());
  std::printf("%8s %8s %7s %9s %9s %9s %8s %8s %8s %8s %8s %7s %7s\n", "sim_min", "wall_s", "scans",
              "med_ms", "p99_ms", "max_ms", "sim_ms", "trk/sim", "rss_MB", "peak_MB", "tracks", "conf", "max_id");
  const auto wall0 = std::chrono::steady_clock::now();
  Window w;
  std::vector<double> window_median_ms;
  // Tracker time over the simulator's time for the same scans: the simulator does the same work
  // every lap, so this ratio is the tracker's time with the machine's load divided out.
  std::vector<double> window_ratio;
  std::vector<double> window_rss;
  std::int64_t next_report = start + every_us;
  ladar_scan_t scan;
  object_list_t truth;
  pose_t pose;
  std::int64_t seq = 0;
  auto report = [&](std::int64_t now) {
    double rss = 0, peak = 0;
    Rss(&rss, &peak);
    const double med = Quantile(w.scan_cpu_ms, 0.5);
    const double sim_ms = w.scans ? w.sim_cpu_s * 1e3 / w.scans : 0.0;
    const double ratio = sim_ms > 0 ? Quantile(w.scan_cpu_ms, 0.5) / sim_ms : 0.0;
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    std::printf("%8.1f %8.0f %7d %9.2f %9.2f %9.2f %8.2f %8.2f %8.1f %8.1f %8zu %7d %7lld\n",
                (now - start) / 60e6, wall, w.scans, med, Quantile(w.scan_cpu_ms, 0.99),
                w.scan_cpu_ms.empty() ? 0.0 : *std::max_element(w.scan_cpu_ms.begin(), w.scan_cpu_ms.end()),
                sim_ms, ratio, rss, peak, live.size(), live_confirmed,
                static_cast<long long>(max_id));
    std::fflush(stdout);
    window_median_ms.push_back(med);
    window_rss.push_back(rss);
    window_ratio.push_back(ratio);
    w = Window{};
  };
  // One handed-over message; the CPU time goes to the scans it made the tracker process.
  auto feed = [&](const std::string& channel, const std::vector<std::uint8_t>& bytes) {
    const std::int64_t before = node.tracks_published();
    const double c0 = ThreadCpuSeconds();
    node.Handle(channel, bytes.data(), bytes.size());
    const std::int64_t n = node.tracks_published() - before;
    if (n > 0) {
      const double ms = (ThreadCpuSeconds() - c0) * 1e3 / static_cast<double>(n);
      for (std::int64_t i = 0; i < n; ++i) w.scan_cpu_ms.push_back(ms);
      w.scans += static_cast<int>(n);
    }
  };
  for (std::int64_t lap_start = start; lap_start < end; lap_start += lap_us) {
    int i = 0, k = 0;
    const int n_scans = sim->NumScans(), n_poses = sim->NumPoses();
    while ((i < n_scans || k < n_poses)) {
      const bool pose_next = k < n_poses && (i >= n_scans || sim->PoseOffsetUs(k) <= sim->ScanPublishOffsetUs(i));
      const std::int64_t t = lap_start + (pose_next ? sim->PoseOffsetUs(k) : sim->ScanPublishOffsetUs(i));
      if (t >= end) break;
      if (t >= next_report) {
        report(next_report);
        next_report += every_us;
      }
      if (pose_next) {
        sim->MakePose(k++, lap_start, &pose);
        feed("EGO_POSE", Encode(pose));
      } else {
        const double c0 = ThreadCpuSeconds();
        sim->MakeScan(i++, lap_start, seq++, &scan, &truth);
        w.sim_cpu_s += ThreadCpuSeconds() - c0;
        feed("LADAR_SCAN", Encode(scan));
      }
    }
  }
  node.Flush();
  report(end);

  const Tracker& tr = node.tracker();
  const tracker_status_t st = node.Status();
  std::printf("\nscans received %lld, processed %lld, dropped %lld, queued %zu; decode errors %lld; resets %lld\n",
              static_cast<long long>(tr.scans_received()), static_cast<long long>(tr.scans_processed()),
              static_cast<long long>(tr.scans_dropped()), tr.queued_scans(),
              static_cast<long long>(st.decode_errors), static_cast<long long>(st.resets));
  std::printf("rejects:");
  for (int r = 0; r < st.num_reasons; ++r) std::printf(" %s=%lld", st.reject_reason[r].c_str(), static_cast<long long>(st.reject_count[r]));
  std::printf("\ntrack ids: %lld issued (max id), %zu ended, %lld reused; %lld TRACKS messages, %lld with bad content\n",
              static_cast<long long>(max_id + 1), gone.size(), static_cast<long long>(id_reuse),
              static_cast<long long>(tracks_msgs), static_cast<long long>(bad_tracks));

  // Verdict: memory and time after the first window (warm-up: buffers and track population
  // reach their working size) against the last one.
  bool ok = true;
  auto check = [&](bool pass, const std::string& what) {
    std::printf("%s %s\n", pass ? "PASS" : "FAIL", what.c_str());
    ok = ok && pass;
  };
  const std::size_t nw = window_rss.size();
  if (nw >= 2) {
    const double growth = window_rss.back() - window_rss.front();
    const double max_rss = *std::max_element(window_rss.begin(), window_rss.end());
    char b[256];
    std::snprintf(b, sizeof b, "memory: RSS %.1f MB after the first window, %.1f MB at the end (%+.1f MB, max %.1f; limit +%.0f MB)",
                  window_rss.front(), window_rss.back(), growth, max_rss, max_growth_mb);
    check(growth <= max_growth_mb, b);
    const double first = window_median_ms.front(), last = window_median_ms.back();
    const double r0 = window_ratio.front(), r1 = window_ratio.back();
    std::snprintf(b, sizeof b, "time per scan: median %.2f ms in the first window, %.2f ms in the last (x%.2f); "
                  "over the simulator's time: %.2f, %.2f (x%.2f; limit x%.2f)",
                  first, last, first > 0 ? last / first : 0.0, r0, r1, r0 > 0 ? r1 / r0 : 0.0, max_slowdown);
    check(r0 <= 0 || r1 <= r0 * max_slowdown, b);
  } else {
    check(false, "too short for a verdict: fewer than two report windows");
  }
  check(id_reuse == 0, "no track id reused (" + std::to_string(id_reuse) + ")");
  check(st.resets == 0, "no tracker reset on a continuous clock (" + std::to_string(st.resets) + ")");
  check(tr.scans_received() == tr.scans_processed() + tr.scans_dropped() + static_cast<std::int64_t>(tr.queued_scans()),
        "scans received = processed + dropped + queued");
  check(bad_tracks == 0, "every TRACKS message decodes with finite positions");
  return ok ? 0 : 1;
}

}  // namespace
}  // namespace vtrack

int main(int argc, char** argv) {
  // The memory settings of vtrack-tracker, so that its resident size is what is measured.
  if (!vtrack::lcm_util::KeepFreedMemory()) std::fprintf(stderr, "vtrack-soak: glibc refused to keep freed memory\n");
  po::options_description desc("Options");
  desc.add_options()("help,h", "print this help and exit");
  vtrack::sim::AddScenarioOptions(&desc, false);
  vtrack::sim::AddSensorOptions(&desc);
  vtrack::sim::AddPoseOptions(&desc);
  desc.add_options()
      ("config", po::value<std::string>()->default_value(VTRACK_DEFAULT_TRACKER_CONFIG), "tracker parameters (YAML)")
      ("mode", po::value<std::string>(), "mht | ism | vasm (default: the config's)")
      ("minutes", po::value<double>()->default_value(30.0), "[min] simulated time to run, lap after lap")
      ("report-every", po::value<double>()->default_value(60.0), "[s] simulated time between report lines")
      ("max-rss-growth-mb", po::value<double>()->default_value(50.0), "[MB] allowed RSS growth after the first window")
      ("max-slowdown", po::value<double>()->default_value(1.5), "[-] allowed growth of the median time per scan (over the simulator's, to divide out the machine's load) from the first window to the last");
  po::variables_map vm;
  try {
    if (!vtrack::sim::ParseCommandLine(argc, argv, desc,
                                       "usage: vtrack-soak [--scenario urban_intersection] [--minutes 30] [options]\n"
                                       "Runs the tracker on the scenario lap after lap (simulated time, as fast as possible)\n"
                                       "and reports memory, time per scan and track ids; exit 1 if a check fails.",
                                       &vm)) {
      return 0;
    }
    if (!vm.count("scenario")) {
      // AddScenarioOptions has no default: the soak's is the demo scene.
      std::vector<std::string> args(argv, argv + argc);
      args.push_back("--scenario=urban_intersection");
      std::vector<char*> av;
      for (auto& a : args) av.push_back(a.data());
      vm.clear();
      po::store(po::parse_command_line(static_cast<int>(av.size()), av.data(), desc), vm);
      po::notify(vm);
    }
  } catch (const po::error& e) {
    std::fprintf(stderr, "vtrack-soak: %s (see --help)\n", e.what());
    return 2;
  }
  try {
    return vtrack::Run(vm);
  } catch (const po::error& e) {
    std::fprintf(stderr, "vtrack-soak: %s (see --help)\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vtrack-soak: %s\n", e.what());
    return 1;
  }
}
