// What the two motion models of the paper (Section 2.1 ISM, Section 2.2 VASM) have in common, so
// that the EKF (ekf.h) and the multi-hypothesis manager handle a hypothesis of either model alike.
//
// A hypothesis is a 6-vector state, its 6x6 covariance and the kind of model that gives the state
// its meaning:
//   ISM  (ism.h,  Eq. 1):  (x, x_dot, y, y_dot, theta, theta_dot)
//   VASM (vasm.h, Sec 2.2): (x, y, L, v, theta, theta_dot)
//   CV   (cv.h, the reference of 3-D MOT papers): the ISM's layout with theta_dot held at 0
// (x, y) is always the centre of the vehicle rectangle in the world frame [m] and theta the
// direction of its length axis [rad], wrapped to (-pi, pi]. The measurement of Eq. 14 picks
// (x, y, theta): ISM indices 0, 2, 4 and VASM indices 0, 1, 4 (docs/design.md note 1).
//
// Conversions between the models go through the ISM state, which is the model-free description
// of a rigid body in the plane: centre, centre velocity, heading, yaw rate. Each model maps its
// state to and from it (ToIsmState / FromIsmState) with Jacobians, so covariances convert by
// first-order propagation.
#pragma once

#include <Eigen/Core>

#include <array>
#include <string>

#include "base/enum_names.h"

namespace vtrack {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

enum class ModelKind : int { kIsm = 0, kVasm = 1, kCv = 2 };  // same values as track_t.MODEL_*

// True for the models whose state has the ISM's layout (x, x_dot, y, y_dot, theta, theta_dot):
// the ISM and the constant-velocity model (cv.h, theta_dot held at 0).
inline bool HasIsmLayout(ModelKind kind) { return kind != ModelKind::kVasm; }

// The covariance over dt of one axis (position, rate) driven by white acceleration of spectral
// density q (paper Eq. 2-3): q [dt^3/3 dt^2/2; dt^2/2 dt]. Shared by the ISM (x, y, theta) and
// the constant-velocity model (x, y).
inline Eigen::Matrix2d WhiteAccelerationNoise(double q, double dt) {
  const double dt2 = dt * dt;
  Eigen::Matrix2d Q;
  Q << dt2 * dt / 3.0, dt2 / 2.0, dt2 / 2.0, dt;
  return q * Q;
}

}  // namespace vtrack

template <>
struct vtrack::EnumNames<vtrack::ModelKind> {
  static constexpr std::array kNames{"ISM", "VASM", "CV"};
};

namespace vtrack {

inline const char* ToString(ModelKind kind) { return NameOf(kind); }

// One estimate of one object under one motion model.
struct Hypothesis {
  ModelKind kind = ModelKind::kIsm;
  Vector6d x = Vector6d::Zero();  // state, meaning given by kind (see above)
  Matrix6d P = Matrix6d::Identity();  // covariance of x
};

// A measurement of the vehicle centre and orientation (Eq. 14, 17) with its covariance (Eq. 18).
struct CentreMeasurement {
  Eigen::Vector3d z = Eigen::Vector3d::Zero();  // (x [m], y [m], theta [rad]) world frame
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // [m^2, m rad, rad^2]
};

// Everything a track report (vtrack track_t) needs from a hypothesis of either model.
struct CentreEstimate {
  Eigen::Vector3d pose = Eigen::Vector3d::Zero();  // (x [m], y [m], theta [rad]) world frame
  Eigen::Matrix3d pose_cov = Eigen::Matrix3d::Zero();  // covariance of pose [m^2, m rad, rad^2]
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  // [m/s] world-frame velocity of the centre
  Eigen::Matrix2d velocity_cov = Eigen::Matrix2d::Zero();  // [m^2/s^2]
  double speed = 0.0;             // [m/s] |velocity| >= 0; VASM: v_c of Eq. 7
  double velocity_heading = 0.0;  // [rad] direction of velocity (VASM: theta + dtheta_c, Eq. 7);
                                  // theta when the centre is at rest
  double yaw_rate = 0.0;          // [rad/s]
  double yaw_rate_var = 0.0;      // [rad^2/s^2]
  double rear_axle_offset = 0.0;  // [m] VASM's L (< 0 behind the centre); NaN for ISM
  double rear_axle_offset_var = 0.0;  // [m^2]; NaN for ISM
};

// One motion model: the nonlinear mean propagation x_next = f(x, dt) with its Jacobian
// Phi = D_next_x, the system noise Q(x, dt), and the map to the ISM state.
class MotionModel {
 public:
  virtual ~MotionModel() = default;

  virtual ModelKind kind() const = 0;

  // Mean propagation over dt [s]; theta of the result is wrapped to (-pi, pi]. A negative dt
  // propagates backwards along the same motion. D_next_x (optional): the Jacobian Phi of the
  // result with respect to x.
  virtual Vector6d Propagate(const Vector6d& x, double dt, Matrix6d* D_next_x = nullptr) const = 0;

  // System noise Q over dt >= 0 [s] about the state x (symmetric positive semi-definite).
  virtual Matrix6d ProcessNoise(const Vector6d& x, double dt) const = 0;

  // State indices of the measured (x, y, theta): the rows of H in Eq. 14.
  virtual std::array<int, 3> PoseIndices() const = 0;

  // The ISM state (x, x_dot, y, y_dot, theta, theta_dot) of the same motion, and its Jacobian.
  virtual Vector6d ToIsmState(const Vector6d& x, Matrix6d* D_ism_x = nullptr) const = 0;

  // This model's state for a rigid-body motion given as an ISM state, and its Jacobian. What the
  // ISM state does not determine comes from the model's prior: its covariance is
  // FromIsmPriorCovariance(), to be added to D P D^T.
  virtual Vector6d FromIsmState(const Vector6d& x_ism, Matrix6d* D_x_ism = nullptr) const = 0;
  virtual Matrix6d FromIsmPriorCovariance() const = 0;
};

}  // namespace vtrack
