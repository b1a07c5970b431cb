// Ego poses over time: interpolation between two poses, and a short history that answers "where
// was the vehicle at time t" for motion compensation of every LADAR return (docs/design.md, section 4.2).
#pragma once

#include <Eigen/Geometry>

#include <cstdint>
#include <deque>
#include <optional>

namespace vtrack {

// [us since the Unix epoch] The latest start time a log or a live run may be given (2^52 us, in
// the year 2112): a run shorter than a century then keeps every utime below 2^53, exact in a
// double as the tracker's and the scorers' times in seconds take it, and far from int64's
// overflow.
inline constexpr std::int64_t kMaxStartUtime = std::int64_t{1} << 52;

// Pose at s in [0, 1] between a (s = 0) and b (s = 1): linear in translation, slerp in rotation.
// s outside [0, 1] extrapolates at constant linear and angular velocity.
Eigen::Isometry3d InterpolatePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double s);

// Heading of the body x axis projected on the world xy plane [rad], in (-pi, pi].
double YawOf(const Eigen::Quaterniond& world_from_body);
double YawOf(const Eigen::Isometry3d& world_from_body);

// Builds a rotation from roll, pitch, yaw (Z-Y-X, intrinsic) [rad].
Eigen::Quaterniond QuaternionFromRpy(double roll, double pitch, double yaw);

// A time-ordered history of world_from_body poses, bounded in time span.
class PoseHistory {
 public:
  enum class AddResult { kOk, kOutOfOrder, kDuplicate };
  enum class LookupStatus {
    kOk,              // interpolated between two poses (or exactly on one)
    kExtrapolated,    // after the last pose, within max_extrapolation_us
    kEmpty,           // no pose yet
    kBeforeHistory,   // earlier than the oldest pose kept
    kTooFarAhead,     // later than the last pose by more than max_extrapolation_us
  };

  // max_span_us: poses older than (newest - max_span_us) are dropped.
  explicit PoseHistory(std::int64_t max_span_us = 5'000'000) : max_span_us_(max_span_us) {}

  // Poses must arrive in increasing time; an earlier or repeated time is refused and not stored.
  AddResult Add(std::int64_t utime, const Eigen::Isometry3d& world_from_body);

  // The pose at utime. Between stored poses it interpolates; after the last one it extrapolates
  // from the last two at constant velocity for at most max_extrapolation_us.
  std::optional<Eigen::Isometry3d> At(std::int64_t utime, std::int64_t max_extrapolation_us,
                                      LookupStatus* status = nullptr) const;

  bool empty() const { return poses_.empty(); }
  std::size_t size() const { return poses_.size(); }
  std::int64_t newest_utime() const { return poses_.empty() ? 0 : poses_.back().utime; }
  std::int64_t oldest_utime() const { return poses_.empty() ? 0 : poses_.front().utime; }
  void Clear() { poses_.clear(); }

 private:
  struct Stamped {
    std::int64_t utime;
    Eigen::Isometry3d pose;
  };
  std::int64_t max_span_us_;
  std::deque<Stamped> poses_;
};

}  // namespace vtrack
