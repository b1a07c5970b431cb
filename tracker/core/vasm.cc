#include "tracker/core/vasm.h"

#include <cmath>
#include <stdexcept>

#include "base/angle.h"

namespace vtrack {
namespace {

// Below this |a| the closed forms lose digits to cancellation (sinc') or divide by ~0 (sinc);
// the series truncated after a^10 (sinc) and a^9 (sinc') are exact to rounding there.
constexpr double kSeriesBelow = 0.1;

// g(a) = (1 - cos a)/a = (a/2) sinc^2(a/2): the lateral displacement factor of Eq. (5).
double G(double a) {
  const double s = Sinc(0.5 * a);
  return 0.5 * a * s * s;
}

// g'(a) = sinc(a) - sinc^2(a/2)/2 (the bracket of d cy / d theta_dot in Eq. 11).
double GDerivative(double a) {
  const double s = Sinc(0.5 * a);
  return Sinc(a) - 0.5 * s * s;
}

}  // namespace

double Sinc(double a) {
  if (std::abs(a) < kSeriesBelow) {
    // sum_k (-1)^k a^(2k) / (2k+1)!
    const double a2 = a * a;
    return 1.0 +
           a2 * (-1.0 / 6.0 +
                 a2 * (1.0 / 120.0 +
                       a2 * (-1.0 / 5040.0 + a2 * (1.0 / 362880.0 + a2 * (-1.0 / 39916800.0)))));
  }
  return std::sin(a) / a;
}

double SincDerivative(double a) {
  if (std::abs(a) < kSeriesBelow) {
    // sum_k>=1 (-1)^k 2k a^(2k-1) / (2k+1)!
    const double a2 = a * a;
    return a * (-1.0 / 3.0 +
                a2 * (1.0 / 30.0 +
                      a2 * (-1.0 / 840.0 + a2 * (1.0 / 45360.0 + a2 * (-1.0 / 3991680.0)))));
  }
  return (a * std::cos(a) - std::sin(a)) / (a * a);
}

VasmModel::VasmModel(const VasmParams& params) : params_(params) {
  std::string error;
  if (!params_.Validate(&error)) throw std::invalid_argument(error);
}

Eigen::Vector2d VasmModel::CentreDisplacement(double L, double v, double theta_dot, double dt) {
  const double a = theta_dot * dt;
  const double sh = std::sin(0.5 * a);
  // Eq. (6); v dt g(a) = v theta_dot dt^2 sinc^2(a/2) / 2.
  return {v * dt * Sinc(a) + 2.0 * L * sh * sh, v * dt * G(a) - L * std::sin(a)};
}

Vector6d VasmModel::Propagate(const Vector6d& x, double dt, Matrix6d* D_next_x) const {
  const double L = x(2), v = x(3), theta = x(4), theta_dot = x(5);
  const double a = theta_dot * dt;
  const double c = std::cos(theta), s = std::sin(theta);
  const Eigen::Vector2d d = CentreDisplacement(L, v, theta_dot, dt);

  // Eq. (8): rotate the local displacement to the world frame.
  Vector6d next = x;
  next(0) += c * d.x() - s * d.y();
  next(1) += s * d.x() + c * d.y();
  next(4) = WrapToPi(theta + a);

  if (D_next_x != nullptr) {
    // Eq. (11): partials of (cx, cy) in the local frame.
    const double sin_a = std::sin(a), cos_a = std::cos(a);
    const double sh = std::sin(0.5 * a);
    const double dt2 = dt * dt;
    const Eigen::Vector2d D_c_L(2.0 * sh * sh, -sin_a);
    const Eigen::Vector2d D_c_v(dt * Sinc(a), dt * G(a));
    const Eigen::Vector2d D_c_theta_dot(v * dt2 * SincDerivative(a) + L * dt * sin_a,
                                        v * dt2 * GDerivative(a) - L * dt * cos_a);
    const Eigen::Vector2d D_c_theta(-d.y(), d.x());  // d R(theta)/d theta = R(theta) J
    Eigen::Matrix2d R;
    R << c, -s, s, c;
    // Eq. (9): Phi = I + T(theta) M.
    D_next_x->setIdentity();
    D_next_x->block<2, 1>(0, 2) = R * D_c_L;
    D_next_x->block<2, 1>(0, 3) = R * D_c_v;
    D_next_x->block<2, 1>(0, 4) = R * D_c_theta;
    D_next_x->block<2, 1>(0, 5) = R * D_c_theta_dot;
    (*D_next_x)(4, 5) = dt;
  }
  return next;
}

Matrix6d VasmModel::ProcessNoise(const Vector6d& x, double dt) const {
  const double L = x(2), v = x(3), theta = x(4), w = x(5);
  const double dt2 = dt * dt, dt3 = dt2 * dt, dt4 = dt3 * dt, dt5 = dt4 * dt, dt6 = dt5 * dt,
               dt7 = dt6 * dt;
  const double alpha = params_.alpha, gamma = params_.gamma, eps = params_.epsilon_L;
  enum { kS = 0, kN = 1, kL = 2, kV = 3, kTheta = 4, kW = 5 };

  // Local frame at the start of the interval; Q = sum of density * integral b b^T (vasm.h).
  Matrix6d Q = Matrix6d::Zero();
  // Along-arc acceleration: Eq. (3) on (s, v), and the bend of the arc (terms in w).
  Q(kS, kS) += alpha * dt3 / 3.0;
  Q(kS, kV) += alpha * dt2 / 2.0;
  Q(kV, kV) += alpha * dt;
  Q(kS, kN) += alpha * w * 5.0 * dt4 / 24.0;
  Q(kN, kN) += alpha * w * w * 2.0 * dt5 / 15.0;
  Q(kN, kV) += alpha * w * dt3 / 3.0;
  // Angular acceleration: Eq. (12) with signed v and the lever arm L of the centre ...
  Q(kN, kN) += gamma * (v * v * dt5 / 20.0 - v * L * dt4 / 4.0 + L * L * dt3 / 3.0);
  Q(kN, kTheta) += gamma * (v * dt4 / 8.0 - L * dt3 / 3.0);
  Q(kN, kW) += gamma * (v * dt3 / 6.0 - L * dt2 / 2.0);
  Q(kTheta, kTheta) += gamma * dt3 / 3.0;
  Q(kTheta, kW) += gamma * dt2 / 2.0;
  Q(kW, kW) += gamma * dt;
  // ... and the along-arc part s_w of its effect while turning.
  Q(kS, kS) += gamma * w * w *
               (L * L * dt5 / 3.0 - 11.0 * L * v * dt6 / 60.0 + 11.0 * v * v * dt7 / 420.0);
  Q(kS, kN) += gamma * w *
               (-L * L * dt4 / 3.0 + 13.0 * L * v * dt5 / 60.0 - 13.0 * v * v * dt6 / 360.0);
  Q(kS, kTheta) += gamma * w * (L * dt4 / 3.0 - 11.0 * v * dt5 / 120.0);
  Q(kS, kW) += gamma * w * (L * dt3 / 2.0 - v * dt4 / 8.0);
  // Random walk of L, and the turn of the later path about the moved axis.
  Q(kL, kL) += eps * dt;
  Q(kN, kL) += -eps * w * dt2 / 2.0;
  Q(kN, kN) += eps * w * w * dt3 / 3.0;
  // Only the upper triangle was filled.
  Q.triangularView<Eigen::StrictlyLower>() = Q.transpose().triangularView<Eigen::StrictlyLower>();

  // Eq. (13): Q = T(theta) Q_local T(theta)^T; T rotates only the (x, y) rows and columns.
  Matrix6d T = Matrix6d::Identity();
  const double c = std::cos(theta), s = std::sin(theta);
  T(0, 0) = c;
  T(0, 1) = -s;
  T(1, 0) = s;
  T(1, 1) = c;
  const Matrix6d world = T * Q * T.transpose();
  return 0.5 * (world + world.transpose());
}

void VasmModel::CentreVelocity(const Vector6d& x, double* dtheta_c, double* v_c) {
  const double L = x(2), v = x(3), theta_dot = x(5);
  const double lateral = -L * theta_dot;  // centre velocity across theta (vehicle frame)
  // Eq. (7); atan2(0, 0) = 0 puts the velocity of a vehicle at rest along theta.
  *dtheta_c = std::atan2(lateral, v);
  *v_c = std::hypot(v, lateral);
}

Vector6d VasmModel::ToIsmState(const Vector6d& x, Matrix6d* D_ism_x) const {
  const double L = x(2), v = x(3), theta = x(4), w = x(5);
  const double c = std::cos(theta), s = std::sin(theta);
  // World velocity of the centre: R(theta) (v, -L w) (Eq. 7).
  const double vx = c * v + s * L * w;
  const double vy = s * v - c * L * w;
  Vector6d ism;
  ism << x(0), vx, x(1), vy, theta, w;
  if (D_ism_x != nullptr) {
    D_ism_x->setZero();
    (*D_ism_x)(0, 0) = 1.0;
    (*D_ism_x)(2, 1) = 1.0;
    (*D_ism_x)(4, 4) = 1.0;
    (*D_ism_x)(5, 5) = 1.0;
    // Row x_dot over (L, v, theta, theta_dot).
    (*D_ism_x)(1, 2) = s * w;
    (*D_ism_x)(1, 3) = c;
    (*D_ism_x)(1, 4) = -s * v + c * L * w;
    (*D_ism_x)(1, 5) = s * L;
    // Row y_dot.
    (*D_ism_x)(3, 2) = -c * w;
    (*D_ism_x)(3, 3) = s;
    (*D_ism_x)(3, 4) = c * v + s * L * w;
    (*D_ism_x)(3, 5) = -c * L;
  }
  return ism;
}

Vector6d VasmModel::FromIsmState(const Vector6d& x_ism, Matrix6d* D_x_ism) const {
  const double vx = x_ism(1), vy = x_ism(3), theta = x_ism(4);
  const double c = std::cos(theta), s = std::sin(theta);
  const double v = c * vx + s * vy;
  Vector6d x;
  x << x_ism(0), x_ism(2), v >= 0.0 ? params_.initial_L : -params_.initial_L, v, WrapToPi(theta),
      x_ism(5);
  if (D_x_ism != nullptr) {
    D_x_ism->setZero();
    (*D_x_ism)(0, 0) = 1.0;
    (*D_x_ism)(1, 2) = 1.0;
    (*D_x_ism)(3, 1) = c;
    (*D_x_ism)(3, 3) = s;
    (*D_x_ism)(3, 4) = -s * vx + c * vy;
    (*D_x_ism)(4, 4) = 1.0;
    (*D_x_ism)(5, 5) = 1.0;
  }
  return x;
}

Matrix6d VasmModel::FromIsmPriorCovariance() const {
  Matrix6d P = Matrix6d::Zero();
  P(2, 2) = params_.initial_L_std * params_.initial_L_std;
  return P;
}

}  // namespace vtrack
