#include "tracker/core/cv.h"

#include <stdexcept>
#include <string>

#include "base/angle.h"

namespace vtrack {

CvModel::CvModel(const CvParams& params) : params_(params) {
  std::string error;
  if (!params_.Validate(&error)) throw std::invalid_argument(error);
}

Vector6d CvModel::Propagate(const Vector6d& x, double dt, Matrix6d* D_next_x) const {
  Vector6d next = x;
  next(0) += dt * x(1);
  next(2) += dt * x(3);
  next(4) = WrapToPi(x(4));
  next(5) = 0.0;
  if (D_next_x != nullptr) {
    D_next_x->setIdentity();
    (*D_next_x)(0, 1) = dt;
    (*D_next_x)(2, 3) = dt;
    (*D_next_x)(5, 5) = 0.0;  // the yaw rate is no state: held at 0
  }
  return next;
}

Matrix6d CvModel::ProcessNoise(const Vector6d& /*x*/, double dt) const {
  Matrix6d Q = Matrix6d::Zero();
  Q.block<2, 2>(0, 0) = WhiteAccelerationNoise(params_.alpha, dt);
  Q.block<2, 2>(2, 2) = WhiteAccelerationNoise(params_.alpha, dt);
  Q(4, 4) = params_.q_theta * dt;
  return Q;
}

Vector6d CvModel::ToIsmState(const Vector6d& x, Matrix6d* D_ism_x) const {
  Vector6d out = x;
  out(5) = 0.0;
  if (D_ism_x != nullptr) {
    D_ism_x->setIdentity();
    (*D_ism_x)(5, 5) = 0.0;
  }
  return out;
}

Vector6d CvModel::FromIsmState(const Vector6d& x_ism, Matrix6d* D_x_ism) const {
  return ToIsmState(x_ism, D_x_ism);  // the same projection: drop the yaw rate
}

}  // namespace vtrack
