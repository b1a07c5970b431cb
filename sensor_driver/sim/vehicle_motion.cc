#include "sensor_driver/sim/vehicle_motion.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "base/angle.h"

namespace vtrack::sim {
namespace {

// sin(phi)/phi and (1 - cos(phi))/phi, with series near 0 (terms beyond are < 1e-17 there).
void ArcFactors(double phi, double* f_along, double* f_across) {
  if (std::abs(phi) < 1e-4) {
    const double p2 = phi * phi;
    *f_along = 1.0 - p2 / 6.0;
    *f_across = phi * (0.5 - p2 / 24.0);
  } else {
    const double h = std::sin(0.5 * phi);
    *f_along = std::sin(phi) / phi;
    *f_across = 2.0 * h * h / phi;  // 1 - cos(phi) without cancellation
  }
}

}  // namespace

VehicleMotion::VehicleMotion(const Params& params, const Eigen::Vector2d& start_center,
                             double start_yaw, PiecewiseLinear speed, PiecewiseLinear turn,
                             double end_time)
    : params_(params), speed_(std::move(speed)), turn_(std::move(turn)) {
  if (params_.kind == SteeringKind::kAckerman && !(params_.wheelbase > 0.0)) {
    throw std::invalid_argument("wheelbase = " + std::to_string(params_.wheelbase) +
                                " m: must be > 0");
  }
  if (!std::isfinite(params_.rotation_axis_offset)) {
    throw std::invalid_argument("rotation axis offset is not finite");
  }
  if (params_.kind == SteeringKind::kAckerman) {
    for (const auto& k : turn_.keys()) {
      if (std::abs(k.value) >= DegToRad(80.0)) {
        throw std::invalid_argument("steering angle " + std::to_string(RadToDeg(k.value)) +
                                    " deg at t = " + std::to_string(k.t) +
                                    " s: must be within (-80, 80) deg");
      }
    }
  }
  if (!std::isfinite(start_center.x()) || !std::isfinite(start_center.y()) ||
      !std::isfinite(start_yaw)) {
    throw std::invalid_argument("start pose is not finite");
  }
  if (!(end_time >= 0.0) || end_time > 1e5) {
    throw std::invalid_argument("end time " + std::to_string(end_time) +
                                " s: must be in [0, 1e5]");
  }
  const double L = params_.rotation_axis_offset;
  Pose2 p{start_center.x() + L * std::cos(start_yaw), start_center.y() + L * std::sin(start_yaw),
          start_yaw};
  const auto n = static_cast<std::size_t>(std::ceil(end_time / kSampleStep)) + 1;
  samples_.reserve(n);
  samples_.push_back(p);
  if (IsStatic()) return;
  const double h = kSampleStep / kSubsteps;
  for (std::size_t k = 1; k < n; ++k) {
    const double t0 = (k - 1) * kSampleStep;
    for (int j = 0; j < kSubsteps; ++j) Arc(t0 + (j + 0.5) * h, h, &p);
    samples_.push_back(p);
  }
}

double VehicleMotion::YawRateAt(double t) const {
  if (params_.kind == SteeringKind::kSkidSteer) return turn_.At(t);
  return speed_.At(t) * std::tan(turn_.At(t)) / params_.wheelbase;
}

bool VehicleMotion::IsStatic() const {
  return speed_.IsZero() && (params_.kind == SteeringKind::kAckerman || turn_.IsZero());
}

void VehicleMotion::Arc(double t_mid, double dt, Pose2* p) const {
  const double v = speed_.At(t_mid);
  const double omega = YawRateAt(t_mid);
  const double phi = omega * dt;
  double f_along, f_across;
  ArcFactors(phi, &f_along, &f_across);
  const double dx = v * dt * f_along;   // Eq. (5), heading frame at the start of the arc
  const double dy = v * dt * f_across;
  const double c = std::cos(p->yaw), s = std::sin(p->yaw);
  p->x += c * dx - s * dy;
  p->y += s * dx + c * dy;
  p->yaw += phi;
}

MotionState VehicleMotion::At(double t) const {
  t = std::max(t, 0.0);
  Pose2 p;
  if (IsStatic()) {
    p = samples_.front();
  } else {
    const auto last = samples_.size() - 1;
    const auto k = std::min(static_cast<std::size_t>(t / kSampleStep), last);
    p = samples_[k];
    const double tk = k * kSampleStep;
    const double dt = t - tk;
    if (dt > 0.0) {
      // Beyond the table, integrate in table-sized pieces so that accuracy does not degrade.
      const int pieces = std::max(1, static_cast<int>(std::ceil(dt / kSampleStep)));
      const double h = dt / pieces;
      for (int j = 0; j < pieces; ++j) Arc(tk + (j + 0.5) * h, h, &p);
    }
  }
  MotionState m;
  const Eigen::Vector2d a(std::cos(p.yaw), std::sin(p.yaw));
  const Eigen::Vector2d nrm(-a.y(), a.x());
  const double L = params_.rotation_axis_offset;
  m.axis_point = {p.x, p.y};
  m.center = m.axis_point - L * a;
  m.yaw = WrapToPi(p.yaw);
  m.speed = speed_.At(t);
  m.yaw_rate = YawRateAt(t);
  m.accel = speed_.Derivative(t);
  m.center_velocity = m.speed * a - L * m.yaw_rate * nrm;
  return m;
}

}  // namespace vtrack::sim
