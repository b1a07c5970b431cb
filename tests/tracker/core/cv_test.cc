// The constant-velocity reference model (cv.h): its Jacobian, its process noise against a
// numerical integration of the continuous model, its consistency (Monte Carlo NEES) on its own
// motion simulated independently in fine steps, and its relation to the ISM state.
#include "tracker/core/cv.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <boost/math/distributions/chi_squared.hpp>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "base/angle.h"
#include "tests/tracker/core/jacobian_check.h"
#include "tracker/core/ekf.h"

namespace vtrack {
namespace {

using testing::JacobianCheckOptions;
using testing::JacobianMatchesCentralDifferences;

constexpr double kDts[] = {0.01, 0.05, 0.1, 0.2, 0.5};

TEST(Cv, PhiMatchesCentralDifferences) {
  const CvModel model;
  JacobianCheckOptions options;
  options.angle_outputs = {4};
  for (double dt : kDts) {
    for (double theta : {0.4, kPi - 1e-9, -kPi + 1e-9}) {
      Vector6d x;
      x << 12.0, 5.0, -7.0, -3.0, theta, 0.0;
      Matrix6d Phi;
      model.Propagate(x, dt, &Phi);
      auto f = [&](const Vector6d& xi) { return model.Propagate(xi, dt); };
      EXPECT_TRUE(JacobianMatchesCentralDifferences(f, x, Phi, options)) << "dt " << dt;
    }
  }
}

// The continuous model: white acceleration (alpha) in x and y, white heading rate (q_theta):
// dQ/dt = F Q + Q F^T + W with F = d/dt of (x, y) by their rates, W = diag(0, alpha, 0, alpha,
// q_theta, 0), integrated by classical Runge-Kutta in fine steps.
TEST(Cv, ProcessNoiseEqualsNumericalIntegration) {
  CvParams params;
  params.alpha = 0.83;
  params.q_theta = 0.017;
  const CvModel model(params);
  Matrix6d F = Matrix6d::Zero();
  F(0, 1) = F(2, 3) = 1.0;
  Matrix6d W = Matrix6d::Zero();
  W(1, 1) = W(3, 3) = params.alpha;
  W(4, 4) = params.q_theta;
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

TEST(Cv, HeadingHeldAndYawRateDroppedFromAnIsmState) {
  const Ekf ekf;
  Hypothesis ism = ekf.InitIsm(CentreMeasurement{});
  ism.x << 1.0, 4.0, 2.0, -1.0, 0.3, 0.4;  // turning at 0.4 rad/s
  ism.P(5, 5) = 0.25;
  const Hypothesis cv = ekf.Convert(ism, ModelKind::kCv);
  EXPECT_EQ(cv.kind, ModelKind::kCv);
  EXPECT_EQ(cv.x(5), 0.0);
  EXPECT_EQ(cv.P.row(5).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(cv.P.col(5).cwiseAbs().maxCoeff(), 0.0);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(cv.x(i), ism.x(i));
  // Predicted 2 s ahead: straight on at the same heading (the ISM turns by 0.8 rad).
  const auto traj = ekf.PredictTrajectory(cv, 2.0, 0.1);
  EXPECT_NEAR(traj.back().pose(0), 1.0 + 2.0 * 4.0, 1e-12);
  EXPECT_NEAR(traj.back().pose(1), 2.0 - 2.0 * 1.0, 1e-12);
  EXPECT_NEAR(traj.back().pose(2), 0.3, 1e-12);
  EXPECT_NEAR(ekf.PredictTrajectory(ism, 2.0, 0.1).back().pose(2), 0.3 + 0.8, 1e-12);
  EXPECT_EQ(ekf.Centre(cv).yaw_rate, 0.0);
}

TEST(Cv, ParamsValidation) {
  CvParams p;
  p.q_theta = -1.0;
  EXPECT_THROW(CvModel{p}, std::invalid_argument);
  p = CvParams{};
  p.alpha = 0.0;
  EXPECT_THROW(CvModel{p}, std::invalid_argument);
}

// The CV truth in fine Euler steps of its continuous model (independent of the closed-form Q):
// the velocity takes a white-acceleration increment each substep, the position the mean of
// the velocities before and after, the heading a random-walk increment.
void StepCvTruth(double dt, int substeps, const CvParams& p, std::mt19937_64& rng, Vector6d* x) {
  std::normal_distribution<double> n01(0.0, 1.0);
  const double h = dt / substeps;
  for (int k = 0; k < substeps; ++k) {
    for (int i : {0, 2}) {
      const double v1 = (*x)(i + 1) + std::sqrt(p.alpha * h) * n01(rng);
      (*x)(i) += 0.5 * h * ((*x)(i + 1) + v1);
      (*x)(i + 1) = v1;
    }
    (*x)(4) += std::sqrt(p.q_theta * h) * n01(rng);
  }
  (*x)(4) = WrapToPi((*x)(4));
}

// NEES of the five estimated components (theta_dot is no state of the CV model) over 100 runs
// of 6 s at 10 Hz on the model's own motion, measured with correlated (x, y, theta) noise: the
// per-step average NEES of a consistent filter is chi-square with 5 R dof divided by R.
TEST(Cv, NeesWithinChiSquareBoundsOnItsOwnMotion) {
  CvParams cp;
  cp.q_theta = 0.01;
  const Ekf ekf(IsmParams(), VasmParams(), EkfParams(), cp);
  constexpr int kRuns = 100, kSteps = 60;
  constexpr double kDt = 0.1;
  std::mt19937_64 rng(77);
  std::normal_distribution<double> n01(0.0, 1.0);
  const double st = DegToRad(2.0);
  Eigen::Matrix3d R;
  R << 0.04, 0.012, 0.0, 0.012, 0.0225, 0.2 * 0.15 * st, 0.0, 0.2 * 0.15 * st, st * st;
  const Eigen::Matrix3d LR = Eigen::LLT<Eigen::Matrix3d>(R).matrixL();
  Matrix6d P0 = Matrix6d::Zero();
  P0.diagonal() << 0.09, 1.0, 0.09, 1.0, 0.0025, 0.0;
  std::vector<double> nees_sum(kSteps, 0.0);
  for (int run = 0; run < kRuns; ++run) {
    Vector6d truth;
    truth << 0.0, 6.0, 0.0, 3.0, 0.46, 0.0;
    Hypothesis h;
    h.kind = ModelKind::kCv;
    h.x = truth;
    for (int i = 0; i < 5; ++i) h.x(i) += std::sqrt(P0(i, i)) * n01(rng);
    h.P = P0;
    for (int k = 0; k < kSteps; ++k) {
      StepCvTruth(kDt, 20, cp, rng, &truth);
      ekf.Predict(kDt, 1.0, &h);
      CentreMeasurement m;
      m.R = R;
      m.z = Eigen::Vector3d(truth(0), truth(2), truth(4)) +
            LR * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
      m.z(2) = WrapToPi(m.z(2));
      // A consistent measurement is gated with probability 0.001 (EkfParams::gate_probability).
      ASSERT_NE(ekf.Update(m, &h).reason, UpdateStatus::kInvalidMeasurement);
      Eigen::Matrix<double, 5, 1> e = (truth - h.x).head<5>();
      e(4) = AngleDiff(truth(4), h.x(4));
      const Eigen::Matrix<double, 5, 5> P5 = h.P.topLeftCorner<5, 5>();
      nees_sum[static_cast<std::size_t>(k)] += e.dot(Eigen::LLT<Eigen::Matrix<double, 5, 5>>(P5).solve(e));
      ASSERT_EQ(h.x(5), 0.0);
    }
  }
  const boost::math::chi_squared_distribution<double> dist(5.0 * kRuns);
  const double lo = boost::math::quantile(dist, 0.025) / kRuns;
  const double hi = boost::math::quantile(dist, 0.975) / kRuns;
  double mean = 0.0;
  int inside = 0;
  for (double s : nees_sum) {
    mean += s / kRuns / kSteps;
    if (s / kRuns >= lo && s / kRuns <= hi) ++inside;
  }
  std::printf("CV own motion: mean ANEES %.3f (95%% bounds per step [%.3f, %.3f]), %d of %d steps inside\n",
              mean, lo, hi, inside, kSteps);
  EXPECT_GT(mean, lo);
  EXPECT_LT(mean, hi);
  EXPECT_GE(inside, static_cast<int>(0.8 * kSteps));
}

}  // namespace
}  // namespace vtrack
