// vtrack-tracker: tracks vehicles from LADAR_SCAN + EGO_POSE and publishes TRACKS,
// TRACKER_STATUS and (with --debug) TRACK_DEBUG.
//
//   live on the bus:   vtrack-tracker [--config F] [--mode mht|ism|vasm|cv] [--lcm-url URL]
//   over a log file:   vtrack-tracker --input run.lcm --output tracks.lcm [--mode ...] [--debug]
//
// Both ways go through the same TrackerNode and the same core calls; estimation uses message
// time only. See tracker/README.md.
#include <boost/program_options.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <string>

#include "lcmtypes/util/command_line.h"
#include "lcmtypes/util/log_reader.h"
#include "lcmtypes/util/process.h"
#include "tracker/config.h"
#include "tracker/tracker_node.h"

namespace po = boost::program_options;
using namespace vtrack;

namespace {

#ifndef VTRACK_DEFAULT_TRACKER_CONFIG
#define VTRACK_DEFAULT_TRACKER_CONFIG ""
#endif

// LADAR_SCAN messages of a 64-beam sensor are ~2 MB: without a large socket buffer most are lost.
std::string WithReceiveBuffer(std::string url) {
  if (url.empty()) {
    const char* env = std::getenv("LCM_DEFAULT_URL");
    url = (env && *env) ? env : "udpm://239.255.76.67:7667?ttl=0";
  }
  if (url.rfind("udpm://", 0) != 0 || url.find("recv_buf_size=") != std::string::npos) return url;
  return url + (url.find('?') == std::string::npos ? "?" : "&") + "recv_buf_size=4194304";
}

// LCM queues at most 30 messages per subscription (LCM's default) between its receive thread and
// handle(), and beyond that drops them without a word. A tracker stalled for a moment (a slow
// scan, a descheduled process, SIGSTOP) finds on resuming everything the socket buffer held, and
// the receive thread reads it faster than the tracker handles it: at 100 Hz 30 poses are 0.3 s.
// The queues are sized for a stall of kStallToAbsorbS at the highest rate expected on each
// channel; whatever is lost anyway is counted (scan_seq_gap, pose_gap, detections_seq_gap).
// kStallToAbsorbS: the longest any track coasts (manager.parked_coast_max_s): after a longer
// stall every track has ended, and older input would only be processed to be discarded.
constexpr double kStallToAbsorbS = 3.0;  // [s]
// Poses: 3 s at 200 Hz (an INS; vtrack-ego-pose sends 100 Hz) = 600, with margin. A pose_t is
// 200 bytes: 0.2 MB at most.
constexpr int kPoseQueue = 1000;
// Scans and detection lists: 3 s at 25 Hz (the fastest simulated sensor, a single-plane one of
// ~10 KB per sweep) = 75, with margin. Memory bound: 3 s of 64-layer sweeps at 10 Hz are 30 x
// 2.8 MB = 84 MB; the whole queue, 100 x 2.8 MB = 280 MB, only if the tracker fell 10 s behind.
constexpr int kScanQueue = 100;
static_assert(kPoseQueue >= 200 * kStallToAbsorbS && kScanQueue >= 25 * kStallToAbsorbS &&
              lcm_util::kSliceQueueCapacity >= 45 * 10 * kStallToAbsorbS);

class LiveHandler {
 public:
  explicit LiveHandler(TrackerNode* node) : node_(node) {}
  void OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    node_->Handle(channel, rbuf->data, rbuf->data_size);
  }

 private:
  TrackerNode* node_;
};

int RunLive(const TrackerParams& params, NodeOptions options, const std::string& url_in,
            double status_period_s) {
  const std::string url = WithReceiveBuffer(url_in);
  auto lcm = lcm_util::OpenLcm(url);
  // Ids unique across restarts: a consumer must never see an id that meant another vehicle.
  if (options.first_track_id <= 0) options.first_track_id = FirstTrackIdAt(lcm_util::WallUtime());
  // Live, sweeps come ~100 ms apart: pinned threads answer sooner (compute.pin_threads).
  Tracker::AllowThreadPinning(true);
  TrackerNode node(params, options,
                   [&](std::int64_t, const std::string& ch, const void* data, std::size_t size) {
                     lcm->publish(ch, data, static_cast<unsigned int>(size));
                   });
  LiveHandler handler(&node);
  lcm->subscribe(options.scan_channel, &LiveHandler::OnMessage, &handler)->setQueueCapacity(kScanQueue);
  // A sweep's slices come in a burst of dozens while the previous sweep is processed: LCM's
  // default queue of 30 messages per subscription would drop the rest of the sweep.
  lcm->subscribe(options.slice_channel, &LiveHandler::OnMessage, &handler)
      ->setQueueCapacity(lcm_util::kSliceQueueCapacity);
  lcm->subscribe(options.pose_channel, &LiveHandler::OnMessage, &handler)->setQueueCapacity(kPoseQueue);
  if (params.detections.mode != InputMode::kScans) {
    lcm->subscribe(options.detections_channel, &LiveHandler::OnMessage, &handler)
        ->setQueueCapacity(kScanQueue);
  }
  std::fprintf(stderr, "vtrack-tracker: live on %s, mode %s, %s + %s -> %s%s\n", url.c_str(),
               ToString(params.manager.mode), options.scan_channel.c_str(),
               options.pose_channel.c_str(), options.tracks_channel.c_str(),
               options.debug ? (" + " + options.debug_channel).c_str() : "");
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(status_period_s));
  auto next_status = std::chrono::steady_clock::now() + period;
  while (!lcm_util::StopRequested()) {
    if (lcm->handleTimeout(100) < 0) {
      if (lcm_util::StopRequested()) break;  // the stop signal interrupted the wait
      std::fprintf(stderr, "vtrack-tracker: LCM handle failed on %s\n", url.c_str());
      return 1;
    }
    if (std::chrono::steady_clock::now() >= next_status) {
      node.PublishStatus(node.tracker().latest_utime());
      next_status += period;
    }
  }
  node.Flush();
  node.PublishStatus(node.tracker().latest_utime());
  std::fprintf(stderr, "vtrack-tracker: stopped after %lld scans (%lld processed, %lld dropped)\n",
               static_cast<long long>(node.tracker().scans_received()),
               static_cast<long long>(node.tracker().scans_processed()),
               static_cast<long long>(node.tracker().scans_dropped()));
  std::fprintf(stderr, "vtrack-tracker: %lld slices received; %lld returns received, %lld processed\n",
               static_cast<long long>(node.assembler().slices_accepted()),
               static_cast<long long>(node.returns_received()),
               static_cast<long long>(node.tracker().returns_processed()));
  return 0;
}

int RunOffline(const TrackerParams& params, const NodeOptions& options, const std::string& input,
               const std::string& output, double status_period_s, bool quiet) {
  lcm_util::LogReader reader(input);
  // Neither output is truncated before both can be written: the log's place checked, then the
  // node (which creates the evidence CSV), then the log.
  if (const std::string why = lcm_util::WhyNotWritable(output); !why.empty()) {
    throw std::runtime_error("cannot create LCM log '" + output + "': " + why);
  }
  std::unique_ptr<lcm_util::LogWriter> writer;
  TrackerNode node(params, options,
                   [&](std::int64_t t, const std::string& ch, const void* data, std::size_t size) {
                     writer->Write(t, ch, data, size);
                   });
  writer = std::make_unique<lcm_util::LogWriter>(output);
  const auto start = std::chrono::steady_clock::now();
  auto next_progress = start + std::chrono::seconds(2);
  const auto status_period_us = static_cast<std::int64_t>(status_period_s * 1e6);
  std::int64_t last_status = 0;
  std::int64_t events = 0;
  std::map<std::string, std::int64_t> channels;  // events per channel: what a log held instead
  while (const lcm::LogEvent* ev = reader.Next()) {
    if (lcm_util::StopRequested()) break;
    ++events;
    ++channels[ev->channel];
    node.Handle(ev->channel, ev->data, static_cast<std::size_t>(ev->datalen));
    const std::int64_t t = node.tracker().latest_utime();
    if (t != 0 && (last_status == 0 || t >= last_status + status_period_us || t < last_status)) {
      node.PublishStatus(t);
      last_status = t;
    }
    if (!quiet && (events & 63) == 0 && std::chrono::steady_clock::now() >= next_progress) {
      next_progress += std::chrono::seconds(2);
      const double pct = reader.FileSize() > 0 ? 100.0 * reader.BytesRead() / reader.FileSize() : 0.0;
      std::fprintf(stderr, "vtrack-tracker: %5.1f%% of %s, %lld scans processed\n", pct,
                   input.c_str(), static_cast<long long>(node.tracker().scans_processed()));
    }
  }
  node.Flush();
  node.PublishStatus(node.tracker().latest_utime());
  const double secs =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const tracker_status_t s = node.Status();
  std::fprintf(stderr,
               "vtrack-tracker: %s -> %s: %lld scans received, %lld processed, %lld dropped, "
               "%lld poses, %lld decode errors, %lld resets, in %.1f s\n",
               input.c_str(), output.c_str(), static_cast<long long>(s.scans_received),
               static_cast<long long>(s.scans_processed), static_cast<long long>(s.scans_dropped),
               static_cast<long long>(s.poses_received), static_cast<long long>(s.decode_errors),
               static_cast<long long>(s.resets), secs);
  for (int i = 0; i < s.num_reasons; ++i) {
    std::fprintf(stderr, "vtrack-tracker:   rejected %-20s %lld\n", s.reject_reason[i].c_str(),
                 static_cast<long long>(s.reject_count[i]));
  }
  // Nothing to track is said: a wrong channel name or input mode gives an empty result otherwise.
  const bool boxes = params.detections.mode == InputMode::kBoxes;
  const std::int64_t inputs = boxes ? (channels.count(options.detections_channel)
                                           ? channels.at(options.detections_channel) : 0)
                                    : s.scans_received;
  if (inputs == 0 && !lcm_util::StopRequested()) {
    std::string seen;
    for (const auto& [name, n] : channels) {
      seen += (seen.empty() ? "" : ", ") + name + " (" + std::to_string(n) + ")";
    }
    const std::string wanted = boxes ? options.detections_channel
                                     : options.scan_channel + " or " + options.slice_channel;
    const std::string undecodable =
        s.decode_errors > 0 ? "; " + std::to_string(s.decode_errors) + " messages could not be decoded" : "";
    std::fprintf(stderr, "vtrack-tracker: warning: nothing to track: no %s message in %s (%s%s)\n",
                 wanted.c_str(), input.c_str(),
                 seen.empty() ? "the log holds no message" : ("channels: " + seen).c_str(),
                 undecodable.c_str());
  }
  if (reader.damaged()) {
    std::fprintf(stderr, "vtrack-tracker: %s\n", reader.DamageSummary().c_str());
    return 3;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // A sweep's memory kept for the next sweep (lcmtypes/util/process.h).
  if (!vtrack::lcm_util::KeepFreedMemory()) {
    std::fprintf(stderr, "vtrack-tracker: glibc refused to keep freed memory (mallopt); running with its defaults\n");
  }
  std::string config, mode, input_mode, input, output, url;
  std::int64_t first_track_id = 0;
  NodeOptions options;
  double status_period = 1.0;
  po::options_description desc(
      "vtrack-tracker: vehicle tracking from a scanning LADAR (LADAR_SCAN + EGO_POSE -> TRACKS).\n"
      "Live on the LCM bus by default; over a log file with --input/--output.\nOptions");
  desc.add_options()
      ("help,h", "show this help")
      ("config", po::value(&config)->default_value(VTRACK_DEFAULT_TRACKER_CONFIG),
       "tracker parameters (YAML, see config/tracker.yaml); empty: built-in defaults")
      ("mode", po::value(&mode), "mht (default) | ism | vasm | cv: overrides the config's manager.mode")
      ("input-mode", po::value(&input_mode),
       "scans (default) | boxes | fused: what tracks are measured with (LADAR_SCAN, a detector's "
       "DETECTIONS, or both); overrides the config's detections.mode")
      ("input", po::value(&input), "LCM log to track offline, as fast as possible")
      ("output", po::value(&output), "LCM log to write (with --input): TRACKS, TRACKER_STATUS, TRACK_DEBUG")
      ("debug", po::bool_switch(&options.debug), "also publish TRACK_DEBUG (large)")
      ("evidence-csv", po::value(&options.evidence_csv),
       "write every scan's vehicle-evidence features per track to this CSV (the fitting set of "
       "scripts/fit-vehicle-evidence)")
      ("first-track-id", po::value(&first_track_id),
       "id of the first track (>= 1); default: live, from the start time (start ms x 100000 + 1,\n"
       "so that a restarted tracker never reuses an id), offline 1 (reruns identical)")
      ("seed", po::value(&options.seed)->default_value(options.seed),
       "seed of the fits' random draws (RANSAC): runs with one seed are identical, another seed\n"
       "is another draw of the same data")
      ("lcm-url", po::value(&url)->default_value(""),
       "LCM URL for live mode ('' = $LCM_DEFAULT_URL or LCM's default); recv_buf_size=4194304 "
       "is appended to udpm:// URLs that lack it")
      ("scan-channel", po::value(&options.scan_channel)->default_value("LADAR_SCAN"), "input scans")
      ("slice-channel", po::value(&options.slice_channel)->default_value("LADAR_SLICE"),
       "input sweeps sent as slices (ladar_slice_t)")
      ("pose-channel", po::value(&options.pose_channel)->default_value("EGO_POSE"), "input ego poses")
      ("detections-channel", po::value(&options.detections_channel)->default_value("DETECTIONS"),
       "input detector boxes (input modes boxes and fused)")
      ("tracks-channel", po::value(&options.tracks_channel)->default_value("TRACKS"), "output tracks")
      ("debug-channel", po::value(&options.debug_channel)->default_value("TRACK_DEBUG"), "output debug")
      ("status-channel", po::value(&options.status_channel)->default_value("TRACKER_STATUS"), "output status")
      ("status-period", po::value(&status_period)->default_value(1.0),
       "seconds between TRACKER_STATUS messages (wall time live, message time offline)")
      ("print-config", "print the parameters in effect (--config, --mode, --input-mode applied) "
       "as YAML and exit; with --config '' the built-in defaults (config/tracker.yaml)")
      ("print-parameter-reference", "print every parameter's default, unit, range and reason "
       "(Markdown, docs/parameters.md) and exit")
      ("quiet,q", "no progress output (offline)");
  po::variables_map vm;
  try {
    const po::parsed_options parsed = po::parse_command_line(argc, argv, desc);
    po::store(parsed, vm);
    po::notify(vm);
    // Every argument is an option: a stray one (a log file without --input) would otherwise be
    // ignored and the tracker would go live instead.
    if (!vm.count("help")) lcm_util::RefuseStrayArguments(parsed);
    lcm_util::RefuseEmptyChannels(vm);
    lcm_util::RefuseOverwritingInputs({{"--input", input}, {"--config", config}},
                                      {{"--output", output}, {"--evidence-csv", options.evidence_csv}});
  } catch (const po::error& e) {
    std::cerr << "vtrack-tracker: " << e.what() << "\n(see --help)\n";
    return 2;
  }
  if (vm.count("help")) {
    std::cout << desc << "\n";
    return 0;
  }
  if (vm.count("print-parameter-reference")) {
    WriteParameterReference(std::cout);
    return 0;
  }
  if (input.empty() != output.empty()) {
    std::cerr << "vtrack-tracker: --input and --output go together\n";
    return 2;
  }
  if (options.seed < 0) {
    std::cerr << "vtrack-tracker: --seed " << options.seed << " must be >= 0\n";
    return 2;
  }
  if (vm.count("first-track-id")) {
    if (first_track_id < 1) {
      std::cerr << "vtrack-tracker: --first-track-id " << first_track_id << " must be >= 1\n";
      return 2;
    }
    options.first_track_id = first_track_id;
  } else if (input.empty()) {
    options.first_track_id = 0;  // live: from the start time (RunLive)
  }
  if (!(status_period > 0.0 && status_period <= 3600.0)) {
    std::cerr << "vtrack-tracker: --status-period " << status_period << " must be in (0, 3600]\n";
    return 2;
  }
  try {
    TrackerParams params;
    if (!config.empty()) {
      if (!std::filesystem::exists(config) && config == VTRACK_DEFAULT_TRACKER_CONFIG) {
        std::cerr << "vtrack-tracker: default config " << config
                  << " not found; using built-in defaults\n";
      } else {
        params = LoadTrackerParams(config);
      }
    }
    if (vm.count("mode") && !FromName(mode, &params.manager.mode)) {
      std::cerr << "vtrack-tracker: --mode '" << mode << "' must be mht, ism, vasm or cv\n";
      return 2;
    }
    if (vm.count("input-mode") && !FromName(input_mode, &params.detections.mode)) {
      std::cerr << "vtrack-tracker: --input-mode '" << input_mode << "' must be scans, boxes or fused\n";
      return 2;
    }
    if (!input.empty()) {
      // Offline the scans come back to back, where pinned threads gain nothing, and several
      // runs may share the machine: they would all be pinned to its first CPUs.
      params.compute.pin_threads = false;
    }
    std::string error;
    if (!params.Validate(&error)) {
      std::cerr << "vtrack-tracker: invalid parameters: " << error << "\n";
      return 1;
    }
    if (vm.count("print-config")) {
      WriteConfigYaml(params, std::cout);
      return 0;
    }
    lcm_util::InstallStopHandlers();
    if (!input.empty()) {
      return RunOffline(params, options, input, output, status_period, vm.count("quiet") > 0);
    }
    return RunLive(params, options, url, status_period);
  } catch (const std::exception& e) {
    std::cerr << "vtrack-tracker: " << e.what() << "\n";
    return 1;
  }
}
