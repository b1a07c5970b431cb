// The tracker: plain structs in (scans, ego poses), plain structs out (track lists, debug,
// counters by reason). No LCM, no files, no clock: the same calls give the same results whether
// the adapter feeds it from the bus or from a log.
//
// Sequencing (message time only). Poses go into a PoseHistory. Scans wait in a queue, in order,
// until the pose stream has reached the scan's last return time (utime + sweep_duration_us), so
// that every return is compensated with an interpolated pose. If the poses stall, a scan is
// processed anyway once any message is max_pose_wait_us later than that time, with the pose
// extrapolated (counted). Flush() processes what is queued (end of a log, shutdown).
//
// Per scan: Preprocessor (compensation, ground) -> Segmenter -> TrackManager::Predict to the
// middle of the sweep -> Associator -> per track: TrackManager::Update with its returns at
// their mean measurement time -> new tracks from unclaimed segments -> life cycle -> Report at
// the scan's utime (the time of the ground truth and of track_list_t.utime).
//
// Bad input is dropped and counted by reason (rejects()): see the reason keys in tracker.cc and
// tracker/README.md. A message more than time_jump_reset_us older than the newest one (a
// looped log) resets the tracker: tracks, poses and queue are cleared, ids continue.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "tracker/core/association.h"
#include "tracker/core/ekf.h"
#include "tracker/core/pose.h"
#include "tracker/core/preprocess.h"
#include "tracker/core/scan.h"
#include "tracker/core/segmentation.h"
#include "tracker/core/track_manager.h"
#include "tracker/core/tracker_params.h"

namespace vtrack {

// The tracker's answer to one scan.
struct ScanOutput {
  std::int64_t utime = 0;       // [us] the scan's utime: the time of every reported state
  std::int64_t seq = 0;
  std::vector<TrackReport> tracks;
  // Filled when debug output is on.
  std::int32_t num_segments = 0;
  std::vector<TrackDebug> debug;
  PreprocessStats stats;
};

// Something the adapter should warn about (rate-limited); the reason is the counter key.
struct TrackerEvent {
  std::string reason;
  std::string message;
};

class Tracker {
 public:
  // Throws std::invalid_argument naming the first invalid parameter.
  explicit Tracker(const TrackerParams& params, bool debug = false);

  // Each may process queued scans; their outputs are appended to *out in scan order.
  void AddPose(const EgoPose& pose, std::vector<ScanOutput>* out);
  void AddScan(LadarScan&& scan, std::vector<ScanOutput>* out);
  void Flush(std::vector<ScanOutput>* out);

  // Counters since construction.
  std::int64_t scans_received() const { return scans_received_; }
  std::int64_t scans_processed() const { return scans_processed_; }
  std::int64_t scans_dropped() const { return scans_dropped_; }
  std::int64_t poses_received() const { return poses_received_; }
  std::int64_t resets() const { return resets_; }
  const std::map<std::string, std::int64_t>& rejects() const { return rejects_; }
  std::int64_t latest_utime() const { return latest_utime_; }  // newest message time seen
  std::size_t queued_scans() const { return queue_.size(); }
  // Events since the last call (for rate-limited warnings).
  std::vector<TrackerEvent> TakeEvents();

  const TrackManager& manager() const { return *manager_; }
  const TrackerParams& params() const { return params_; }

 private:
  void Reject(const std::string& reason, std::int64_t count, const std::string& message);
  bool CheckTime(std::int64_t utime, const char* what);
  void ProcessReady(bool flush, std::vector<ScanOutput>* out);
  bool Process(const LadarScan& scan, bool forced, ScanOutput* out);
  void Reset(const std::string& why);

  TrackerParams params_;
  bool debug_;
  std::unique_ptr<Ekf> ekf_;
  std::unique_ptr<TrackManager> manager_;
  Preprocessor preprocessor_;
  Segmenter segmenter_;
  Associator associator_;
  PoseHistory poses_;
  std::deque<LadarScan> queue_;

  // Scratch reused from scan to scan.
  WorldPoints points_;
  Segments segments_;
  std::vector<PredictedObject> predicted_;
  AssociationResult association_;
  PointSet point_set_;
  std::vector<OrientedBox> created_;
  RangeProfile profile_;  // nearest return per bearing of the scan being processed
  std::vector<std::pair<std::int64_t, std::int32_t>> thin_;
  std::vector<float> thin_x_, thin_y_;
  struct RingSpan {
    std::int16_t ring;
    double lo, hi;  // [m] range of the ring's returns in a segment
  };
  std::vector<RingSpan> ring_span_;

  std::int64_t latest_utime_ = 0;
  bool have_time_ = false;
  std::int64_t last_scan_utime_ = 0;
  bool have_scan_ = false;
  std::int64_t last_seq_ = 0;  // newest scan seq received (for scan_seq_gap)
  bool have_seq_ = false;
  std::int64_t scans_received_ = 0, scans_processed_ = 0, scans_dropped_ = 0;
  std::int64_t poses_received_ = 0, resets_ = 0;
  std::map<std::string, std::int64_t> rejects_;
  std::vector<TrackerEvent> events_;
};

}  // namespace vtrack
