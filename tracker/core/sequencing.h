// Sequencing of the tracker's input, by message time only (never the wall clock). Poses go into
// a PoseHistory. Scans wait in a queue, in order, until the pose stream has reached the scan's
// last return time (utime + sweep_duration_us), so that every return is compensated with an
// interpolated pose. If the poses stall, a scan is released anyway once any message is
// max_pose_wait_us later than that time, with the pose extrapolated.
//
// Bad input is refused and counted by reason (RejectCounter): malformed scans and poses, scans
// out of time order or repeated, scans lost on the way (gaps in the sensor's seq), a full
// queue, poses lost on the way (gaps in their timing). Every scan that is received and not
// processed is counted under exactly one scan reason (see tracker/README.md), so that
// scans_dropped equals their sum. A message more than time_jump_reset_us older than the newest one (a looped log), or
// newer than the newest by more than any track may coast, is refused ("time_jump_unconfirmed")
// unless the message before it made the same jump: two in a row reset the input (queue and
// poses cleared, the caller clears its tracks) and the second is taken. One stray message
// cannot wipe the tracks.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <string>
#include <vector>

#include "tracker/core/detections.h"
#include "base/pose.h"
#include "tracker/core/scan.h"
#include "tracker/core/parameters.h"

namespace vtrack {

// Something the adapter should warn about (rate-limited); the reason is the counter key.
struct TrackerEvent {
  std::string reason;
  std::string message;
};

// What was refused, counted by reason, and the events to warn about.
class RejectCounter {
 public:
  // Adds count (nothing if <= 0) to reason's counter and keeps the message for a warning.
  void Count(const std::string& reason, std::int64_t count, const std::string& message);
  // An event that is not a refusal (a reset).
  void Event(const std::string& reason, const std::string& message);
  const std::map<std::string, std::int64_t>& counts() const { return counts_; }
  std::vector<TrackerEvent> TakeEvents();

 private:
  // Events kept between two TakeEvents() at the most: a flood of bad input must not grow them
  // without bound while the adapter is not reading them.
  static constexpr std::size_t kMaxEvents = 1000;
  std::map<std::string, std::int64_t> counts_;
  std::vector<TrackerEvent> events_;
};

// Messages lost on the way from a stream without a sequence number (the ego poses), inferred
// from its timing: an interval longer than kGapFactor nominal periods means
// round(interval / period) - 1 messages missing. The nominal period is estimated from the stream
// itself from its last kWindow intervals (once kMinIntervals are known): the mean of those within
// half a median of their median. Robust to the gaps themselves and to jitter, precise enough
// for long gaps, and it follows a source that changes its rate (once most intervals have).
class StreamGapCounter {
 public:
  // A gap longer than this many periods counts: a late message (jitter up to half a period)
  // never does, one message missing (two periods) always does.
  static constexpr double kGapFactor = 1.5;
  // Intervals kept: the error of their mean (sigma / sqrt(kWindow) of the interval jitter, under
  // 1 % of the period at +-15 % jitter per stamp) stays under half a period over a gap of 50
  // periods; the estimate follows a change of rate after ~50 messages.
  static constexpr std::size_t kWindow = 101;
  static constexpr std::size_t kMinIntervals = 5;  // before any gap is counted
  // The message at utime (times increasing); returns the number missing before it.
  std::int64_t Add(std::int64_t utime);
  void Clear();
  // [us] the nominal period now (0 until kMinIntervals are known).
  std::int64_t period_us() const;

 private:
  std::deque<std::int64_t> intervals_;
  std::int64_t last_utime_ = 0;
  bool have_last_ = false;
};

class ScanSequencer {
 public:
  // max_coast_us: the longest any track may coast; a jump forward beyond it (and beyond
  // time_jump_reset_us) resets. max_points: larger scans are refused ("huge_scan").
  ScanSequencer(const InputParams& params, std::int64_t max_coast_us, std::int64_t max_points,
                RejectCounter* rejects);

  struct Admission {
    bool accepted = false;  // queued (a scan) or added (a pose)
    bool reset = false;     // the message's time jumped: the input was reset before it
  };
  Admission AddPose(const EgoPose& pose);
  Admission AddScan(LadarScan&& scan);
  // A detector's boxes wait like a scan whose sweep ends at their utime.
  Admission AddDetections(DetectionList&& list);

  // The oldest queued scan if it may be processed now (flush: whatever the poses), else
  // nullptr. *extrapolate: the pose stream has not reached the scan's end.
  const LadarScan* Ready(bool flush, bool* extrapolate) const;
  // Removes the scan Ready() gave, counting it processed or dropped. Its arrays are kept for
  // TakeSpare().
  void Done(bool processed);
  // The scan Done() removed last (an empty scan if there is none, or it was taken), to decode the
  // next sweep into: its arrays still hold its returns, and a decoder that overwrites them
  // (lcm_util::DecodePointCloud) allocates and zeroes nothing for a sweep of no more returns (a
  // 64-beam sweep is 2.7 MB, whose fresh pages cost about as much as decoding it).
  LadarScan TakeSpare();
  // The same for detection lists.
  const DetectionList* ReadyDetections(bool flush, bool* extrapolate) const;
  void DoneDetections(bool processed);

  const PoseHistory& poses() const { return poses_; }
  std::int64_t scans_received() const { return scans_received_; }
  std::int64_t scans_processed() const { return scans_processed_; }
  std::int64_t scans_dropped() const { return scans_dropped_; }
  std::int64_t poses_received() const { return poses_received_; }
  std::int64_t resets() const { return resets_; }
  std::int64_t latest_utime() const { return latest_utime_; }
  std::size_t queued_scans() const { return queue_.size(); }
  std::int64_t detections_received() const { return detections_received_; }
  std::int64_t detections_processed() const { return detections_processed_; }

 private:
  // Counts a gap in a sensor's seq (scans, detection lists) as messages lost on the way, under
  // reason; *last / *have: the newest seq of that stream.
  void CountSeqGap(std::int64_t seq, const char* reason, const char* what, std::int64_t* last,
                   bool* have);
  // "" if the scan is well formed, else why not (its reject reason in *reason).
  std::string CheckScan(const LadarScan& scan, const char** reason) const;
  // Follows the newest message time: kOk, kReset (a jump confirmed: the input was reset), or
  // kOutlier (an unconfirmed jump: the message is refused, counted).
  enum class TimeCheck { kOk, kReset, kOutlier };
  TimeCheck CheckTime(std::int64_t utime, const char* what);
  void Reset(const std::string& why);

  InputParams params_;
  std::int64_t max_coast_us_ = 0;
  std::int64_t max_points_ = 0;
  RejectCounter* rejects_;
  PoseHistory poses_;
  std::deque<LadarScan> queue_;
  LadarScan spare_;
  std::deque<DetectionList> detections_;
  std::int64_t last_detections_utime_ = 0;
  bool have_detections_ = false;
  std::int64_t detections_received_ = 0, detections_processed_ = 0;
  std::int64_t latest_utime_ = 0;
  bool have_time_ = false;
  bool jump_pending_ = false;       // the previous message jumped (refused, unconfirmed)
  std::int64_t pending_utime_ = 0;  // [us] its time
  std::int64_t last_scan_utime_ = 0;
  bool have_scan_ = false;
  std::int64_t last_seq_ = 0;  // newest scan seq received (for scan_seq_gap)
  bool have_seq_ = false;
  std::int64_t last_detections_seq_ = 0;  // newest detection list seq (detections_seq_gap)
  bool have_detections_seq_ = false;
  StreamGapCounter pose_gaps_;  // poses lost on the way (pose_gap)
  std::int64_t scans_received_ = 0, scans_processed_ = 0, scans_dropped_ = 0;
  std::int64_t poses_received_ = 0, resets_ = 0;
};

}  // namespace vtrack
