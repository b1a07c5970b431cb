#include "base/pose.h"

#include <algorithm>
#include <cmath>

namespace vtrack {

Eigen::Isometry3d InterpolatePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                                  double s) {
  const Eigen::Quaterniond qa(a.rotation());
  Eigen::Quaterniond qb(b.rotation());
  Eigen::Quaterniond q;
  if (s >= 0.0 && s <= 1.0) {
    q = qa.slerp(s, qb);
  } else {
    // Constant angular velocity: q(s) = qa * exp(s * log(qa^-1 qb)).
    if (qa.dot(qb) < 0.0) qb.coeffs() = -qb.coeffs();
    const Eigen::AngleAxisd delta(qa.conjugate() * qb);
    q = qa * Eigen::Quaterniond(Eigen::AngleAxisd(s * delta.angle(), delta.axis()));
  }
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = q.normalized().toRotationMatrix();
  out.translation() = (1.0 - s) * a.translation() + s * b.translation();
  return out;
}

double YawOf(const Eigen::Quaterniond& q) {
  const Eigen::Vector3d x = q * Eigen::Vector3d::UnitX();
  return std::atan2(x.y(), x.x());
}

double YawOf(const Eigen::Isometry3d& world_from_body) {
  const Eigen::Vector3d x = world_from_body.linear() * Eigen::Vector3d::UnitX();
  return std::atan2(x.y(), x.x());
}

Eigen::Quaterniond QuaternionFromRpy(double roll, double pitch, double yaw) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
}

PoseHistory::AddResult PoseHistory::Add(std::int64_t utime, const Eigen::Isometry3d& pose) {
  if (!poses_.empty()) {
    if (utime == poses_.back().utime) return AddResult::kDuplicate;
    if (utime < poses_.back().utime) return AddResult::kOutOfOrder;
  }
  poses_.push_back({utime, pose});
  while (poses_.size() > 2 && poses_.front().utime < utime - max_span_us_) poses_.pop_front();
  return AddResult::kOk;
}

std::optional<Eigen::Isometry3d> PoseHistory::At(std::int64_t utime,
                                                 std::int64_t max_extrapolation_us,
                                                 LookupStatus* status) const {
  auto set = [&](LookupStatus s) {
    if (status) *status = s;
  };
  if (poses_.empty()) {
    set(LookupStatus::kEmpty);
    return std::nullopt;
  }
  if (utime < poses_.front().utime) {
    set(LookupStatus::kBeforeHistory);
    return std::nullopt;
  }
  const auto& last = poses_.back();
  if (utime >= last.utime) {
    if (utime - last.utime > max_extrapolation_us) {
      set(LookupStatus::kTooFarAhead);
      return std::nullopt;
    }
    if (utime == last.utime || poses_.size() < 2) {
      set(utime == last.utime ? LookupStatus::kOk : LookupStatus::kExtrapolated);
      return last.pose;
    }
    const auto& prev = poses_[poses_.size() - 2];
    const double s = static_cast<double>(utime - prev.utime) /
                     static_cast<double>(last.utime - prev.utime);
    set(LookupStatus::kExtrapolated);
    return InterpolatePose(prev.pose, last.pose, s);
  }
  // First pose with time > utime; its predecessor has time <= utime.
  const auto it = std::upper_bound(poses_.begin(), poses_.end(), utime,
                                   [](std::int64_t t, const Stamped& p) { return t < p.utime; });
  const auto& b = *it;
  const auto& a = *(it - 1);
  set(LookupStatus::kOk);
  if (a.utime == utime) return a.pose;
  const double s =
      static_cast<double>(utime - a.utime) / static_cast<double>(b.utime - a.utime);
  return InterpolatePose(a.pose, b.pose, s);
}

}  // namespace vtrack
