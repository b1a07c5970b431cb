// End-to-end latency of the live tracker over LCM: a sweep's last return published -> its
// track_list_t received on TRACKS, with the real vtrack-tracker process, full KITTI HDL-64E scans
// (sequence 0000, 98k-124k returns) at 10 Hz and ego poses at 100 Hz. Two ways to send a sweep:
//   --slices 0     whole, one ladar_scan_t of ~2.7 MB on LADAR_SCAN at the sweep's end (LCM
//                  sends it as 44 fragments; the tracker receives and decodes it all at once);
//   --slices auto  in the azimuth slices vtrack-ladar-driver cuts a 64-beam sweep into (one
//                  datagram each on LADAR_SLICE, 46-47 for these scans), each published when
//                  its own last return is measured (the scan's start plus the slice's largest
//                  dt_us), in that order, as a sensor's packets come: the slices spread over the
//                  sweep's 100 ms and the last one closes it. (The driver itself sends a sweep's
//                  slices in one burst after the sweep, kSliceGapUs apart.)
// The latency runs from the publication of the last return (the whole scan, or the last slice).
// The poses through each scan's last return time are published before the scan (as on a vehicle,
// where the pose source runs ahead of the sweep), so the latency is the sweep's encoding (as
// vtrack-ladar-driver encodes it, lcm_util::Publish) + the bus + decoding + tracking + encoding
// the tracks + the bus, not waiting for poses. The first --warmup scans are not counted.
//
// udpm only inside a private loopback-only network namespace (scripts/vtrack-netns); elsewhere
// it exits 77 (skipped). Wall-clock times (steady clock) of this process.
//
//   scripts/vtrack-netns build/bench/e2e_latency --bin-dir build/bin [--scans 150] [--slices auto] [--json F]
#include <lcm/lcm-cpp.hpp>
#include <poll.h>

#include <boost/program_options.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "lcmtypes/util/encode.h"
#include "lcmtypes/util/ladar_slices.h"
#include "lcmtypes/util/process.h"
#include "sensor_driver/kitti/kitti_sequence.h"
#include "tests/bench/bench_data.h"
#include "tests/bench/bench_options.h"
#include "tests/support/subprocess.h"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/pose_t.hpp"
#include "vtrack/track_list_t.hpp"
#include "vtrack/tracker_status_t.hpp"

namespace po = boost::program_options;
using Clock = std::chrono::steady_clock;

namespace {

struct Receiver {
  std::map<std::int64_t, Clock::time_point> tracks_at;  // scan utime -> TRACKS arrival
  std::map<std::int64_t, double> processing_ms;         // scan utime -> the tracker's latency_us
  bool status_seen = false;
  std::int64_t decode_errors = 0;

  void OnTracks(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    const auto now = Clock::now();
    vtrack::track_list_t msg;
    if (msg.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) < 0) {
      ++decode_errors;
      return;
    }
    tracks_at.emplace(msg.utime, now);
    processing_ms.emplace(msg.utime, 1e-3 * static_cast<double>(msg.latency_us));
  }
  void OnStatus(const lcm::ReceiveBuffer*, const std::string&) { status_seen = true; }
};

// Mean slices per scan with one decimal ("46.9").
std::string FormatSlicesPerScan(long slices, long scans) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", static_cast<double>(slices) / static_cast<double>(scans));
  return buf;
}

// [us] When a slice's last return is measured, after the sweep's start (0 for an empty slice).
std::int32_t LastDt(const vtrack::ladar_slice_t& s) {
  return s.dt_us.empty() ? 0 : *std::max_element(s.dt_us.begin(), s.dt_us.end());
}

}  // namespace

int main(int argc, char** argv) {
  std::string bin_dir, kitti_dir = vtrack::bench::KittiDir(), json, url, log, slices_text = "0";
  int scans = 150, warmup = 10;
  double rate_hz = 10.0;
  po::options_description desc(
      "e2e_latency: a sweep published (whole or as slices) -> TRACKS received, live vtrack-tracker over LCM (udpm, private "
      "network namespace only)\nOptions");
  desc.add_options()("help,h", "show this help")(
      "bin-dir", po::value(&bin_dir)->required(), "directory holding vtrack-tracker")(
      "kitti", po::value(&kitti_dir)->default_value(kitti_dir), "KITTI tracking_0000 directory")(
      "scans", po::value(&scans)->default_value(scans), "scans to publish (frames 1.., cycled)")(
      "warmup", po::value(&warmup)->default_value(warmup), "first scans not counted")(
      "rate-hz", po::value(&rate_hz)->default_value(rate_hz), "scan rate [Hz]")(
      "slices", po::value(&slices_text)->default_value(slices_text),
      "how each sweep is sent: 0 = whole, one message on LADAR_SCAN; auto = in the fewest azimuth "
      "slices that each fit one datagram (46-47 for these scans), N = in N slices (1-4096), on "
      "LADAR_SLICE, each when its last return is measured")(
      "lcm-url", po::value(&url)->default_value("udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608"),
      "LCM URL (udpm)")("tracker-log", po::value(&log)->default_value("/tmp/e2e_latency_tracker.log"),
                        "the tracker's stdout/stderr")("json", po::value(&json), "write the figures here");
  if (const auto status = vtrack::bench::ParseOptions("e2e_latency", desc, argc, argv)) return *status;
  if (scans <= warmup || scans < 1 || warmup < 0 || !(rate_hz > 0.0 && rate_hz <= 100.0)) {
    std::cerr << "e2e_latency: need scans > warmup >= 0 and rate-hz in (0, 100]; got scans=" << scans
              << " warmup=" << warmup << " rate-hz=" << rate_hz << "\n";
    return 2;
  }
  const std::optional<int> slices_option = vtrack::lcm_util::ParseSlicesOption(slices_text);
  if (!slices_option) {
    std::cerr << "e2e_latency: --slices must be auto, 0 or a count in [1, "
              << vtrack::lcm_util::kMaxSlicesPerSweep << "]; got '" << slices_text << "'\n";
    return 2;
  }
  if (url.rfind("udpm://", 0) == 0 && !vtrack::lcm_util::InPrivateLoopbackNamespace()) {
    std::cerr << "e2e_latency: not in a private loopback-only network namespace; run through "
                 "scripts/vtrack-netns so multicast stays on this machine (skipped)\n";
    return 77;
  }

  // Scans and poses, prepared before the clock starts.
  vtrack::kitti::SequenceOptions o;
  o.dir = kitti_dir;
  o.cache_dir = VTRACK_BINARY_DIR "/kitti_cache";
  std::vector<vtrack::ladar_scan_t> frames;
  std::vector<std::vector<vtrack::ladar_slice_t>> frame_slices;  // per frame; empty: sent whole
  std::unique_ptr<vtrack::kitti::Sequence> seq;
  try {
    seq = std::make_unique<vtrack::kitti::Sequence>(o);
    const int n = std::min(seq->num_frames() - 1, scans);
    std::fprintf(stderr, "e2e_latency: reading %d KITTI frames\n", n);
    for (int i = 1; i <= n; ++i) frames.push_back(seq->Scan(i));
    for (vtrack::ladar_scan_t& f : frames) {
      const int count = vtrack::lcm_util::SlicesFor(*slices_option, f);
      std::vector<vtrack::ladar_slice_t> slices;
      if (count > 0) slices = vtrack::lcm_util::SliceSweep(f, count);
      // In the order their last returns are measured: the slicer follows the order of the
      // returns in the file, which for KITTI (laser by laser, each in increasing azimuth) is not
      // the order of the nominal per-return times (clockwise from behind, kitti_scan.h).
      std::stable_sort(slices.begin(), slices.end(), [](const vtrack::ladar_slice_t& a, const vtrack::ladar_slice_t& b) {
        return LastDt(a) < LastDt(b);
      });
      if (!slices.empty()) {  // only the header is sent whole from now on
        for (auto* v : {&f.x, &f.y, &f.z, &f.intensity}) std::vector<float>().swap(*v);
        std::vector<std::int32_t>().swap(f.dt_us);
        std::vector<std::int16_t>().swap(f.ring);
        f.npoints = 0;
      }
      frame_slices.push_back(std::move(slices));
    }
  } catch (const std::exception& e) {
    std::cerr << "e2e_latency: KITTI data or its slices: " << e.what() << "\n";
    return 1;
  }

  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::cerr << "e2e_latency: cannot open LCM at " << url << "\n";
    return 1;
  }
  Receiver rx;
  lcm.subscribe("TRACKS", &Receiver::OnTracks, &rx);
  lcm.subscribe("TRACKER_STATUS", &Receiver::OnStatus, &rx);
  // Handles messages until deadline, waiting on LCM's socket with ppoll() and its nanosecond
  // timeout: handleTimeout counts whole milliseconds, so the last millisecond before each slice
  // would be a busy poll, and with ~47 slices a sweep that poll held most of a core that the
  // tracker shares on a 2-core machine. ppoll() may wake late by the kernel's timer slack
  // (~50 us), never early, so no slice goes out before its time.
  const int lcm_fd = lcm.getFileno();
  if (lcm_fd < 0) {
    std::cerr << "e2e_latency: LCM gives no file descriptor to wait on\n";
    return 1;
  }
  bool bus_failed = false;
  std::string bus_error;
  auto handle_until = [&](Clock::time_point deadline) {
    while (!bus_failed) {
      const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - Clock::now()).count();
      if (left <= 0) return;
      pollfd readable{lcm_fd, POLLIN, 0};
      const timespec timeout{static_cast<time_t>(left / 1'000'000'000), static_cast<long>(left % 1'000'000'000)};
      const int r = ppoll(&readable, 1, &timeout, nullptr);
      if (r < 0 && errno != EINTR) {
        bus_error = std::string("ppoll: ") + std::strerror(errno);
        bus_failed = true;
      } else if (r > 0 && lcm.handle() != 0) {
        bus_error = "lcm handle() failed";
        bus_failed = true;
      }
    }
  };

  vtrack::testing::Subprocess tracker({bin_dir + "/vtrack-tracker", "--lcm-url", url}, log);
  // Ready once it publishes its status (it subscribes before its first status).
  const auto ready_deadline = Clock::now() + std::chrono::seconds(20);
  while (!rx.status_seen && !bus_failed && Clock::now() < ready_deadline) handle_until(Clock::now() + std::chrono::milliseconds(100));
  if (bus_failed) {
    std::cerr << "e2e_latency: waiting on the LCM bus failed: " << bus_error << "\n";
    return 1;
  }
  if (!rx.status_seen) {
    std::cerr << "e2e_latency: no TRACKER_STATUS from vtrack-tracker within 20 s (log: " << log << ")\n";
    return 1;
  }

  // Message times advance by the scan period on every cycle through the frames.
  const std::int64_t period_us = static_cast<std::int64_t>(1e6 / rate_hz);
  const std::int64_t first = frames.front().utime;
  const std::int64_t seq_span = frames.back().utime + period_us - first;
  std::int64_t next_pose = seq->FirstPoseUtime() + 10'000;
  std::map<std::int64_t, Clock::time_point> published;
  std::vector<std::uint8_t> cloud_buffer;  // encoded as vtrack-ladar-driver does (encode.h)
  std::vector<std::int64_t> counted;
  long sliced_scans = 0, slices_sent = 0;
  auto tick = Clock::now();
  for (int k = 0; k < scans; ++k) {
    const std::size_t f = static_cast<std::size_t>(k) % frames.size();
    const std::int64_t shift = static_cast<std::int64_t>(k / frames.size()) * seq_span;
    vtrack::ladar_scan_t& scan = frames[f];
    const std::int64_t orig_utime = scan.utime;
    scan.utime = orig_utime + shift;
    scan.seq = k;
    const std::int64_t end = scan.utime + scan.sweep_duration_us;
    for (; next_pose <= end + 10'000; next_pose += 10'000) {
      const std::int64_t t = next_pose - (next_pose - first) / seq_span * seq_span;  // in the sequence
      vtrack::pose_t p = seq->PoseAt(std::clamp(t, seq->FirstPoseUtime(), seq->LastPoseUtime()));
      p.utime = next_pose;
      lcm.publish("EGO_POSE", &p);
    }
    std::vector<vtrack::ladar_slice_t>& slices = frame_slices[f];
    if (slices.empty()) {
      published[scan.utime] = Clock::now();
      vtrack::lcm_util::Publish(&lcm, "LADAR_SCAN", scan, &cloud_buffer);
    } else {
      // Each slice when its last return is measured, from the scan's start (this tick); TRACKS
      // of the scan before are taken in the gaps.
      for (vtrack::ladar_slice_t& slice : slices) {
        handle_until(tick + std::chrono::microseconds(LastDt(slice)));
        slice.utime = scan.utime;
        slice.seq = k;
        published[scan.utime] = Clock::now();
        vtrack::lcm_util::Publish(&lcm, "LADAR_SLICE", slice, &cloud_buffer);
        slice.utime = orig_utime;
      }
      sliced_scans += 1;
      slices_sent += static_cast<long>(slices.size());
    }
    if (k >= warmup) counted.push_back(scan.utime);
    scan.utime = orig_utime;
    tick += std::chrono::microseconds(period_us);
    handle_until(tick);
    if (k % 50 == 49) std::fprintf(stderr, "e2e_latency: %d/%d scans published\n", k + 1, scans);
  }
  handle_until(Clock::now() + std::chrono::seconds(2));
  if (bus_failed) {
    std::cerr << "e2e_latency: waiting on the LCM bus failed: " << bus_error << "\n";
    return 1;
  }
  const int status = tracker.Stop();

  std::vector<double> ms, proc;
  int lost = 0;
  for (const std::int64_t u : counted) {
    const auto it = rx.tracks_at.find(u);
    if (it == rx.tracks_at.end()) {
      ++lost;
      continue;
    }
    ms.push_back(std::chrono::duration<double, std::milli>(it->second - published[u]).count());
    proc.push_back(rx.processing_ms[u]);
  }
  if (ms.empty()) {
    std::cerr << "e2e_latency: no TRACKS answered a counted scan (log: " << log << ")\n";
    return 1;
  }
  const double med = vtrack::bench::Percentile(ms, 50), p99 = vtrack::bench::Percentile(ms, 99),
               mx = vtrack::bench::Percentile(ms, 100);
  // The tracker's own latency_us: from the sweep being ready (the whole scan received and
  // decoded, or put together from its slices) to publishing TRACKS; the rest is the bus
  // (fragmentation, loopback, reassembly), the decoding and the putting together.
  const double proc_med = vtrack::bench::Percentile(proc, 50), proc_p99 = vtrack::bench::Percentile(proc, 99);
  const std::string sent =
      sliced_scans == 0 ? std::string("whole scans on LADAR_SCAN")
                        : FormatSlicesPerScan(slices_sent, sliced_scans) + " slices a scan on LADAR_SLICE";
  std::printf("e2e latency over LCM (%zu scans at %.0f Hz, %s, %zu answered, %d lost): median %.2f ms, p99 %.2f ms, max %.2f ms; "
              "in the tracker (sweep ready to publish): median %.2f ms, p99 %.2f ms\n",
              counted.size(), rate_hz, sent.c_str(), ms.size(), lost, med, p99, mx, proc_med, proc_p99);
  if (!json.empty()) {
    std::ofstream os(json);
    os << "{\"e2e_latency_ms_median\": " << med << ", \"e2e_latency_ms_p99\": " << p99
       << ", \"e2e_latency_ms_max\": " << mx << ", \"e2e_tracker_ms_median\": " << proc_med
       << ", \"e2e_tracker_ms_p99\": " << proc_p99 << ", \"e2e_scans\": " << counted.size()
       << ", \"e2e_lost\": " << lost << ", \"e2e_rate_hz\": " << rate_hz
       << ", \"e2e_slices_per_scan\": " << (sliced_scans == 0 ? 0.0 : static_cast<double>(slices_sent) / sliced_scans)
       << ", \"tracker_exit_status\": " << status << "}\n";
  }
  return 0;
}
