// True planar kinematics of a simulated vehicle (docs/design.md, section 5; the motion that the paper's
// VASM, Section 2.2, models).
//
// The rotation axis point A lies on the vehicle's centreline, L = rotation_axis_offset metres
// ahead of the box centre C (L < 0: behind, as a car's rear axle). A moves along the heading:
//
//   dA/dt = v (cos theta, sin theta),   d(theta)/dt = omega,
//   Ackerman (kinematic bicycle):  omega = v tan(delta) / wheelbase,  delta = front steering angle
//   skid-steer:                    omega is the commanded yaw rate (v = 0 turns in place)
//
// v is signed (v < 0 reverses). So a car at constant steering delta drives a circle of radius
// wheelbase / tan(delta) with its rear axle. The centre C = A - L a (a = heading unit vector,
// n = its left normal) moves with
//
//   dC/dt = v a - L omega n,
//
// whose direction is offset from theta by atan2(-L omega, v) and whose speed is v / cos of that
// offset (the paper's Eq. 7).
//
// Integration: over a step in which v and omega are constant, A follows an exact arc (Eq. 5):
// in the heading frame at the start of the step, dx = v dt sinc(phi), dy = v dt (1 - cos phi)/phi
// with phi = omega dt. The trajectory is tabulated every kSampleStep s, each sample reached in
// kSubsteps arcs with v and omega taken at the sub-step midpoints (exact for constant controls,
// third-order accurate for ramps); At(t) takes one more arc from the sample before t.
#pragma once

#include <Eigen/Core>

#include <vector>

#include "sensor_driver/sim/piecewise_linear.h"

namespace vtrack::sim {

enum class SteeringKind { kAckerman, kSkidSteer };

// Where a vehicle is and how it moves at one instant. World frame, SI units.
struct MotionState {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();      // [m] box centre C
  Eigen::Vector2d axis_point = Eigen::Vector2d::Zero();  // [m] rotation axis point A
  double yaw = 0.0;                                      // [rad] heading, (-pi, pi]
  Eigen::Vector2d center_velocity = Eigen::Vector2d::Zero();  // [m/s] dC/dt
  double speed = 0.0;        // [m/s] v, signed speed of A along the heading
  double yaw_rate = 0.0;     // [rad/s] omega
  double accel = 0.0;        // [m/s^2] dv/dt (along the heading)
};

class VehicleMotion {
 public:
  static constexpr double kSampleStep = 0.01;  // [s] spacing of the tabulated trajectory
  static constexpr int kSubsteps = 10;         // arcs per tabulation step

  struct Params {
    SteeringKind kind = SteeringKind::kAckerman;
    double wheelbase = 2.7;             // [m] Ackerman only, > 0
    double rotation_axis_offset = -1.35;  // [m] L: axis point ahead of the centre (< 0 behind)
  };

  // start_center/start_yaw: the box centre and heading at t = 0. speed: v(t) [m/s].
  // turn: steering angle delta(t) [rad] (Ackerman, |delta| < 80 deg) or yaw rate omega(t)
  // [rad/s] (skid-steer). The trajectory is tabulated on [0, end_time]; later times hold the
  // controls of end_time and are integrated on the fly. Throws std::invalid_argument on bad
  // parameters, naming the value.
  VehicleMotion(const Params& params, const Eigen::Vector2d& start_center, double start_yaw,
                PiecewiseLinear speed, PiecewiseLinear turn, double end_time);

  // State at scenario time t [s]; t < 0 gives the state at t = 0.
  MotionState At(double t) const;

  // omega at time t from the controls (not from the tabulated path).
  double YawRateAt(double t) const;
  const Params& params() const { return params_; }
  const PiecewiseLinear& speed_profile() const { return speed_; }
  const PiecewiseLinear& turn_profile() const { return turn_; }
  // True if v is zero and omega is zero at every time (the vehicle never moves).
  bool IsStatic() const;

 private:
  struct Pose2 {
    double x, y, yaw;  // axis point A and (unwrapped) heading
  };
  // One exact arc of duration dt with controls taken at time t_mid.
  void Arc(double t_mid, double dt, Pose2* p) const;

  Params params_;
  PiecewiseLinear speed_;
  PiecewiseLinear turn_;
  std::vector<Pose2> samples_;  // samples_[k] at t = k * kSampleStep
};

}  // namespace vtrack::sim
