// The LCM side of vtrack-tracker: decodes LADAR_SCAN, LADAR_SLICE and EGO_POSE messages
// (checked, through lcm_util::Decode), joins slices into sweeps (lcm_util::SweepAssembler: a
// sweep with lost slices goes on with its lost wedges when the next sweep's slices start, or
// when the poses pass its end by the assembler's timeout), feeds the core Tracker, and hands TRACKS / TRACK_DEBUG / TRACKER_STATUS
// messages to a publish function. The same object serves the live bus and the offline log: only
// the publish function and the status clock differ, so the results cannot depend on how the
// tracker was fed.
#pragma once

#include <cstdint>
#include <deque>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "lcmtypes/util/ladar_slices.h"
#include "lcmtypes/util/process.h"
#include "tracker/core/tracker.h"
#include "vtrack/tracker_status_t.hpp"

namespace vtrack {

struct NodeOptions {
  std::string scan_channel = "LADAR_SCAN";
  std::string slice_channel = "LADAR_SLICE";  // sweeps sent as slices, assembled here
  std::string pose_channel = "EGO_POSE";
  std::string detections_channel = "DETECTIONS";  // read in the input modes boxes and fused
  std::string tracks_channel = "TRACKS";
  std::string debug_channel = "TRACK_DEBUG";
  std::string status_channel = "TRACKER_STATUS";
  bool debug = false;  // publish TRACK_DEBUG
  // If not empty: every scan's vehicle-evidence features of every track it gave returns, as CSV
  // (utime, track_id, x, y, three_d, the features by name, logit, log_odds): the fitting set of
  // scripts/fit-vehicle-evidence.
  std::string evidence_csv;
  // The first track id. Offline: 1 (reruns identical). Live: FirstTrackIdAt(wall clock), so
  // that a restarted tracker never reuses an id that meant another vehicle before.
  std::int64_t first_track_id = 1;
  // The seed of the fits' random draws (Tracker::SetSeed).
  std::int64_t seed = 1;
};

class TrackerNode {
 public:
  // event_utime: the message time the output answers (for log timestamps).
  using PublishFn = std::function<void(std::int64_t event_utime, const std::string& channel,
                                       const void* data, std::size_t size)>;

  // Throws std::invalid_argument if params are invalid.
  TrackerNode(const TrackerParams& params, NodeOptions options, PublishFn publish);

  // One received message. Channels other than scan/pose are ignored. Never throws.
  void Handle(const std::string& channel, const void* data, std::size_t size);
  // Processes every queued scan (end of a log, shutdown).
  void Flush();
  // Publishes TRACKER_STATUS now; event_utime for its log timestamp.
  void PublishStatus(std::int64_t event_utime);
  tracker_status_t Status() const;

  const Tracker& tracker() const { return tracker_; }
  std::int64_t decode_errors() const { return decode_errors_; }
  std::int64_t tracks_published() const { return tracks_published_; }
  const lcm_util::SweepAssembler& assembler() const { return assembler_; }
  // Returns in the scans and slices decoded (before any check of the core).
  std::int64_t returns_received() const { return returns_received_; }

 private:
  // Decodes a message (checked); a bad one is counted by reason and warned about.
  template <class Msg>
  bool DecodeOrCount(const std::string& channel, const void* data, std::size_t size, Msg* msg);
  // The wall time a scan or detection list of this utime arrived (for the latency figures).
  void NoteArrival(std::int64_t utime);
  void Emit(std::vector<ScanOutput>* outs);
  void WriteEvidence(const ScanOutput& o);
  // Hands the sweeps the assembler put together (sweeps_) to the tracker.
  void FeedSweeps();
  void Warn();

  TrackerParams params_;
  NodeOptions options_;
  PublishFn publish_;
  Tracker tracker_;
  lcm_util::RateLimitedLog log_{"vtrack-tracker"};
  std::map<std::string, std::int64_t> decode_reasons_;
  std::int64_t decode_errors_ = 0;
  std::int64_t tracks_published_ = 0;
  std::int64_t returns_received_ = 0;
  std::deque<std::pair<std::int64_t, std::int64_t>> arrival_;  // (scan utime, wall utime)
  std::deque<double> latencies_ms_;
  double last_latency_ms_ = 0.0;
  std::vector<ScanOutput> outs_;
  lcm_util::SweepAssembler assembler_;
  std::vector<lcm_util::AssembledSweep> sweeps_;
  std::vector<std::uint8_t> buffer_;
  std::ofstream evidence_csv_;
  std::int64_t last_tentative_ = 0, last_confirmed_ = 0, last_coasting_ = 0;
};

}  // namespace vtrack
