// Independent Steered Model (ISM), paper Section 2.1.
//
// State (Eq. 1):  x = (x, x_dot, y, y_dot, theta, theta_dot)
//   x, y      [m]      centre of the vehicle rectangle, world frame
//   x_dot, y_dot [m/s] velocity of the centre, world frame; independent of theta (Figure 1a)
//   theta     [rad]    orientation of the length axis, wrapped to (-pi, pi]
//   theta_dot [rad/s]  yaw rate
//
// Mean propagation (Eq. 1): a constant-velocity model in each of x, y, theta,
//   x_next = Phi x,  Phi = blockdiag(A, A, A),  A = [1 dt; 0 1],
// which is linear, so the Jacobian D_next_x is Phi itself (theta is wrapped after the product).
//
// System noise (Eq. 2-4): white acceleration of spectral density alpha [m^2/s^3] in x and in y,
// and beta [rad^2/s^3] in theta. For one axis, F = [0 1; 0 0] and Q solves
//   dQ/dt = F Q + Q F^T + [0 0; 0 alpha],  Q(0) = 0                              (Eq. 2)
// over dt, giving
//   Q_x = alpha [dt^3/3  dt^2/2; dt^2/2  dt]                                      (Eq. 3)
// and Q = blockdiag(Q_x, Q_y, Q_theta), with beta in place of alpha for theta      (Eq. 4).
// This Q is the exact discretisation of the continuous model, so predicting in several short
// steps gives the same covariance as one long step.
//
// Measurement (Eq. 14, docs/design.md note 1): H picks state indices 0, 2, 4.
#pragma once

#include <string>

#include "tracker/core/motion_model.h"
#include "tracker/core/parameters.h"

namespace vtrack {

class IsmModel final : public MotionModel {
 public:
  // Throws std::invalid_argument with the Validate() message if params are invalid.
  explicit IsmModel(const IsmParams& params = IsmParams());

  const IsmParams& params() const { return params_; }

  ModelKind kind() const override { return ModelKind::kIsm; }
  Vector6d Propagate(const Vector6d& x, double dt, Matrix6d* D_next_x = nullptr) const override;
  Matrix6d ProcessNoise(const Vector6d& x, double dt) const override;
  std::array<int, 3> PoseIndices() const override { return {0, 2, 4}; }
  Vector6d ToIsmState(const Vector6d& x, Matrix6d* D_ism_x = nullptr) const override;
  Vector6d FromIsmState(const Vector6d& x_ism, Matrix6d* D_x_ism = nullptr) const override;
  Matrix6d FromIsmPriorCovariance() const override { return Matrix6d::Zero(); }

  // A hypothesis from a first measurement: pose and its 3x3 covariance from the measurement, at
  // rest with the velocity and yaw-rate spread of the params.
  Hypothesis InitFromMeasurement(const CentreMeasurement& m) const;

 private:
  IsmParams params_;
};

}  // namespace vtrack
