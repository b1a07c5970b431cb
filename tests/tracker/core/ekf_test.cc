#include "tracker/core/ekf.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <boost/math/distributions/chi_squared.hpp>

#include <cmath>
#include <random>
#include <stdexcept>

#include "base/angle.h"

namespace vtrack {
namespace {

Matrix6d RandomSpd(std::mt19937_64& rng, double scale) {
  std::normal_distribution<double> n01(0.0, 1.0);
  Matrix6d A;
  for (int i = 0; i < 36; ++i) A(i) = n01(rng);
  return scale * (A * A.transpose() / 6.0 + 0.2 * Matrix6d::Identity());
}

Eigen::Matrix3d RandomR(std::mt19937_64& rng, double scale) {
  std::normal_distribution<double> n01(0.0, 1.0);
  Eigen::Matrix3d A;
  for (int i = 0; i < 9; ++i) A(i) = n01(rng);
  return scale * (A * A.transpose() / 3.0 + 0.2 * Eigen::Matrix3d::Identity());
}

// A hypothesis of `kind` with state (x0, ..., x5) and the default covariance.
Hypothesis MakeHypothesis(ModelKind kind, double x0, double x1, double x2, double x3, double x4,
                          double x5) {
  Hypothesis h;
  h.kind = kind;
  h.x << x0, x1, x2, x3, x4, x5;
  return h;
}

// Samples N(mean, cov) for the Monte Carlo checks.
template <int N>
Eigen::Matrix<double, N, 1> Sample(const Eigen::Matrix<double, N, 1>& mean,
                                   const Eigen::Matrix<double, N, N>& cov, std::mt19937_64& rng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  Eigen::Matrix<double, N, 1> w;
  for (int i = 0; i < N; ++i) w(i) = n01(rng);
  return mean + Eigen::LLT<Eigen::Matrix<double, N, N>>(cov).matrixL() * w;
}

TEST(ChiSquare, MatchesBoostMath) {
  for (int dof : {1, 2, 3, 4, 5, 6, 7, 10, 50, 300}) {
    const boost::math::chi_squared_distribution<double> dist(dof);
    for (double p : {1e-4, 0.025, 0.5, 0.9, 0.95, 0.975, 0.99, 0.999, 0.9999}) {
      const double reference = boost::math::quantile(dist, p);
      EXPECT_NEAR(ChiSquareQuantile(p, dof), reference, 1e-9 * reference) << dof << " " << p;
      EXPECT_NEAR(ChiSquareCdf(reference, dof), p, 1e-11) << dof << " " << p;
    }
  }
  EXPECT_EQ(ChiSquareCdf(0.0, 3), 0.0);
  EXPECT_THROW(ChiSquareQuantile(1.0, 3), std::invalid_argument);
  EXPECT_THROW(ChiSquareQuantile(0.5, 0), std::invalid_argument);
  EXPECT_NEAR(Ekf().gate_nis(),
              boost::math::quantile(boost::math::chi_squared_distribution<double>(3), 0.999),
              1e-9);
}

// Eq. (19) for a linear measurement is Bayes' rule for Gaussians; in information form two
// updates give P^-1 = P0^-1 + H^T (R1^-1 + R2^-1) H and P^-1 x = P0^-1 x0 + H^T (R1^-1 z1 +
// R2^-1 z2), with H of Eq. (14) written out here for each model.
TEST(Ekf, UpdateEqualsInformationFormFusion) {
  std::mt19937_64 rng(3);
  const Ekf ekf(IsmParams(), VasmParams(), EkfParams{0.999999});
  for (ModelKind kind : {ModelKind::kIsm, ModelKind::kVasm}) {
    const int idx[3] = {0, kind == ModelKind::kIsm ? 2 : 1, 4};
    Eigen::Matrix<double, 3, 6> H = Eigen::Matrix<double, 3, 6>::Zero();
    for (int r = 0; r < 3; ++r) H(r, idx[r]) = 1.0;
    for (int trial = 0; trial < 20; ++trial) {
      Hypothesis h;
      h.kind = kind;
      h.x << 1.0, 2.0, -1.0, 3.0, 0.4, -0.1;
      h.P = RandomSpd(rng, 0.05);
      const Vector6d x0 = h.x;
      const Matrix6d P0 = h.P;
      CentreMeasurement m1, m2;
      m1.R = RandomR(rng, 0.02);
      m2.R = RandomR(rng, 0.03);
      m1.z = H * x0 + Eigen::Vector3d(0.1, -0.05, 0.02);
      m2.z = H * x0 + Eigen::Vector3d(-0.03, 0.08, -0.01);
      ASSERT_TRUE(ekf.Update(m1, &h).accepted);
      ASSERT_TRUE(ekf.Update(m2, &h).accepted);

      const Matrix6d info = P0.inverse() + H.transpose() * (m1.R.inverse() + m2.R.inverse()) * H;
      const Vector6d eta = P0.inverse() * x0 + H.transpose() * (m1.R.inverse() * m1.z +
                                                                m2.R.inverse() * m2.z);
      const Matrix6d P_ref = info.inverse();
      const Vector6d x_ref = P_ref * eta;
      EXPECT_LT((h.x - x_ref).cwiseAbs().maxCoeff(), 1e-10) << ToString(kind);
      EXPECT_LT((h.P - P_ref).cwiseAbs().maxCoeff(), 1e-10 * P_ref.cwiseAbs().maxCoeff())
          << ToString(kind);
    }
  }
}

// With the truth drawn from the prior and the measurement from its noise model, the NIS is
// chi-square with 3 dof: mean 3, and the gate refuses a fraction 1 - gate_probability.
TEST(Ekf, NisIsChiSquareAndGateRefusesItsShare) {
  const double gate_probability = 0.95;
  const Ekf ekf(IsmParams(), VasmParams(), EkfParams{gate_probability});
  std::mt19937_64 rng(5);
  Hypothesis prior = MakeHypothesis(ModelKind::kVasm, 10.0, -4.0, -1.3, 7.0, 2.0, 0.2);
  prior.P = RandomSpd(rng, 0.04);
  const Eigen::Matrix3d R = RandomR(rng, 0.01);
  const int n = 20000;
  double nis_sum = 0.0;
  int refused = 0;
  for (int i = 0; i < n; ++i) {
    const Vector6d truth = Sample<6>(prior.x, prior.P, rng);
    CentreMeasurement m;
    m.R = R;
    m.z = Sample<3>(Eigen::Vector3d(truth(0), truth(1), truth(4)), R, rng);
    Hypothesis h = prior;
    const UpdateResult r = ekf.Update(m, &h);
    ASSERT_TRUE(std::isfinite(r.nis));
    nis_sum += r.nis;
    if (!r.accepted) {
      EXPECT_EQ(r.reason, UpdateStatus::kGated);
      EXPECT_GT(r.nis, r.gate);
      ++refused;
    }
  }
  EXPECT_NEAR(nis_sum / n, 3.0, 4.0 * std::sqrt(6.0 / n));
  const double expected = 1.0 - gate_probability;
  EXPECT_NEAR(static_cast<double>(refused) / n, expected,
              4.0 * std::sqrt(expected * (1.0 - expected) / n));
}

// theta of the state just below +pi, measured just above -pi: the innovation goes the short way
// (+0.04 rad, not -2 pi + 0.04) and the result equals the same update in a frame turned by pi.
TEST(Ekf, OrientationInnovationIsWrapped) {
  const Ekf ekf;
  for (ModelKind kind : {ModelKind::kIsm, ModelKind::kVasm}) {
    Hypothesis near_pi;
    near_pi.kind = kind;
    near_pi.x << 0.0, 1.0, 0.0, 2.0, kPi - 0.02, 0.0;
    near_pi.P = Matrix6d::Identity() * 0.01;
    CentreMeasurement m;
    const int iy = kind == ModelKind::kIsm ? 2 : 1;
    m.z << near_pi.x(0), near_pi.x(iy), -kPi + 0.02;
    m.R = Eigen::Matrix3d::Identity() * 0.01;

    Hypothesis near_zero = near_pi;
    near_zero.x(4) = -0.02;
    CentreMeasurement m0 = m;
    m0.z(2) = 0.02;

    const UpdateResult r = ekf.Update(m, &near_pi);
    const UpdateResult r0 = ekf.Update(m0, &near_zero);
    ASSERT_TRUE(r.accepted) << ToString(r.reason);
    ASSERT_TRUE(r0.accepted);
    EXPECT_NEAR(r.innovation(2), 0.04, 1e-12);
    EXPECT_NEAR(r.nis, r0.nis, 1e-9);
    EXPECT_NEAR(AngleDiff(near_pi.x(4), near_zero.x(4) + kPi), 0.0, 1e-12);
    EXPECT_GT(near_pi.x(4), -kPi);
    EXPECT_LE(near_pi.x(4), kPi);
    EXPECT_LT((near_pi.P - near_zero.P).cwiseAbs().maxCoeff(), 1e-15);
  }
}

TEST(Ekf, GatedMeasurementLeavesHypothesisUnchanged) {
  const Ekf ekf;
  Hypothesis h = MakeHypothesis(ModelKind::kIsm, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0);
  h.P = Matrix6d::Identity() * 0.01;
  const Hypothesis before = h;
  CentreMeasurement m;
  m.z << 3.0, 0.0, 0.0;  // 3 m away; S_xx = 0.02 m^2: NIS = 450
  m.R = Eigen::Matrix3d::Identity() * 0.01;
  const UpdateResult r = ekf.Update(m, &h);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.reason, UpdateStatus::kGated);
  EXPECT_NEAR(r.nis, 9.0 / 0.02, 1e-9);
  EXPECT_DOUBLE_EQ(r.gate, ekf.gate_nis());
  EXPECT_LT((r.innovation_cov - 0.02 * Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(h.x, before.x);
  EXPECT_EQ(h.P, before.P);
}

TEST(Ekf, BadMeasurementOrStateIsRefusedWithReason) {
  const Ekf ekf;
  Hypothesis good = MakeHypothesis(ModelKind::kVasm, 0.0, 0.0, -1.0, 5.0, 0.0, 0.0);
  CentreMeasurement ok;
  ok.R = Eigen::Matrix3d::Identity() * 0.01;

  std::vector<CentreMeasurement> bad(4, ok);
  bad[0].z(1) = std::numeric_limits<double>::quiet_NaN();
  bad[1].R(0, 2) = 0.005;  // not symmetric
  bad[2].R(1, 1) = -0.01;  // not positive definite
  bad[3].R(2, 2) = std::numeric_limits<double>::infinity();
  for (const CentreMeasurement& m : bad) {
    Hypothesis h = good;
    const UpdateResult r = ekf.Update(m, &h);
    EXPECT_FALSE(r.accepted);
    EXPECT_EQ(r.reason, UpdateStatus::kInvalidMeasurement) << ToString(r.reason);
    EXPECT_EQ(h.x, good.x);
  }
  Hypothesis diverged = good;
  diverged.P(3, 3) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(ekf.Update(ok, &diverged).reason, UpdateStatus::kInvalidState);
  EXPECT_TRUE(ekf.Update(ok, &good).accepted);
  EXPECT_STRNE(ToString(UpdateStatus::kGated), ToString(UpdateStatus::kInvalidState));
}

TEST(Ekf, CallerErrorsThrowNamingTheValue) {
  const Ekf ekf;
  Hypothesis h;
  auto message = [&](auto&& call) -> std::string {
    try {
      call();
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no exception";
  };
  EXPECT_NE(message([&] { ekf.Predict(-0.25, 1.0, &h); }).find("-0.25"), std::string::npos);
  EXPECT_NE(message([&] { ekf.Predict(std::nan(""), 1.0, &h); }).find("dt"), std::string::npos);
  EXPECT_NE(message([&] { ekf.Predict(0.1, 0.0, &h); }).find("noise_scale"), std::string::npos);
  EXPECT_NE(message([&] { EkfPredict(ekf.vasm(), 0.1, 1.0, &h); }).find("ISM"),
            std::string::npos);
  EXPECT_NE(message([&] { ekf.PredictTrajectory(h, 3.0, 0.0); }).find("step_s"),
            std::string::npos);
  EkfParams bad;
  bad.gate_probability = 1.0;
  EXPECT_NE(message([&] { Ekf e(IsmParams(), VasmParams(), bad); }).find("gate_probability = 1"),
            std::string::npos);
}

// Predicting from P = 0 leaves k Q: for the ISM, Eq. (3) scaled by the noise factor k.
TEST(Ekf, PredictScalesSystemNoise) {
  const Ekf ekf;
  const double dt = 0.2, k = 2.5;
  Hypothesis h = MakeHypothesis(ModelKind::kIsm, 1.0, 2.0, 3.0, 4.0, 0.5, 0.1);
  h.P.setZero();
  ekf.Predict(dt, k, &h);
  const double alpha = ekf.ism().params().alpha, beta = ekf.ism().params().beta;
  EXPECT_NEAR(h.P(0, 0), k * alpha * dt * dt * dt / 3.0, 1e-15);
  EXPECT_NEAR(h.P(2, 3), k * alpha * dt * dt / 2.0, 1e-15);
  EXPECT_NEAR(h.P(5, 5), k * beta * dt, 1e-15);
  EXPECT_NEAR(h.x(0), 1.0 + 2.0 * dt, 1e-15);
}

// Many cycles of predict and very precise measurements from a very uncertain start: the
// covariance stays symmetric positive definite (Joseph form, docs/design.md, note 7).
TEST(Ekf, CovarianceStaysSymmetricPositiveDefinite) {
  const Ekf ekf(IsmParams(), VasmParams(), EkfParams{0.999999999});
  std::mt19937_64 rng(9);
  for (ModelKind kind : {ModelKind::kIsm, ModelKind::kVasm}) {
    Hypothesis h;
    h.kind = kind;
    h.x << 0.0, 0.0, 0.0, 0.0, 0.0, 0.0;
    h.P = RandomSpd(rng, 1e4);
    std::normal_distribution<double> n01(0.0, 1.0);
    for (int k = 0; k < 2000; ++k) {
      ekf.Predict(0.05, 1.0, &h);
      CentreMeasurement m;
      m.R = RandomR(rng, 1e-10);
      const std::array<int, 3> idx = ekf.model(kind).PoseIndices();
      m.z << h.x(idx[0]) + 1e-5 * n01(rng), h.x(idx[1]) + 1e-5 * n01(rng),
          h.x(idx[2]) + 1e-5 * n01(rng);
      const UpdateResult r = ekf.Update(m, &h);
      ASSERT_TRUE(r.accepted) << ToString(r.reason) << " at " << k;
      ASSERT_EQ((h.P - h.P.transpose()).cwiseAbs().maxCoeff(), 0.0);
      const Eigen::SelfAdjointEigenSolver<Matrix6d> eig(h.P);
      ASSERT_GT(eig.eigenvalues().minCoeff(), 0.0) << "cycle " << k << "\n" << h.P;
    }
  }
}

TEST(Ekf, CentreEstimateOfBothModels) {
  const Ekf ekf;
  Hypothesis ism = MakeHypothesis(ModelKind::kIsm, 1.0, -3.0, 2.0, 4.0, 0.3, 0.2);
  ism.P = Matrix6d::Identity() * 0.5;
  ism.P(1, 3) = ism.P(3, 1) = 0.1;
  const CentreEstimate a = ekf.Centre(ism);
  EXPECT_EQ(a.pose, Eigen::Vector3d(1.0, 2.0, 0.3));
  EXPECT_DOUBLE_EQ(a.speed, 5.0);
  EXPECT_DOUBLE_EQ(a.velocity_heading, std::atan2(4.0, -3.0));
  EXPECT_DOUBLE_EQ(a.velocity_cov(0, 1), 0.1);
  EXPECT_DOUBLE_EQ(a.yaw_rate, 0.2);
  EXPECT_TRUE(std::isnan(a.rear_axle_offset));

  // VASM: centre velocity of a rigid body, v_axis + theta_dot z x (centre - axis), with the axis
  // point at L along the heading; its covariance from Monte Carlo of that formula.
  Hypothesis vasm = MakeHypothesis(ModelKind::kVasm, 1.0, 2.0, -1.3, 6.0, -2.8, 0.4);
  std::mt19937_64 rng(21);
  vasm.P = RandomSpd(rng, 1e-4);
  auto rigid_velocity = [](const Vector6d& x) {
    const Eigen::Vector2d u(std::cos(x(4)), std::sin(x(4)));
    const Eigen::Vector2d centre_from_axis = -x(2) * u;
    return Eigen::Vector2d(x(3) * u + x(5) * Eigen::Vector2d(-centre_from_axis.y(),
                                                             centre_from_axis.x()));
  };
  const CentreEstimate b = ekf.Centre(vasm);
  const Eigen::Vector2d vel = rigid_velocity(vasm.x);
  EXPECT_NEAR((b.velocity - vel).norm(), 0.0, 1e-12);
  EXPECT_NEAR(b.speed, vel.norm(), 1e-12);
  EXPECT_NEAR(AngleDiff(b.velocity_heading, std::atan2(vel.y(), vel.x())), 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(b.rear_axle_offset, -1.3);
  EXPECT_DOUBLE_EQ(b.rear_axle_offset_var, vasm.P(2, 2));
  EXPECT_EQ(b.pose, Eigen::Vector3d(1.0, 2.0, -2.8));
  const int n = 20000;
  Eigen::Matrix<double, 2, Eigen::Dynamic> samples(2, n);
  for (int i = 0; i < n; ++i) samples.col(i) = rigid_velocity(Sample<6>(vasm.x, vasm.P, rng));
  const Eigen::Vector2d mean = samples.rowwise().mean();
  samples.colwise() -= mean;
  const Eigen::Matrix2d mc_cov = samples * samples.transpose() / (n - 1);
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      const double se = std::sqrt((b.velocity_cov(i, i) * b.velocity_cov(j, j) +
                                   b.velocity_cov(i, j) * b.velocity_cov(i, j)) / n);
      EXPECT_NEAR(mc_cov(i, j), b.velocity_cov(i, j), 4.5 * se) << i << j;
    }
  }
}

// The hypothesis conversions of the multi-hypothesis manager keep the rigid-body motion.
TEST(Ekf, ConvertIsmToVasmAndBack) {
  const Ekf ekf;
  std::mt19937_64 rng(33);
  Hypothesis ism = MakeHypothesis(ModelKind::kIsm, 4.0, 3.0, -2.0, 5.0, 0.9, 0.25);
  ism.P = RandomSpd(rng, 1e-3);

  // ISM -> VASM: v is the centre velocity along the heading; L from the prior.
  const Hypothesis vasm = ekf.Convert(ism, ModelKind::kVasm);
  EXPECT_EQ(vasm.kind, ModelKind::kVasm);
  const Eigen::Vector2d u(std::cos(0.9), std::sin(0.9));
  EXPECT_NEAR(vasm.x(3), u.dot(Eigen::Vector2d(3.0, 5.0)), 1e-12);
  EXPECT_EQ(vasm.x(2), ekf.vasm().params().initial_L);
  EXPECT_NEAR(vasm.P(2, 2), std::pow(ekf.vasm().params().initial_L_std, 2), 1e-12);
  EXPECT_EQ(vasm.x(0), 4.0);
  EXPECT_EQ(vasm.x(1), -2.0);
  EXPECT_EQ(vasm.x(4), 0.9);
  EXPECT_EQ(vasm.x(5), 0.25);
  EXPECT_DOUBLE_EQ(vasm.P(0, 0), ism.P(0, 0));
  EXPECT_DOUBLE_EQ(vasm.P(1, 4), ism.P(2, 4));
  // var(v) by Monte Carlo of the projection v = (x_dot, y_dot) . (cos theta, sin theta).
  const int n = 20000;
  double s = 0.0, s2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const Vector6d xi = Sample<6>(ism.x, ism.P, rng);
    const double v = xi(1) * std::cos(xi(4)) + xi(3) * std::sin(xi(4));
    s += v;
    s2 += v * v;
  }
  const double var_v = (s2 - s * s / n) / (n - 1);
  EXPECT_NEAR(var_v, vasm.P(3, 3), 4.5 * vasm.P(3, 3) * std::sqrt(2.0 / n));

  // VASM -> ISM: the ISM velocity is the VASM centre velocity (Eq. 7).
  const Hypothesis back = ekf.Convert(vasm, ModelKind::kIsm);
  const CentreEstimate c = ekf.Centre(vasm);
  EXPECT_NEAR(back.x(1), c.velocity.x(), 1e-12);
  EXPECT_NEAR(back.x(3), c.velocity.y(), 1e-12);
  // The velocity along the heading survives the round trip; across it, the VASM centre moves at
  // -L theta_dot (Eq. 7) with L from the prior.
  const Eigen::Vector2d left(-u.y(), u.x());
  EXPECT_NEAR(back.x(1) * u.x() + back.x(3) * u.y(), u.dot(Eigen::Vector2d(3.0, 5.0)), 1e-12);
  EXPECT_NEAR(back.x(1) * left.x() + back.x(3) * left.y(), -vasm.x(2) * 0.25, 1e-12);

  // A centre moving against theta: theta likely points to the back, the axis is ahead.
  Hypothesis backwards = ism;
  backwards.x(1) = -3.0;
  backwards.x(3) = -5.0;
  const Hypothesis vasm_backwards = ekf.Convert(backwards, ModelKind::kVasm);
  EXPECT_LT(vasm_backwards.x(3), 0.0);
  EXPECT_EQ(vasm_backwards.x(2), -ekf.vasm().params().initial_L);

  // Same kind, no offset: unchanged.
  const Hypothesis same = ekf.Convert(vasm, ModelKind::kVasm);
  EXPECT_EQ(same.x, vasm.x);
  EXPECT_EQ(same.P, vasm.P);
}

// While a corner leaves the orientation ambiguous, a second VASM is held at theta + 90 deg.
TEST(Ekf, ConvertVasmToAlternativeOrientation) {
  const Ekf ekf;
  Hypothesis vasm = MakeHypothesis(ModelKind::kVasm, 2.0, 1.0, -1.2, 0.4, kPi - 0.3, 0.05);
  std::mt19937_64 rng(41);
  vasm.P = RandomSpd(rng, 1e-2);
  const Hypothesis turned = ekf.Convert(vasm, ModelKind::kVasm, kPi / 2.0);
  EXPECT_NEAR(turned.x(4), -kPi / 2.0 - 0.3, 1e-12);  // wrapped
  EXPECT_EQ(turned.x(0), 2.0);
  EXPECT_EQ(turned.x(1), 1.0);
  EXPECT_EQ(turned.x(5), 0.05);
  const CentreEstimate c = ekf.Centre(vasm);
  const Eigen::Vector2d u_new(std::cos(turned.x(4)), std::sin(turned.x(4)));
  EXPECT_NEAR(turned.x(3), c.velocity.dot(u_new), 1e-12);
  const double prior_L = ekf.vasm().params().initial_L;
  EXPECT_EQ(turned.x(2), turned.x(3) >= 0.0 ? prior_L : -prior_L);
  EXPECT_DOUBLE_EQ(turned.P(4, 4), vasm.P(4, 4));
  EXPECT_DOUBLE_EQ(turned.P(0, 1), vasm.P(0, 1));
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eig(turned.P);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);

  // ISM turned by 90 deg keeps its velocity.
  Hypothesis ism = MakeHypothesis(ModelKind::kIsm, 0.0, 1.0, 0.0, 2.0, 0.1, 0.0);
  const Hypothesis ism_turned = ekf.Convert(ism, ModelKind::kIsm, kPi / 2.0);
  EXPECT_NEAR(ism_turned.x(4), 0.1 + kPi / 2.0, 1e-12);
  EXPECT_EQ(ism_turned.x(1), 1.0);
  EXPECT_EQ(ism_turned.x(3), 2.0);
}

// The ISM predicted trajectory against its closed form: mean x0 + v t; position variance
// sigma_p^2 + t^2 sigma_v^2 + alpha t^3 / 3 (exact discretisation, so the 0.1 s steps add up to
// the one-step result).
TEST(Ekf, PredictedTrajectoryOfIsmMatchesClosedForm) {
  const Ekf ekf;
  Hypothesis h = MakeHypothesis(ModelKind::kIsm, 1.0, 2.0, -1.0, -0.5, 0.2, 0.1);
  h.P = Matrix6d::Zero();
  h.P.diagonal() << 0.04, 0.25, 0.04, 0.25, 0.01, 0.0025;
  const Hypothesis before = h;
  const std::vector<PredictedPose> traj = ekf.PredictTrajectory(h);
  ASSERT_EQ(traj.size(), 31u);
  const double alpha = ekf.ism().params().alpha;
  for (std::size_t k = 0; k < traj.size(); ++k) {
    const double t = 0.1 * k;
    EXPECT_NEAR(traj[k].t, t, 1e-12);
    EXPECT_NEAR(traj[k].pose.x(), 1.0 + 2.0 * t, 1e-9);
    EXPECT_NEAR(traj[k].pose.y(), -1.0 - 0.5 * t, 1e-9);
    EXPECT_NEAR(traj[k].pose.z(), 0.2 + 0.1 * t, 1e-9);
    EXPECT_NEAR(traj[k].pos_std, std::sqrt(0.04 + t * t * 0.25 + alpha * t * t * t / 3.0), 1e-9);
  }
  EXPECT_EQ(h.x, before.x);
  EXPECT_EQ(h.P, before.P);
  EXPECT_EQ(ekf.PredictTrajectory(h, 1.0, 0.25).size(), 5u);
  EXPECT_EQ(ekf.PredictTrajectory(h, 0.0, 0.1).size(), 1u);
}

// The VASM predicted trajectory of a car follows its Ackerman circle about the ICR.
TEST(Ekf, PredictedTrajectoryOfVasmFollowsAckermanCircle) {
  const Ekf ekf;
  Hypothesis h;
  h.kind = ModelKind::kVasm;
  const double L = -1.4, v = 5.0, w = 0.5, theta = 1.0;
  h.x << 3.0, 4.0, L, v, theta, w;
  h.P = Matrix6d::Identity() * 1e-3;
  const Eigen::Vector2d u(std::cos(theta), std::sin(theta)), left(-u.y(), u.x());
  const Eigen::Vector2d centre(3.0, 4.0);
  const Eigen::Vector2d icr = centre + L * u + (v / w) * left;
  const double radius = (centre - icr).norm();
  const std::vector<PredictedPose> traj = ekf.PredictTrajectory(h);
  ASSERT_EQ(traj.size(), 31u);
  double last_std = 0.0;
  for (const PredictedPose& p : traj) {
    EXPECT_NEAR((p.pose.head<2>() - icr).norm(), radius, 1e-9) << p.t;
    EXPECT_NEAR(AngleDiff(p.pose.z(), theta + w * p.t), 0.0, 1e-12);
    EXPECT_GE(p.pos_std, last_std);
    last_std = p.pos_std;
  }
  EXPECT_NEAR(traj[0].pos_std, std::sqrt(1e-3), 1e-12);
}

TEST(Ekf, InitIsmFromMeasurement) {
  const Ekf ekf;
  CentreMeasurement m;
  m.z << 1.0, 2.0, 0.5;
  m.R = Eigen::Matrix3d::Identity() * 0.04;
  const Hypothesis h = ekf.InitIsm(m);
  EXPECT_EQ(h.kind, ModelKind::kIsm);
  const CentreEstimate c = ekf.Centre(h);
  EXPECT_EQ(c.pose, m.z);
  EXPECT_EQ(c.pose_cov, m.R);
  EXPECT_EQ(c.speed, 0.0);
  EXPECT_EQ(c.velocity_heading, 0.5);
}

}  // namespace
}  // namespace vtrack
