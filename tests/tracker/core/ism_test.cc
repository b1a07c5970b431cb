#include "tracker/core/ism.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <random>
#include <stdexcept>

#include "tests/support/grid.h"
#include "tests/support/params_check.h"
#include "tests/tracker/core/jacobian_check.h"
#include "base/angle.h"

namespace vtrack {
namespace {

using testing::ForEachCombination;
using testing::With;
using testing::JacobianCheckOptions;
using testing::JacobianMatchesCentralDifferences;

constexpr double kDts[] = {0.01, 0.05, 0.1, 0.2, 0.5};

// Every column of Phi equals central differences of the propagation, over theta_dot = 0,
// |theta_dot| = 1e-9, velocities of either sign and zero, theta near +-pi, dt 0.01..0.5 s.
TEST(Ism, PhiMatchesCentralDifferences) {
  const IsmModel model;
  JacobianCheckOptions options;
  options.angle_outputs = {4};
  const int checked = ForEachCombination(
      {std::begin(kDts), std::end(kDts)}, {0.4, kPi - 1e-9, -kPi + 1e-9, kPi},
      {0.0, 1e-9, -1e-9, 0.7, -2.0}, {0.0, 8.0, -3.0},
      [&](double dt, double theta, double theta_dot, double speed) {
        Vector6d x;
        x << 12.0, speed * std::cos(1.1), -7.0, speed * std::sin(1.1), theta, theta_dot;
        Matrix6d Phi;
        model.Propagate(x, dt, &Phi);
        auto f = [&](const Vector6d& xi) { return model.Propagate(xi, dt); };
        EXPECT_TRUE(JacobianMatchesCentralDifferences(f, x, Phi, options))
            << "dt " << dt << " theta " << theta << " theta_dot " << theta_dot;
      });
  EXPECT_EQ(checked, 5 * 4 * 5 * 3);
}

// Eq. (2): dQ/dt = F Q + Q F^T + W, Q(0) = 0, integrated numerically (classical Runge-Kutta,
// fine steps) for all three axes at once; Eq. (3)-(4) must equal the result.
TEST(Ism, ProcessNoiseEqualsNumericalIntegrationOfEq2) {
  IsmParams params;
  params.alpha = 1.7;
  params.beta = 0.23;
  const IsmModel model(params);
  Matrix6d F = Matrix6d::Zero();
  F(0, 1) = F(2, 3) = F(4, 5) = 1.0;
  Matrix6d W = Matrix6d::Zero();
  W(1, 1) = W(3, 3) = params.alpha;
  W(5, 5) = params.beta;
  auto rhs = [&](const Matrix6d& Q) -> Matrix6d { return F * Q + Q * F.transpose() + W; };
  for (double dt : kDts) {
    const int steps = 1000;
    const double h = dt / steps;
    Matrix6d Q = Matrix6d::Zero();
    for (int k = 0; k < steps; ++k) {
      const Matrix6d k1 = rhs(Q);
      const Matrix6d k2 = rhs(Q + 0.5 * h * k1);
      const Matrix6d k3 = rhs(Q + 0.5 * h * k2);
      const Matrix6d k4 = rhs(Q + h * k3);
      Q += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    const Matrix6d closed = model.ProcessNoise(Vector6d::Zero(), dt);
    EXPECT_LT((closed - Q).cwiseAbs().maxCoeff(), 1e-12 * Q.cwiseAbs().maxCoeff() + 1e-15)
        << "dt " << dt << "\nclosed form\n" << closed << "\nintegrated\n" << Q;
  }
}

TEST(Ism, ProcessNoiseIsSymmetricPositiveSemiDefinite) {
  const IsmModel model;
  for (double dt : {0.0, 0.01, 0.1, 0.5, 3.0}) {
    const Matrix6d Q = model.ProcessNoise(Vector6d::Zero(), dt);
    EXPECT_EQ((Q - Q.transpose()).cwiseAbs().maxCoeff(), 0.0);
    const Eigen::SelfAdjointEigenSolver<Matrix6d> eig(Q);
    EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-14 * std::max(1.0, Q.norm())) << "dt " << dt;
    if (dt > 0.0) {
      EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0) << "dt " << dt;
    }
  }
}

// Constant velocity: any sequence of steps lands on x0 + v t, theta0 + theta_dot t (mod 2 pi).
TEST(Ism, ExactOnConstantVelocity) {
  const IsmModel model;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> step(0.0, 0.3);
  Vector6d x0;
  x0 << 3.0, -4.5, 10.0, 2.25, 3.0, 0.9;
  Vector6d x = x0;
  double t = 0.0;
  for (int k = 0; k < 200; ++k) {
    const double dt = step(rng);
    x = model.Propagate(x, dt);
    t += dt;
    ASSERT_NEAR(x(0), x0(0) + x0(1) * t, 1e-9 * (1.0 + std::abs(x0(1) * t)));
    ASSERT_NEAR(x(2), x0(2) + x0(3) * t, 1e-9 * (1.0 + std::abs(x0(3) * t)));
    ASSERT_NEAR(AngleDiff(x(4), x0(4) + x0(5) * t), 0.0, 1e-9);
    ASSERT_GT(x(4), -kPi);
    ASSERT_LE(x(4), kPi);
    ASSERT_EQ(x(1), x0(1));
    ASSERT_EQ(x(3), x0(3));
    ASSERT_EQ(x(5), x0(5));
  }
}

TEST(Ism, InitFromMeasurementTakesPoseAndCovarianceFromIt) {
  IsmParams params;
  params.initial_velocity_std = 6.0;
  params.initial_yaw_rate_std = 0.4;
  const IsmModel model(params);
  CentreMeasurement m;
  m.z << 5.0, -2.0, kPi + 0.1;  // outside (-pi, pi]: wrapped
  m.R << 0.04, 0.01, 0.002, 0.01, 0.09, -0.001, 0.002, -0.001, 0.0025;
  const Hypothesis h = model.InitFromMeasurement(m);
  EXPECT_EQ(h.kind, ModelKind::kIsm);
  EXPECT_DOUBLE_EQ(h.x(0), 5.0);
  EXPECT_DOUBLE_EQ(h.x(2), -2.0);
  EXPECT_NEAR(h.x(4), -kPi + 0.1, 1e-12);
  EXPECT_EQ(h.x(1), 0.0);
  EXPECT_EQ(h.x(3), 0.0);
  EXPECT_EQ(h.x(5), 0.0);
  const int idx[3] = {0, 2, 4};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(h.P(idx[r], idx[c]), m.R(r, c));
  }
  EXPECT_DOUBLE_EQ(h.P(1, 1), 36.0);
  EXPECT_DOUBLE_EQ(h.P(3, 3), 36.0);
  EXPECT_DOUBLE_EQ(h.P(5, 5), 0.16);
  EXPECT_EQ(h.P(1, 0), 0.0);
}

TEST(Ism, ParamsValidationNamesFieldAndValue) {
  EXPECT_TRUE(testing::Accepted(IsmParams()));
  EXPECT_TRUE(testing::RefusedSaying(With(&IsmParams::beta, -0.5), {"beta", "-0.5"}));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(testing::RefusedSaying(With(&IsmParams::alpha, nan), {"alpha"}));
  const IsmParams p = With(&IsmParams::initial_velocity_std, 0.0);
  EXPECT_FALSE(p.Validate(nullptr));
  try {
    IsmModel model(p);
    ADD_FAILURE() << "invalid params accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("initial_velocity_std"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace vtrack
