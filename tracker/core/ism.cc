#include "tracker/core/ism.h"

#include <cmath>
#include <stdexcept>

#include "base/angle.h"

namespace vtrack {

IsmModel::IsmModel(const IsmParams& params) : params_(params) {
  std::string error;
  if (!params_.Validate(&error)) throw std::invalid_argument(error);
}

Vector6d IsmModel::Propagate(const Vector6d& x, double dt, Matrix6d* D_next_x) const {
  // Eq. (1): constant velocity in x, y and theta.
  Vector6d next = x;
  next(0) += dt * x(1);
  next(2) += dt * x(3);
  next(4) = WrapToPi(x(4) + dt * x(5));
  if (D_next_x != nullptr) {
    D_next_x->setIdentity();
    (*D_next_x)(0, 1) = dt;
    (*D_next_x)(2, 3) = dt;
    (*D_next_x)(4, 5) = dt;
  }
  return next;
}

Matrix6d IsmModel::ProcessNoise(const Vector6d& /*x*/, double dt) const {
  // Eq. (3) per axis, Eq. (4) block diagonal.
  Matrix6d Q = Matrix6d::Zero();
  Q.block<2, 2>(0, 0) = WhiteAccelerationNoise(params_.alpha, dt);
  Q.block<2, 2>(2, 2) = WhiteAccelerationNoise(params_.alpha, dt);
  Q.block<2, 2>(4, 4) = WhiteAccelerationNoise(params_.beta, dt);
  return Q;
}

Vector6d IsmModel::ToIsmState(const Vector6d& x, Matrix6d* D_ism_x) const {
  if (D_ism_x != nullptr) D_ism_x->setIdentity();
  return x;
}

Vector6d IsmModel::FromIsmState(const Vector6d& x_ism, Matrix6d* D_x_ism) const {
  if (D_x_ism != nullptr) D_x_ism->setIdentity();
  return x_ism;
}

Hypothesis IsmModel::InitFromMeasurement(const CentreMeasurement& m) const {
  Hypothesis h;
  h.kind = ModelKind::kIsm;
  h.x << m.z(0), 0.0, m.z(1), 0.0, WrapToPi(m.z(2)), 0.0;
  h.P.setZero();
  const std::array<int, 3> idx = PoseIndices();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) h.P(idx[r], idx[c]) = 0.5 * (m.R(r, c) + m.R(c, r));
  }
  const double sv2 = params_.initial_velocity_std * params_.initial_velocity_std;
  h.P(1, 1) = sv2;
  h.P(3, 3) = sv2;
  h.P(5, 5) = params_.initial_yaw_rate_std * params_.initial_yaw_rate_std;
  return h;
}

}  // namespace vtrack
