// Variable-axis Ackerman Steered Model (VASM), paper Section 2.2.
//
// State:  x = (x, y, L, v, theta, theta_dot)
//   x, y      [m]     centre of the vehicle rectangle, world frame
//   L         [m]     signed position of the rotation axis along the centreline, measured from the
//                     centre towards the front (L < 0: behind the centre, as a car's rear axle)
//   v         [m/s]   signed speed of that axis point along theta (v < 0: reversing)
//   theta     [rad]   orientation of the length axis, wrapped to (-pi, pi]
//   theta_dot [rad/s] yaw rate
// The axis point is the point of the centreline whose velocity is parallel to theta; for an
// Ackerman car it is the middle of the rear axle, for a skid-steer vehicle near the centre.
//
// Mean propagation (nonlinear, constant v and theta_dot over dt), with a = theta_dot dt and
// sinc(a) = sin(a)/a (unnormalised, docs/design.md note 2):
//   Eq. (5)  the axis point in its own frame C_0:
//            0x = v dt sinc(a),   0y = v theta_dot dt^2 sinc^2(a/2) / 2
//   Eq. (6)  the centre in the centre frame C_c at the start of the interval:
//            cx = v dt sinc(a) + 2 L sin^2(a/2)
//            cy = v theta_dot dt^2 sinc^2(a/2) / 2 - L sin(a)
//   Eq. (8)  (x, y)_next = (x, y) + R(theta) (cx, cy),   theta_next = theta + a,
//            L, v, theta_dot unchanged.
// Jacobian Phi (Eq. 9-11): Phi = I + T(theta) M with T(theta) = blockdiag(R(theta), I4), and
//   the (x, y) rows of M: d/dL = (2 sin^2(a/2), -sin a),  d/dv = (dt sinc a, dt g(a)),
//   d/dtheta = (-cy, cx),
//   d/dtheta_dot = (v dt^2 sinc'(a) + L dt sin a,  v dt^2 g'(a) - L dt cos a),
//   where g(a) = (1 - cos a)/a = (a/2) sinc^2(a/2) and g'(a) = sinc(a) - sinc^2(a/2)/2 (Eq. 11);
//   the theta row has dt in the theta_dot column.
// Near theta_dot = 0 sinc and sinc' use their Taylor series (Sinc, SincDerivative below), so the
// mean and Phi are smooth through theta_dot = 0 and exact for straight motion.
//
// Centre velocity (Eq. 7): the centre lies at -L along the heading from the axis point, so its
// velocity in the vehicle frame is (v, -L theta_dot): direction offset
//   dtheta_c = atan2(-L theta_dot, v) from theta, and speed v_c = |(v, -L theta_dot)| >= 0
// (the paper's v / cos(dtheta_c), computed without the division that fails at v = 0).
//
// System noise (Eq. 12-13, derived here; docs/design.md note 3). Three independent white noises drive the
// model: an along-arc acceleration on v (spectral density alpha [m^2/s^3]), an angular
// acceleration on theta_dot (gamma [rad^2/s^3]), and a random walk of L (epsilon_L [m^2/s]).
// Work in the frame of the vehicle at the start of the interval, s along theta and n to its left,
// state order (s, n, L, v, theta, theta_dot). An impulse of a noise sigma before the end of the
// interval changes the end state by a vector b(sigma), and Q = density * integral_0^dt b b^T
// dsigma, which is positive semi-definite by construction.
//  * Angular acceleration (the paper's derivation, Eq. 12). The heading error grows as
//    dtheta(sigma) = sigma; the axis point then drifts sideways at v sin(dtheta) ~ v dtheta (the
//    lateral offset ~ v theta), giving v sigma^2/2; and the centre, which sits -L along the
//    heading from the axis point, moves sideways by a further -L sigma:
//      b_w = (s_w, v sigma^2/2 - L sigma, 0, 0, sigma, 1).
//    For straight motion s_w = 0 and Q_n,theta,theta_dot = gamma *
//      [ v^2dt^5/20 - v L dt^4/4 + L^2 dt^3/3   v dt^4/8 - L dt^3/3   v dt^3/6 - L dt^2/2 ]
//      [ v dt^4/8 - L dt^3/3                      dt^3/3               dt^2/2             ]
//      [ v dt^3/6 - L dt^2/2                      dt^2/2               dt                 ].
//    At L = 0, the axis point for which the paper derives it, this is Eq. (12) with two of the
//    paper's typesetting errors corrected: the cross terms carry signed v, not |v| (a reversing
//    vehicle drifts to the other side for the same heading error), and the (theta, theta) term is
//    gamma dt^3/3, not dt^3/6 as printed in Eq. (13).
//    DEVIATION: the paper applies the L = 0 matrix to the centre, calling it a very good
//    approximation. It is not at scan rates: for dt = 0.1 s, v = 10 m/s and L = -1.4 m,
//    v^2 dt^5/20 = 5e-5 m^2 while the lever-arm terms add 3.5e-4 + 6.5e-4 m^2, twenty times more.
//  * Along-arc acceleration (Eq. 3 acting on s and v): b_a = (sigma, n_a, 0, 1, 0, 0).
//  * L is a random walk, Q_L = epsilon_L dt, epsilon_L in [m^2/s]: the paper's "small constant
//    epsilon_L" per step would make L wander faster at a 75 Hz scan rate than at 10 Hz; scaling
//    with dt makes the model independent of the rate. The centre does not jump when the axis
//    slides, but its later path turns about the new axis: b_L = (0, n_L, 1, 0, 0, 0).
//  * While turning (DEVIATION: the paper keeps only theta_dot = 0), the arc bends during the
//    interval and mixes the along-arc and lateral directions. To first order in theta_dot sigma,
//    from Eq. (11) evaluated over the remaining time sigma and rotated by the heading gained
//    before the impulse, theta_dot (dt - sigma):
//      n_a = theta_dot sigma (dt - sigma/2),   n_L = -theta_dot sigma,
//      s_w = theta_dot (v sigma^3/6 - v dt sigma^2/2 + L dt sigma).
//    Integrating b b^T with these gives the terms in theta_dot of ProcessNoise(); they reach a
//    few per cent of Q at 0.5 rad/s and 10 Hz, which a Monte Carlo of the noise model resolves
//    (vasm_test), and what remains is O((theta_dot dt)^2).
// Q is formed in the local frame and rotated to the world by T(theta) of the start of the
// interval: Q = T Q_local T^T (Eq. 13).
//
// Measurement (Eq. 14): H picks state indices 0, 1, 4.
#pragma once

#include <string>

#include "tracker/core/motion_model.h"
#include "tracker/core/parameters.h"

namespace vtrack {

// sinc(a) = sin(a)/a, sinc(0) = 1 (unnormalised); Taylor series for |a| < 0.1.
double Sinc(double a);
// d sinc / da = (a cos a - sin a)/a^2, 0 at a = 0; Taylor series for |a| < 0.1.
double SincDerivative(double a);

class VasmModel final : public MotionModel {
 public:
  // Throws std::invalid_argument with the Validate() message if params are invalid.
  explicit VasmModel(const VasmParams& params = VasmParams());

  const VasmParams& params() const { return params_; }

  ModelKind kind() const override { return ModelKind::kVasm; }
  Vector6d Propagate(const Vector6d& x, double dt, Matrix6d* D_next_x = nullptr) const override;
  Matrix6d ProcessNoise(const Vector6d& x, double dt) const override;
  std::array<int, 3> PoseIndices() const override { return {0, 1, 4}; }
  // Centre velocity R(theta) (v, -L theta_dot) (Eq. 7) in the ISM's x_dot, y_dot.
  Vector6d ToIsmState(const Vector6d& x, Matrix6d* D_ism_x = nullptr) const override;
  // v = the centre velocity projected on theta; L = initial_L if v >= 0, else -initial_L
  // (variance initial_L_std^2).
  Vector6d FromIsmState(const Vector6d& x_ism, Matrix6d* D_x_ism = nullptr) const override;
  Matrix6d FromIsmPriorCovariance() const override;

  // Eq. (6): the centre's displacement (cx, cy) over dt in the frame C_c at the interval's start.
  static Eigen::Vector2d CentreDisplacement(double L, double v, double theta_dot, double dt);

  // Eq. (7): direction offset dtheta_c [rad] of the centre velocity from theta, and its speed
  // v_c [m/s] >= 0. Both are 0 for a vehicle at rest.
  static void CentreVelocity(const Vector6d& x, double* dtheta_c, double* v_c);

 private:
  VasmParams params_;
};

}  // namespace vtrack
