// Constant-velocity model (CV): the reference model of 3-D multi-object tracking (AB3DMOT and
// the papers that compare with it): the centre moves at constant velocity, the heading is held
// constant and wanders as a random walk. It is the ISM (ism.h) without the yaw rate: no turn is
// predicted, and one hypothesis per object, never a VASM.
//
// State: the ISM's layout, so that every rule written for an ISM hypothesis (orientation.h)
// applies unchanged:
//   x = (x, x_dot, y, y_dot, theta, theta_dot)   with theta_dot held at 0 (no yaw-rate state):
//   Propagate leaves it 0, its rows and columns of Phi, Q and P are 0, and FromIsmState drops it.
//
// Mean propagation: x_next = x + dt x_dot, y_next = y + dt y_dot, theta_next = theta.
//
// System noise over dt (exact discretisation, like Eq. 3):
//   per axis x and y, white acceleration of spectral density alpha [m^2/s^3]:
//     Q_x = alpha [dt^3/3  dt^2/2; dt^2/2  dt]
//   theta, white heading rate of spectral density q_theta [rad^2/s] (a random walk):
//     Q_theta = q_theta dt.
// Both densities are fitted to the labelled KITTI car trajectories (scripts/fit-cv-noise;
// parameters.h, CvParams).
//
// Measurement: H picks state indices 0, 2, 4, as for the ISM.
#pragma once

#include "tracker/core/motion_model.h"
#include "tracker/core/parameters.h"

namespace vtrack {

class CvModel final : public MotionModel {
 public:
  // Throws std::invalid_argument with the Validate() message if params are invalid.
  explicit CvModel(const CvParams& params = CvParams());

  const CvParams& params() const { return params_; }

  ModelKind kind() const override { return ModelKind::kCv; }
  Vector6d Propagate(const Vector6d& x, double dt, Matrix6d* D_next_x = nullptr) const override;
  Matrix6d ProcessNoise(const Vector6d& x, double dt) const override;
  std::array<int, 3> PoseIndices() const override { return {0, 2, 4}; }
  // The ISM state with yaw rate 0.
  Vector6d ToIsmState(const Vector6d& x, Matrix6d* D_ism_x = nullptr) const override;
  // The ISM state with its yaw rate dropped (set to 0, zero rows in the Jacobian).
  Vector6d FromIsmState(const Vector6d& x_ism, Matrix6d* D_x_ism = nullptr) const override;
  Matrix6d FromIsmPriorCovariance() const override { return Matrix6d::Zero(); }

 private:
  CvParams params_;
};

}  // namespace vtrack
