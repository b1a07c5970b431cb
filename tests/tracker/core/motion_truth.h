// Ground truth for the statistical tests of the motion models: the continuous-time noise models
// that ISM and VASM assume, simulated in fine substeps. Written from the models' definitions
// (white accelerations driving rigid-body kinematics), not from their discrete equations, so
// that the Monte Carlo and NEES tests check Q, Phi and the EKF against an independent truth.
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <random>

#include "base/angle.h"
#include "tracker/core/motion_model.h"

namespace vtrack::testing {

// A vehicle that turns about a point of its centreline (the axis point, L from the centre along
// the heading) and whose axis point moves along the heading at speed v.
struct AxisVehicle {
  Eigen::Vector2d axis = Eigen::Vector2d::Zero();  // [m] world position of the axis point
  double theta = 0.0;                              // [rad] heading, not wrapped
  double theta_dot = 0.0;                          // [rad/s]
  double v = 0.0;                                  // [m/s] signed speed of the axis point
  double L = 0.0;                                  // [m] axis point from the centre, along theta

  Eigen::Vector2d Centre() const {
    return axis - L * Eigen::Vector2d(std::cos(theta), std::sin(theta));
  }
  // As a VASM state (x, y, L, v, theta, theta_dot).
  Vector6d VasmState() const {
    const Eigen::Vector2d c = Centre();
    Vector6d x;
    x << c.x(), c.y(), L, v, WrapToPi(theta), theta_dot;
    return x;
  }
  static AxisVehicle FromVasmState(const Vector6d& x) {
    AxisVehicle a;
    a.L = x(2);
    a.v = x(3);
    a.theta = x(4);
    a.theta_dot = x(5);
    a.axis = Eigen::Vector2d(x(0), x(1)) + a.L * Eigen::Vector2d(std::cos(a.theta), std::sin(a.theta));
    return a;
  }
};

// Advances the vehicle by dt [s] in `substeps` steps under white noise of spectral densities
// alpha [m^2/s^3] on dv/dt, gamma [rad^2/s^3] on d(theta_dot)/dt and epsilon_L [m^2/s] on dL/dt
// (the axis point slides along the centreline; the centre stays where the motion puts it).
// The noisy rates are Brownian paths sampled at the substeps; the smooth states integrate them
// with the trapezoidal rule, whose error in the covariance is O(1 / substeps^2).
inline void StepAxisVehicle(double dt, int substeps, double alpha, double gamma, double epsilon_L,
                            std::mt19937_64& rng, AxisVehicle* a) {
  std::normal_distribution<double> n01(0.0, 1.0);
  const double h = dt / substeps;
  const double sa = std::sqrt(alpha * h), sg = std::sqrt(gamma * h), sl = std::sqrt(epsilon_L * h);
  for (int k = 0; k < substeps; ++k) {
    const double v1 = a->v + sa * n01(rng);
    const double w1 = a->theta_dot + sg * n01(rng);
    const double theta1 = a->theta + 0.5 * h * (a->theta_dot + w1);
    a->axis += 0.5 * h *
               (a->v * Eigen::Vector2d(std::cos(a->theta), std::sin(a->theta)) +
                v1 * Eigen::Vector2d(std::cos(theta1), std::sin(theta1)));
    a->v = v1;
    a->theta_dot = w1;
    a->theta = theta1;
    // The rotation axis moves along the centreline; the body (its centre) does not jump.
    const double dL = sl * n01(rng);
    a->L += dL;
    a->axis += dL * Eigen::Vector2d(std::cos(a->theta), std::sin(a->theta));
  }
}

// The ISM's continuous model: independent white accelerations on x, y (alpha [m^2/s^3]) and on
// theta (beta [rad^2/s^3]). x is an ISM state (x, x_dot, y, y_dot, theta, theta_dot); theta is
// returned wrapped.
inline void StepIsmBody(double dt, int substeps, double alpha, double beta, std::mt19937_64& rng,
                        Vector6d* x) {
  std::normal_distribution<double> n01(0.0, 1.0);
  const double h = dt / substeps;
  const double sd[3] = {std::sqrt(alpha * h), std::sqrt(alpha * h), std::sqrt(beta * h)};
  for (int k = 0; k < substeps; ++k) {
    for (int axis = 0; axis < 3; ++axis) {
      const int i = 2 * axis;
      const double rate1 = (*x)(i + 1) + sd[axis] * n01(rng);
      (*x)(i) += 0.5 * h * ((*x)(i + 1) + rate1);
      (*x)(i + 1) = rate1;
    }
  }
  (*x)(4) = WrapToPi((*x)(4));
}

}  // namespace vtrack::testing
