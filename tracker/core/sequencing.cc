#include "tracker/core/sequencing.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

namespace vtrack {
namespace {

std::string Str(std::int64_t v) { return std::to_string(v); }

// A rotation matrix R has R^T R = I; a mounting or pose further from it than this (Frobenius
// norm) is refused: far beyond the rounding of a rotation sent as floats, far below any real
// shear or scale.
constexpr double kMaxRotationError = 1e-3;

// A jump in the sensor's scan seq larger than this is a renumbered sensor, not scans lost.
constexpr std::uint64_t kMaxSeqGap = 100'000;

// An ego pose farther than this from the world origin, on any axis, is refused as invalid: a
// local-level world frame spans a region driven in one run (10,000 km is a quarter of the
// Earth's circumference), and coordinates beyond it (1e300 from a bad source) would make every
// return placed with the pose absurd and overflow the ground grid's cell arithmetic.
constexpr double kMaxPoseCoordinate = 1e7;  // [m]

// A sensor mounted farther than this from the body origin is refused: vehicles measure metres,
// and a mounting height beyond a float's range (the returns' heights are computed in float)
// would give every return an infinite height.
constexpr double kMaxMountingOffset = 1000.0;  // [m]

bool IsRotation(const Eigen::Matrix3d& R) {
  return (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() <= kMaxRotationError;
}

}  // namespace

void RejectCounter::Count(const std::string& reason, std::int64_t count,
                          const std::string& message) {
  if (count <= 0) return;
  counts_[reason] += count;
  if (events_.size() < kMaxEvents) events_.push_back({reason, message});
}

void RejectCounter::Event(const std::string& reason, const std::string& message) {
  events_.push_back({reason, message});
}

std::vector<TrackerEvent> RejectCounter::TakeEvents() {
  std::vector<TrackerEvent> e;
  e.swap(events_);
  return e;
}

std::int64_t StreamGapCounter::period_us() const {
  if (intervals_.size() < kMinIntervals) return 0;
  // The median gives the period robustly (the gaps, a change of rate); the mean of the intervals
  // near it gives it precisely (the median of jittered intervals wanders by a few per cent, which
  // a long gap multiplies): the mean of those within half a median of it.
  std::vector<std::int64_t> v(intervals_.begin(), intervals_.end());
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  const double median = static_cast<double>(*mid);
  double sum = 0.0;
  int n = 0;
  for (const std::int64_t d : intervals_) {
    if (std::abs(static_cast<double>(d) - median) <= 0.5 * median) {
      sum += static_cast<double>(d);
      ++n;
    }
  }
  return n > 0 ? static_cast<std::int64_t>(std::llround(sum / n)) : *mid;
}

std::int64_t StreamGapCounter::Add(std::int64_t utime) {
  std::int64_t missing = 0;
  if (have_last_ && utime > last_utime_) {
    // In 128 bits: the difference of two stamps near the ends of int64 must not overflow.
    const __int128 d = static_cast<__int128>(utime) - static_cast<__int128>(last_utime_);
    const std::int64_t period = period_us();
    if (period > 0 && static_cast<double>(d) > kGapFactor * static_cast<double>(period)) {
      // Bounded so that the conversion cannot overflow (a stamp jumping by centuries).
      const double ratio = std::min(1e12, static_cast<double>(d) / static_cast<double>(period));
      missing = static_cast<std::int64_t>(std::llround(ratio)) - 1;
    }
    intervals_.push_back(d > INT64_MAX ? INT64_MAX : static_cast<std::int64_t>(d));
    if (intervals_.size() > kWindow) intervals_.pop_front();
  }
  last_utime_ = utime;
  have_last_ = true;
  return missing;
}

void StreamGapCounter::Clear() {
  intervals_.clear();
  have_last_ = false;
}

ScanSequencer::ScanSequencer(const InputParams& params, std::int64_t max_coast_us,
                             std::int64_t max_points, RejectCounter* rejects)
    : params_(params),
      max_coast_us_(max_coast_us),
      max_points_(max_points),
      rejects_(rejects),
      poses_(params.pose_history_us) {}

void ScanSequencer::Reset(const std::string& why) {
  ++resets_;
  // The scans waiting for poses cannot be placed across the jump: dropped, and counted.
  const auto queued = static_cast<std::int64_t>(queue_.size());
  scans_dropped_ += queued;
  rejects_->Count("scan_reset", queued, Str(queued) + " queued scans dropped by a reset");
  queue_.clear();
  const auto lists = static_cast<std::int64_t>(detections_.size());
  rejects_->Count("detections_reset", lists, Str(lists) + " queued detection lists dropped by a reset");
  detections_.clear();
  have_detections_ = false;
  poses_.Clear();
  have_scan_ = false;
  have_time_ = false;
  have_seq_ = false;
  have_detections_seq_ = false;
  pose_gaps_.Clear();
  rejects_->Event("reset", "tracker reset: " + why);
}

ScanSequencer::TimeCheck ScanSequencer::CheckTime(std::int64_t utime, const char* what) {
  if (!have_time_) {
    latest_utime_ = utime;
    have_time_ = true;
    return TimeCheck::kOk;
  }
  // In 128 bits: a stamp near INT64_MIN or INT64_MAX must not overflow the difference.
  const __int128 d = static_cast<__int128>(utime) - static_cast<__int128>(latest_utime_);
  // A jump forward longer than any track may coast (a clock step, a log that skips ahead): no
  // track can survive it, and predicting them across it would only let stale tracks (with huge
  // covariances) catch the new returns. A jump back: a looped log.
  const std::int64_t forward_us = std::max(params_.time_jump_reset_us, max_coast_us_);
  const bool back = d < -static_cast<__int128>(params_.time_jump_reset_us);
  const bool forward = d > static_cast<__int128>(forward_us);
  if (!back && !forward) {
    jump_pending_ = false;
    if (utime > latest_utime_) latest_utime_ = utime;
    return TimeCheck::kOk;
  }
  const std::string how = std::string(what) + " time jumped " + (back ? "back" : "forward") + " by " +
                          Str(static_cast<std::int64_t>((back ? -d : d) / 1000)) + " ms";
  // One message alone (a stray datagram, a bad stamp) must not wipe every track: the jump is
  // believed when the next message lies within time_jump_reset_us of it.
  const __int128 from_pending = static_cast<__int128>(utime) - static_cast<__int128>(pending_utime_);
  if (jump_pending_ && from_pending <= params_.time_jump_reset_us &&
      from_pending >= -static_cast<__int128>(params_.time_jump_reset_us)) {
    Reset(how + (back ? " (looped log?), confirmed by the next message" : ", confirmed by the next message"));
    jump_pending_ = false;
    latest_utime_ = utime;
    have_time_ = true;
    return TimeCheck::kReset;
  }
  jump_pending_ = true;
  pending_utime_ = utime;
  // A scan has its own reason, so that every dropped scan is counted under a scan reason.
  rejects_->Count(std::string(what) == "scan" ? "scan_time_jump" : "time_jump_unconfirmed", 1,
                  how + ": refused (believed only if the next message confirms it)");
  return TimeCheck::kOutlier;
}

ScanSequencer::Admission ScanSequencer::AddPose(const EgoPose& pose) {
  ++poses_received_;
  Admission a;
  if (!pose.world_from_body.matrix().allFinite() || !IsRotation(pose.world_from_body.linear()) ||
      pose.world_from_body.translation().cwiseAbs().maxCoeff() > kMaxPoseCoordinate) {
    rejects_->Count("invalid_pose", 1,
                    "pose at " + Str(pose.utime) +
                        " is not finite, not a rotation or farther than 1e7 m from the origin");
    return a;
  }
  const TimeCheck tc = CheckTime(pose.utime, "pose");
  if (tc == TimeCheck::kOutlier) return a;
  a.reset = tc == TimeCheck::kReset;
  switch (poses_.Add(pose.utime, pose.world_from_body)) {
    case PoseHistory::AddResult::kOk: break;
    case PoseHistory::AddResult::kDuplicate:
      rejects_->Count("pose_repeated", 1, "pose at " + Str(pose.utime) + " repeats the previous time");
      return a;
    case PoseHistory::AddResult::kOutOfOrder:
      rejects_->Count("pose_out_of_order", 1,
                      "pose at " + Str(pose.utime) + " is older than " + Str(poses_.newest_utime()));
      return a;
  }
  // Poses lost on the way (a full receive queue, a lost datagram): the pose stream has no seq,
  // so they are inferred from its timing. Counted on accepted poses only (in time order).
  if (const std::int64_t missing = pose_gaps_.Add(pose.utime); missing > 0) {
    rejects_->Count("pose_gap", missing,
                    Str(missing) + " poses missing before the pose at " + Str(pose.utime) +
                        " (nominal period " + Str(pose_gaps_.period_us()) + " us)");
  }
  a.accepted = true;
  return a;
}

void ScanSequencer::CountSeqGap(std::int64_t seq, const char* reason, const char* what,
                                std::int64_t* last, bool* have) {
  // Messages lost on the way (LCM drops a datagram, or a fragmented message with a fragment
  // missing, or a full receive queue, without a word) show as gaps in the sensor's seq: one
  // count per missing message.
  if (*have && seq > *last) {
    const std::uint64_t gap = static_cast<std::uint64_t>(seq) - static_cast<std::uint64_t>(*last) - 1;
    if (gap > 0 && gap <= kMaxSeqGap) {
      rejects_->Count(reason, static_cast<std::int64_t>(gap),
                      Str(static_cast<std::int64_t>(gap)) + " " + what + " missing before seq " + Str(seq));
    }
  }
  if (!*have || seq > *last) *last = seq;
  *have = true;
}

std::string ScanSequencer::CheckScan(const LadarScan& scan, const char** reason) const {
  const std::size_t n = scan.x.size();
  *reason = "bad_scan";
  if (scan.y.size() != n || scan.z.size() != n ||
      (!scan.dt_us.empty() && scan.dt_us.size() != n) ||
      (!scan.ring.empty() && scan.ring.size() != n)) {
    return "arrays of different lengths";
  }
  if (scan.sweep_duration_us < 0 || scan.sweep_duration_us > params_.max_sweep_duration_us) {
    return "sweep_duration_us " + Str(scan.sweep_duration_us) + " out of range";
  }
  if (scan.num_rings < 1) return "num_rings " + Str(scan.num_rings) + " < 1";
  // 0: the sensor did not say (returns are then bounded by the absolute limit only).
  if (!std::isfinite(scan.max_range) || scan.max_range < 0.0f) {
    return "max_range " + std::to_string(scan.max_range) + " is not finite or negative";
  }
  if (!scan.body_from_sensor.matrix().allFinite()) return "mounting pose is not finite";
  if (scan.body_from_sensor.translation().norm() > kMaxMountingOffset) {
    std::ostringstream os;
    os << "mounting position " << scan.body_from_sensor.translation().norm()
       << " m from the body origin (at most " << kMaxMountingOffset << " m)";
    return os.str();
  }
  if (!IsRotation(scan.body_from_sensor.linear())) return "mounting orientation is not a rotation";
  if (n == 0) {
    *reason = "empty_scan";
    return "no returns";
  }
  if (static_cast<std::int64_t>(n) > max_points_) {
    *reason = "huge_scan";
    return Str(static_cast<std::int64_t>(n)) + " returns > max_points " + Str(max_points_);
  }
  return "";
}

ScanSequencer::Admission ScanSequencer::AddScan(LadarScan&& scan) {
  ++scans_received_;
  CountSeqGap(scan.seq, "scan_seq_gap", "scans", &last_seq_, &have_seq_);
  Admission a;
  auto drop = [&](const char* reason, const std::string& msg) {
    ++scans_dropped_;
    rejects_->Count(reason, 1, "scan " + Str(scan.seq) + " at " + Str(scan.utime) + ": " + msg);
    return a;
  };
  const char* reason = "";
  if (const std::string why = CheckScan(scan, &reason); !why.empty()) return drop(reason, why);
  const TimeCheck tc = CheckTime(scan.utime, "scan");
  if (tc == TimeCheck::kOutlier) {
    ++scans_dropped_;
    return a;
  }
  a.reset = tc == TimeCheck::kReset;
  if (have_scan_ && scan.utime <= last_scan_utime_) {
    return drop(scan.utime == last_scan_utime_ ? "scan_repeated" : "scan_out_of_order",
                "not after the previous scan at " + Str(last_scan_utime_));
  }
  last_scan_utime_ = scan.utime;
  have_scan_ = true;
  if (static_cast<int>(queue_.size()) >= params_.max_queued_scans) {
    ++scans_dropped_;
    rejects_->Count("scan_overrun", 1, "scan queue full (no pose for " + Str(queue_.size()) +
                                           " scans): dropped scan at " + Str(queue_.front().utime));
    queue_.pop_front();
  }
  queue_.push_back(std::move(scan));
  a.accepted = true;
  return a;
}

ScanSequencer::Admission ScanSequencer::AddDetections(DetectionList&& list) {
  ++detections_received_;
  CountSeqGap(list.seq, "detections_seq_gap", "detection lists", &last_detections_seq_,
              &have_detections_seq_);
  Admission a;
  for (const Detection& d : list.boxes) {
    const bool finite = std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z) &&
                        std::isfinite(d.yaw) && std::isfinite(d.score);
    if (!finite || !(d.length > 0.0) || !(d.width > 0.0) || !(d.height > 0.0)) {
      rejects_->Count("bad_detections", 1, "detections " + Str(list.seq) + " at " + Str(list.utime) +
                                               ": a box is not finite or not of positive size");
      return a;
    }
  }
  const TimeCheck tc = CheckTime(list.utime, "detections");
  if (tc == TimeCheck::kOutlier) return a;
  a.reset = tc == TimeCheck::kReset;
  if (have_detections_ && list.utime <= last_detections_utime_) {
    rejects_->Count(list.utime == last_detections_utime_ ? "detections_repeated" : "detections_out_of_order",
                    1, "detections at " + Str(list.utime) + " not after the previous ones at " +
                           Str(last_detections_utime_));
    return a;
  }
  last_detections_utime_ = list.utime;
  have_detections_ = true;
  if (static_cast<int>(detections_.size()) >= params_.max_queued_scans) {
    rejects_->Count("detections_overrun", 1, "detection queue full: dropped detections at " +
                                                 Str(detections_.front().utime));
    detections_.pop_front();
  }
  detections_.push_back(std::move(list));
  a.accepted = true;
  return a;
}

const DetectionList* ScanSequencer::ReadyDetections(bool flush, bool* extrapolate) const {
  if (detections_.empty()) return nullptr;
  const DetectionList& d = detections_.front();
  const bool ready = !poses_.empty() && poses_.newest_utime() >= d.utime;
  const bool forced = flush || latest_utime_ >= d.utime + params_.max_pose_wait_us;
  if (!ready && !forced) return nullptr;
  *extrapolate = !ready;
  return &d;
}

void ScanSequencer::DoneDetections(bool processed) {
  if (processed) ++detections_processed_;
  detections_.pop_front();
}

const LadarScan* ScanSequencer::Ready(bool flush, bool* extrapolate) const {
  if (queue_.empty()) return nullptr;
  const LadarScan& s = queue_.front();
  const bool ready = !poses_.empty() && poses_.newest_utime() >= s.end_utime();
  const bool forced = flush || latest_utime_ >= s.end_utime() + params_.max_pose_wait_us;
  if (!ready && !forced) return nullptr;
  *extrapolate = !ready;
  return &s;
}

void ScanSequencer::Done(bool processed) {
  if (processed) ++scans_processed_;
  else ++scans_dropped_;
  spare_ = std::move(queue_.front());
  queue_.pop_front();
}

LadarScan ScanSequencer::TakeSpare() {
  LadarScan s = std::move(spare_);
  spare_ = LadarScan();
  return s;
}

}  // namespace vtrack
