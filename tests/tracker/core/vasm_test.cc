#include "tracker/core/vasm.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>
#include <stdexcept>

#include "tests/support/grid.h"
#include "tests/support/params_check.h"
#include "tests/tracker/core/jacobian_check.h"
#include "tests/tracker/core/motion_truth.h"
#include "base/angle.h"

namespace vtrack {
namespace {

using testing::AxisVehicle;
using testing::ForEachCombination;
using testing::With;
using testing::JacobianCheckOptions;
using testing::JacobianMatchesCentralDifferences;

Eigen::Vector2d Rot(double a, const Eigen::Vector2d& p) {
  return {std::cos(a) * p.x() - std::sin(a) * p.y(), std::sin(a) * p.x() + std::cos(a) * p.y()};
}

// sinc and sinc' against the closed forms in long double, across the series threshold.
TEST(Vasm, SincAndDerivativeMatchLongDoubleReference) {
  for (double mag : {1e-12, 1e-6, 1e-3, 0.02, 0.0999999, 0.1, 0.1000001, 0.5, 1.0, 3.0, 9.0}) {
    for (double a : {mag, -mag}) {
      const long double al = a;
      const long double sinc = std::sin(al) / al;
      EXPECT_NEAR(Sinc(a), static_cast<double>(sinc), 4e-16) << a;
      if (std::abs(a) >= 1e-3) {
        const long double dsinc = (al * std::cos(al) - std::sin(al)) / (al * al);
        EXPECT_NEAR(SincDerivative(a), static_cast<double>(dsinc),
                    1e-15 + 1e-10 * std::abs(static_cast<double>(dsinc)))
            << a;
      } else {
        // The closed form cancels catastrophically even in long double: use its leading terms.
        // The next term is -a^5/840.
        EXPECT_NEAR(SincDerivative(a), -a / 3.0 + a * a * a / 30.0,
                    std::pow(std::abs(a), 5) / 800.0 + 1e-16 * std::abs(a))
            << a;
      }
    }
  }
  EXPECT_EQ(Sinc(0.0), 1.0);
  EXPECT_EQ(SincDerivative(0.0), 0.0);
}

// Every column of Phi (Eq. 9-11) equals central differences of the nonlinear propagation
// (Eq. 6, 8): theta_dot = 0, +-1e-9, on the series threshold and large; v = 0, v > 0, v < 0;
// L behind, at and ahead of the centre; theta near +-pi; dt from 0.01 to 0.5 s.
TEST(Vasm, PhiMatchesCentralDifferences) {
  const VasmModel model;
  JacobianCheckOptions options;
  options.angle_outputs = {4};
  int checked = 0;
  for (double dt : {0.01, 0.1, 0.25, 0.5}) {
    for (double theta : {0.3, kPi - 1e-9, -kPi + 1e-9, kPi}) {
      for (double theta_dot : {0.0, 1e-9, -1e-9, 0.1 / dt, 0.05, 0.8, -1.5, 4.0}) {
        for (double v : {0.0, 7.5, -4.0}) {
          for (double L : {-1.4, 0.0, 0.9}) {
            Vector6d x;
            x << -20.0, 35.0, L, v, theta, theta_dot;
            Matrix6d Phi;
            model.Propagate(x, dt, &Phi);
            auto f = [&](const Vector6d& xi) { return model.Propagate(xi, dt); };
            EXPECT_TRUE(JacobianMatchesCentralDifferences(f, x, Phi, options))
                << "dt " << dt << " theta " << theta << " theta_dot " << theta_dot << " v " << v
                << " L " << L;
            ++checked;
          }
        }
      }
    }
  }
  EXPECT_EQ(checked, 4 * 4 * 8 * 3 * 3);
}

// With L at the rear axle, the model is exactly a car with Ackerman steering at constant speed
// and steering angle: the rear axle circles the instantaneous centre of rotation (ICR) at
// radius v / theta_dot, and the centre circles it rigidly. Checked in one step and in many.
TEST(Vasm, RearAxleReproducesExactAckermanArc) {
  const VasmModel model;
  struct Case {
    double v, theta_dot;
  };
  for (const Case& cs : {Case{6.0, 0.6}, Case{-3.0, 0.4}, Case{9.0, -0.25}, Case{0.0, 0.8},
                         Case{6.0, 1e-9}, Case{6.0, 0.0}, Case{-2.0, 0.0}}) {
    const double L = -1.35, theta0 = 2.9;
    const Eigen::Vector2d c0(4.0, -3.0);
    const Eigen::Vector2d heading(std::cos(theta0), std::sin(theta0));
    const Eigen::Vector2d left(-heading.y(), heading.x());
    const Eigen::Vector2d axle = c0 + L * heading;
    Vector6d x0;
    x0 << c0.x(), c0.y(), L, cs.v, theta0, cs.theta_dot;
    for (double t : {0.1, 0.5, 2.0, 7.0}) {
      Eigen::Vector2d expected;
      if (cs.theta_dot == 0.0) {
        expected = c0 + cs.v * t * heading;
      } else {
        const Eigen::Vector2d icr = axle + (cs.v / cs.theta_dot) * left;
        expected = icr + Rot(cs.theta_dot * t, c0 - icr);
      }
      const Vector6d one = model.Propagate(x0, t);
      Vector6d many = x0;
      const int steps = 50;
      for (int k = 0; k < steps; ++k) many = model.Propagate(many, t / steps);
      for (const Vector6d& x : {one, many}) {
        EXPECT_NEAR(x(0), expected.x(), 1e-6) << "v " << cs.v << " w " << cs.theta_dot << " t " << t;
        EXPECT_NEAR(x(1), expected.y(), 1e-6) << "v " << cs.v << " w " << cs.theta_dot << " t " << t;
        EXPECT_NEAR(AngleDiff(x(4), theta0 + cs.theta_dot * t), 0.0, 1e-12);
        EXPECT_EQ(x(2), L);
        EXPECT_EQ(x(3), cs.v);
        EXPECT_EQ(x(5), cs.theta_dot);
      }
    }
  }
}

// Eq. (7): the centre's velocity is that of a point of a rigid body turning about the ICR,
// theta_dot z x (centre - ICR); for theta_dot = 0 it is v along the heading.
TEST(Vasm, CentreVelocityOfEq7MatchesRigidBodyRotation) {
  const VasmModel model;
  for (double L : {-1.4, 0.0, 2.0}) {
    for (double v : {8.0, 0.0, -3.0}) {
      for (double theta_dot : {0.5, -0.9, 0.0}) {
        const double theta = -2.5;
        const Eigen::Vector2d heading(std::cos(theta), std::sin(theta));
        const Eigen::Vector2d left(-heading.y(), heading.x());
        const Eigen::Vector2d centre(1.0, 2.0);
        const Eigen::Vector2d axis = centre + L * heading;
        Eigen::Vector2d expected = v * heading;
        if (theta_dot != 0.0) {
          const Eigen::Vector2d icr = axis + (v / theta_dot) * left;
          const Eigen::Vector2d r = centre - icr;
          expected = theta_dot * Eigen::Vector2d(-r.y(), r.x());
        }
        Vector6d x;
        x << centre.x(), centre.y(), L, v, theta, theta_dot;
        double dtheta_c = 0.0, v_c = 0.0;
        VasmModel::CentreVelocity(x, &dtheta_c, &v_c);
        EXPECT_NEAR(v_c, expected.norm(), 1e-12) << L << " " << v << " " << theta_dot;
        if (expected.norm() > 0.0) {
          EXPECT_NEAR(AngleDiff(theta + dtheta_c, std::atan2(expected.y(), expected.x())), 0.0,
                      1e-12);
        } else {
          EXPECT_EQ(dtheta_c, 0.0);
        }
        const Vector6d ism = model.ToIsmState(x);
        EXPECT_NEAR(ism(1), expected.x(), 1e-12);
        EXPECT_NEAR(ism(3), expected.y(), 1e-12);
      }
    }
  }
}

TEST(Vasm, StateConversionJacobiansMatchCentralDifferences) {
  const VasmModel model;
  for (double theta : {0.3, kPi - 1e-9, -2.0}) {
    Vector6d x;
    x << 3.0, -1.0, -1.2, 6.5, theta, 0.35;
    Matrix6d D;
    model.ToIsmState(x, &D);
    auto to_ism = [&](const Vector6d& xi) { return model.ToIsmState(xi); };
    JacobianCheckOptions options;
    options.angle_outputs = {4};
    EXPECT_TRUE(JacobianMatchesCentralDifferences(to_ism, x, D, options));

    Vector6d ism;
    ism << 3.0, 4.0, -1.0, -2.5, theta, 0.35;
    model.FromIsmState(ism, &D);
    auto from_ism = [&](const Vector6d& xi) { return model.FromIsmState(xi); };
    EXPECT_TRUE(JacobianMatchesCentralDifferences(from_ism, ism, D, options));
  }
}

// Monte Carlo of the continuous noise model (motion_truth.h): white along-arc acceleration on v,
// white angular acceleration on theta_dot, random walk on L, integrated in fine substeps. The
// sample covariance of the end state must match Q element by element within the statistical
// error of a sample covariance, sqrt((Q_ii Q_jj + Q_ij^2) / N) for Gaussian data. Noise is kept
// small so that the model is in its linear range, which is what Q describes.
struct McResult {
  Matrix6d sample_cov;
  int samples;
};

McResult SimulateNoise(const Vector6d& x0, double dt, const VasmParams& p, std::uint64_t seed) {
  const int n = 20000, substeps = 20;
  std::mt19937_64 rng(seed);
  const AxisVehicle start = AxisVehicle::FromVasmState(x0);
  Eigen::Matrix<double, 6, Eigen::Dynamic> d(6, n);
  for (int i = 0; i < n; ++i) {
    AxisVehicle a = start;
    testing::StepAxisVehicle(dt, substeps, p.alpha, p.gamma, p.epsilon_L, rng, &a);
    const Eigen::Vector2d c = a.Centre();
    d.col(i) << c.x(), c.y(), a.L, a.v, a.theta, a.theta_dot;  // theta unwrapped
  }
  const Vector6d mean = d.rowwise().mean();
  d.colwise() -= mean;
  return {d * d.transpose() / (n - 1), n};
}

// Largest |S - Q| in units of the standard error of the sample covariance.
double WorstDeviation(const McResult& mc, const Matrix6d& Q, std::string* where) {
  double worst = 0.0;
  for (int i = 0; i < 6; ++i) {
    for (int j = i; j < 6; ++j) {
      const double se = std::sqrt((Q(i, i) * Q(j, j) + Q(i, j) * Q(i, j)) / mc.samples);
      const double dev = std::abs(mc.sample_cov(i, j) - Q(i, j)) / se;
      if (dev > worst) {
        worst = dev;
        std::ostringstream os;
        os << "(" << i << "," << j << "): sample " << mc.sample_cov(i, j) << " Q " << Q(i, j);
        *where = os.str();
      }
    }
  }
  return worst;
}

// The noise intensities the Monte Carlo comparisons of Q below simulate.
VasmParams MonteCarloNoise() {
  VasmParams p;
  p.alpha = 0.01;
  p.gamma = 0.001;
  p.epsilon_L = 0.002;
  return p;
}

TEST(Vasm, ProcessNoiseMatchesMonteCarloOfContinuousNoiseModel) {
  const VasmParams p = MonteCarloNoise();
  const VasmModel model(p);
  struct Case {
    double v, L, dt;
  };
  std::uint64_t seed = 11;
  for (const Case& cs : {Case{10.0, -1.4, 0.1}, Case{-6.0, -1.4, 0.1}, Case{10.0, -1.4, 0.5},
                         Case{-6.0, 1.1, 0.5}, Case{3.0, 0.0, 0.3}, Case{0.0, -1.4, 0.3}}) {
    Vector6d x0;
    x0 << 5.0, -2.0, cs.L, cs.v, 0.7, 0.0;
    const McResult mc = SimulateNoise(x0, cs.dt, p, seed++);
    const Matrix6d Q = model.ProcessNoise(x0, cs.dt);
    std::string where;
    const double worst = WorstDeviation(mc, Q, &where);
    std::printf("Q vs Monte Carlo, v %5.1f L %5.2f dt %.1f: worst |S - Q| = %.2f standard errors\n",
                cs.v, cs.L, cs.dt, worst);
    EXPECT_LT(worst, 5.0) << "v " << cs.v << " L " << cs.L << " dt " << cs.dt << " worst at "
                          << where << "\nsample\n" << mc.sample_cov << "\nQ\n" << Q;

    // The same simulation tells the corrections from the paper's printed forms: the Q of the
    // axis point (L = 0, which the paper applies to the centre) and |v| in the cross terms.
    if (cs.L != 0.0) {
      Vector6d axis_x0 = x0;
      axis_x0(2) = 0.0;
      Matrix6d Q_axis = model.ProcessNoise(axis_x0, cs.dt);
      Q_axis(2, 2) = Q(2, 2);
      const double worst_axis = WorstDeviation(mc, Q_axis, &where);
      std::printf("  the paper's axis-point Q (L = 0): worst %.1f standard errors\n", worst_axis);
      EXPECT_GT(worst_axis, 20.0) << "v " << cs.v << " L " << cs.L;
    }
    if (cs.v < 0.0) {
      Vector6d abs_v_x0 = x0;
      abs_v_x0(3) = -cs.v;
      const double worst_abs_v = WorstDeviation(mc, model.ProcessNoise(abs_v_x0, cs.dt), &where);
      std::printf("  |v| in the cross terms: worst %.1f standard errors\n", worst_abs_v);
      EXPECT_GT(worst_abs_v, 10.0) << "v " << cs.v << " L " << cs.L;
    }
  }
}

// While turning, the arc bends during the interval; Q keeps the first-order terms in theta_dot dt
// (vasm.h). At urban yaw rates and 10 Hz they are resolved by the Monte Carlo: with them Q is
// inside the statistical bounds, without them (the straight-motion Q) it is not.
TEST(Vasm, ProcessNoiseMatchesMonteCarloWhileTurning) {
  const VasmParams p = MonteCarloNoise();
  const VasmModel model(p);
  struct Case {
    double v, theta_dot;
  };
  std::uint64_t seed = 99;
  for (const Case& cs : {Case{8.0, 0.5}, Case{-4.0, -0.6}}) {
    Vector6d x0;
    x0 << 5.0, -2.0, -1.4, cs.v, -0.4, cs.theta_dot;
    const double dt = 0.1;
    const McResult mc = SimulateNoise(x0, dt, p, seed++);
    std::string where;
    const double worst = WorstDeviation(mc, model.ProcessNoise(x0, dt), &where);
    EXPECT_LT(worst, 5.0) << "v " << cs.v << " theta_dot " << cs.theta_dot << " worst at "
                          << where;
    Vector6d straight = x0;
    straight(5) = 0.0;
    const double worst_straight = WorstDeviation(mc, model.ProcessNoise(straight, dt), &where);
    std::printf("Q vs Monte Carlo, v %5.1f theta_dot %5.2f dt %.1f: worst %.2f standard errors "
                "(straight-motion Q: %.1f)\n",
                cs.v, cs.theta_dot, dt, worst, worst_straight);
    EXPECT_GT(worst_straight, 10.0) << "v " << cs.v << " theta_dot " << cs.theta_dot;
  }
}

TEST(Vasm, ProcessNoiseIsSymmetricPositiveSemiDefinite) {
  const VasmModel model;
  const int checked = ForEachCombination(
      {0.0, 0.01, 0.1, 0.5, 2.0}, {0.0, 12.0, -5.0}, {0.0, -1.5, 3.0}, {0.0, 0.3, -2.0},
      [&](double dt, double v, double L, double theta_dot) {
        Vector6d x;
        x << 0.0, 0.0, L, v, 1.0, theta_dot;
        const Matrix6d Q = model.ProcessNoise(x, dt);
        EXPECT_EQ((Q - Q.transpose()).cwiseAbs().maxCoeff(), 0.0);
        const Eigen::SelfAdjointEigenSolver<Matrix6d> eig(Q);
        EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-13 * std::max(1e-300, Q.norm()))
            << "dt " << dt << " v " << v << " L " << L << " theta_dot " << theta_dot << "\n"
            << Q;
      });
  EXPECT_EQ(checked, 5 * 3 * 3 * 3);
}

// Straight motion at the axis point (L = 0), theta = 0: the local block is the paper's Eq. (12),
// with signed v and gamma dt^3/3 in the (theta, theta) entry (docs/design.md, note 3); (x, v) is Eq. (3);
// L is eps_L dt.
TEST(Vasm, AtAxisPointQIsEq12WithSignedV) {
  VasmParams p;
  p.alpha = 1.3;
  p.gamma = 0.7;
  p.epsilon_L = 0.02;
  const VasmModel model(p);
  const double dt = 0.4;
  for (double v : {5.0, -5.0}) {
    Vector6d x;
    x << 0.0, 0.0, 0.0, v, 0.0, 0.0;
    const Matrix6d Q = model.ProcessNoise(x, dt);
    const double g = p.gamma, a = p.alpha;
    EXPECT_NEAR(Q(1, 1), g * v * v * std::pow(dt, 5) / 20.0, 1e-15);
    EXPECT_NEAR(Q(1, 4), g * v * std::pow(dt, 4) / 8.0, 1e-15);
    EXPECT_NEAR(Q(1, 5), g * v * std::pow(dt, 3) / 6.0, 1e-15);
    EXPECT_NEAR(Q(4, 4), g * std::pow(dt, 3) / 3.0, 1e-15);
    EXPECT_NEAR(Q(4, 5), g * dt * dt / 2.0, 1e-15);
    EXPECT_NEAR(Q(5, 5), g * dt, 1e-15);
    EXPECT_NEAR(Q(0, 0), a * std::pow(dt, 3) / 3.0, 1e-15);
    EXPECT_NEAR(Q(0, 3), a * dt * dt / 2.0, 1e-15);
    EXPECT_NEAR(Q(3, 3), a * dt, 1e-15);
    EXPECT_NEAR(Q(2, 2), p.epsilon_L * dt, 1e-15);
    EXPECT_EQ(Q(0, 1), 0.0);
    EXPECT_EQ(Q(0, 4), 0.0);
    EXPECT_EQ(Q(2, 3), 0.0);
  }
}

TEST(Vasm, ParamsValidationNamesFieldAndValue) {
  EXPECT_TRUE(testing::Accepted(VasmParams()));
  EXPECT_TRUE(testing::RefusedSaying(With(&VasmParams::epsilon_L, -0.01), {"epsilon_L", "-0.01"}));
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(testing::RefusedSaying(With(&VasmParams::gamma, inf), {"gamma"}));
  EXPECT_THROW(VasmModel{With(&VasmParams::initial_L_std, 0.0)}, std::invalid_argument);
}

}  // namespace
}  // namespace vtrack
