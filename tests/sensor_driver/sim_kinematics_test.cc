// The simulator's vehicle kinematics against independent computations: a least-squares circle fit
// of the sampled path, an RK4 integration of the kinematic ODE written here, and finite
// differences of the reported positions.
#include <gtest/gtest.h>

#include <Eigen/QR>

#include <cmath>
#include <functional>
#include <vector>

#include "sensor_driver/sim/piecewise_linear.h"
#include "sensor_driver/sim/vehicle_motion.h"
#include "base/angle.h"

namespace vtrack::sim {
namespace {

using Eigen::Vector2d;

// Algebraic (Kasa) circle fit: minimises sum (x^2 + y^2 + D x + E y + F)^2.
void FitCircle(const std::vector<Vector2d>& p, Vector2d* centre, double* radius) {
  Eigen::MatrixXd A(p.size(), 3);
  Eigen::VectorXd b(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    A(i, 0) = p[i].x();
    A(i, 1) = p[i].y();
    A(i, 2) = 1.0;
    b(i) = -(p[i].squaredNorm());
  }
  const Eigen::Vector3d s = A.colPivHouseholderQr().solve(b);
  *centre = Vector2d(-0.5 * s(0), -0.5 * s(1));
  *radius = std::sqrt(centre->squaredNorm() - s(2));
}

TEST(PiecewiseLinearTest, InterpolatesHoldsAndSteps) {
  const PiecewiseLinear f({{1.0, 2.0}, {3.0, 6.0}, {3.0, 0.0}, {5.0, 1.0}});
  EXPECT_DOUBLE_EQ(f.At(0.0), 2.0);   // held before the first keyframe
  EXPECT_DOUBLE_EQ(f.At(2.0), 4.0);   // halfway from 2 to 6
  EXPECT_NEAR(f.At(2.999999), 6.0 - 2.0 * 1e-6, 1e-12);  // still on the 2 -> 6 ramp
  EXPECT_DOUBLE_EQ(f.At(3.0), 0.0);   // the step: the later keyframe holds from t = 3
  EXPECT_DOUBLE_EQ(f.At(4.0), 0.5);
  EXPECT_DOUBLE_EQ(f.At(9.0), 1.0);   // held after the last
  EXPECT_DOUBLE_EQ(f.Derivative(2.0), 2.0);
  EXPECT_DOUBLE_EQ(f.Derivative(4.0), 0.5);
  EXPECT_DOUBLE_EQ(f.Derivative(0.5), 0.0);
  EXPECT_TRUE(PiecewiseLinear().IsZero());
  EXPECT_DOUBLE_EQ(PiecewiseLinear().At(3.0), 0.0);
  EXPECT_THROW(PiecewiseLinear({{2.0, 1.0}, {1.0, 1.0}}), std::invalid_argument);
  EXPECT_THROW(PiecewiseLinear({{0.0, std::nan("")}}), std::invalid_argument);
}

struct TurnCase {
  double speed, steer_deg, wheelbase, axis;
};

class AckermanCircleTest : public ::testing::TestWithParam<TurnCase> {};

// A car at constant steering drives its rear axle on a circle of radius wheelbase / tan(steer),
// forwards or reversing; its centre, L ahead of the axle, on one of radius sqrt(R^2 + L^2).
TEST_P(AckermanCircleTest, RadiusIsWheelbaseOverTanSteer) {
  const TurnCase c = GetParam();
  const double steer = DegToRad(c.steer_deg);
  VehicleMotion m({SteeringKind::kAckerman, c.wheelbase, c.axis}, Vector2d(3.0, -2.0), 0.7,
                  PiecewiseLinear({{0.0, c.speed}}), PiecewiseLinear({{0.0, steer}}), 20.0);
  std::vector<Vector2d> axle, centre;
  for (double t = 0.0; t <= 20.0; t += 0.37) {
    const MotionState s = m.At(t);
    axle.push_back(s.axis_point);
    centre.push_back(s.center);
    // Eq. (kinematic bicycle): omega = v tan(delta) / wheelbase.
    EXPECT_NEAR(s.yaw_rate, c.speed * std::tan(steer) / c.wheelbase, 1e-12);
  }
  const double R = c.wheelbase / std::tan(std::abs(steer));
  Vector2d o1, o2;
  double r1, r2;
  FitCircle(axle, &o1, &r1);
  FitCircle(centre, &o2, &r2);
  EXPECT_NEAR(r1, R, 1e-6 * R);
  EXPECT_NEAR(r2, std::hypot(R, c.axis), 1e-6 * R);
  EXPECT_NEAR((o1 - o2).norm(), 0.0, 1e-6 * R);
  for (const auto& p : axle) EXPECT_NEAR((p - o1).norm(), R, 1e-7 * R);
  // The turning centre lies on the steered side (left for steer > 0), whatever the sign of v.
  const MotionState s0 = m.At(0.0);
  const Vector2d left(-std::sin(s0.yaw), std::cos(s0.yaw));
  EXPECT_NEAR((o1 - s0.axis_point).dot(left), steer > 0 ? R : -R, 1e-6 * R);
  // After t, the heading has changed by omega t (unwrapped through WrapToPi).
  EXPECT_NEAR(AngleDiff(m.At(7.0).yaw, 0.7 + 7.0 * c.speed * std::tan(steer) / c.wheelbase), 0.0, 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Cases, AckermanCircleTest,
                         ::testing::Values(TurnCase{5.0, 20.0, 2.7, -1.35},
                                           TurnCase{8.0, -12.0, 2.7, -1.35},
                                           TurnCase{-2.0, 25.0, 2.7, -1.35},   // reversing
                                           TurnCase{3.0, 35.0, 5.0, -2.0},     // truck
                                           TurnCase{12.0, 2.0, 3.0, -1.5}));   // wide curve

// The kinematic ODE integrated here with classical RK4 at 0.2 ms, for ramps of speed (through a
// reversal) and steering: the tabulated path must agree to well under a millimetre.
TEST(VehicleMotionTest, MatchesIndependentRk4Integration) {
  const PiecewiseLinear v({{0.0, 4.0}, {3.0, 6.0}, {5.0, 0.0}, {6.0, -2.0}, {9.0, -2.0}, {10.0, 3.0}});
  const PiecewiseLinear d({{0.0, 0.0}, {1.0, 0.3}, {4.0, -0.2}, {7.0, 0.4}, {10.0, 0.0}});
  const double wb = 2.9, L = -1.4, yaw0 = -0.4;
  const Vector2d c0(10.0, 5.0);
  VehicleMotion m({SteeringKind::kAckerman, wb, L}, c0, yaw0, v, d, 12.0);

  // State (x, y, theta) of the rear axle: x' = v cos(theta), y' = v sin(theta), theta' = v tan(delta) / wb.
  auto f = [&](double t, const Eigen::Vector3d& s) {
    const double vv = v.At(t);
    return Eigen::Vector3d(vv * std::cos(s(2)), vv * std::sin(s(2)), vv * std::tan(d.At(t)) / wb);
  };
  Eigen::Vector3d s(c0.x() + L * std::cos(yaw0), c0.y() + L * std::sin(yaw0), yaw0);
  const double h = 2e-4;
  double t = 0.0;
  for (int step = 1; t < 11.999; ++step) {
    const Eigen::Vector3d k1 = f(t, s), k2 = f(t + h / 2, s + h / 2 * k1),
                          k3 = f(t + h / 2, s + h / 2 * k2), k4 = f(t + h, s + h * k3);
    s += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    t = step * h;
    if (step % 1237 == 0 || t >= 11.999) {
      const MotionState ms = m.At(t);
      ASSERT_NEAR(ms.axis_point.x(), s(0), 2e-4) << "t = " << t;
      ASSERT_NEAR(ms.axis_point.y(), s(1), 2e-4) << "t = " << t;
      ASSERT_NEAR(AngleDiff(ms.yaw, s(2)), 0.0, 1e-5) << "t = " << t;
    }
  }
}

// Reported velocities against central differences of reported positions and headings, and the
// nonholonomic constraint: the rotation-axis point moves only along the heading.
void CheckDerivatives(const VehicleMotion& m, double t_end) {
  const double h = 1e-4;
  for (double t = 0.05; t < t_end; t += 0.173) {
    const MotionState a = m.At(t - h), b = m.At(t + h), s = m.At(t);
    const Vector2d vc = (b.center - a.center) / (2 * h);
    const Vector2d va = (b.axis_point - a.axis_point) / (2 * h);
    const double w = AngleDiff(b.yaw, a.yaw) / (2 * h);
    const Vector2d heading(std::cos(s.yaw), std::sin(s.yaw));
    const Vector2d left(-heading.y(), heading.x());
    SCOPED_TRACE("t = " + std::to_string(t));
    EXPECT_NEAR((s.center_velocity - vc).norm(), 0.0, 2e-3);
    EXPECT_NEAR(s.yaw_rate, w, 2e-3);
    EXPECT_NEAR(s.speed, va.dot(heading), 2e-3);
    EXPECT_NEAR(va.dot(left), 0.0, 2e-3);
    // Eq. (7): the centre's velocity direction is offset from the heading by atan2(-L omega, v).
    const double L = m.params().rotation_axis_offset;
    if (std::abs(s.speed) > 0.5) {
      const Vector2d dir = s.center_velocity.normalized();
      const double offset = std::atan2(dir.dot(left), dir.dot(heading));
      EXPECT_NEAR(AngleDiff(offset, std::atan2(-L * s.yaw_rate, s.speed)), 0.0, 1e-9);
      // ... and its speed is v / cos(offset).
      EXPECT_NEAR(s.center_velocity.norm(),
                  std::abs(s.speed / std::cos(std::atan2(-L * s.yaw_rate, s.speed))), 1e-9);
    }
  }
}

TEST(VehicleMotionTest, VelocitiesMatchFiniteDifferencesAckerman) {
  VehicleMotion m({SteeringKind::kAckerman, 2.7, -1.35}, Vector2d(0, 0), 1.0,
                  PiecewiseLinear({{0, 3.0}, {4, 7.0}, {6, -1.5}, {9, -1.5}}),
                  PiecewiseLinear({{0, 0.0}, {2, 0.4}, {5, -0.3}, {8, 0.1}}), 10.0);
  CheckDerivatives(m, 9.5);
}

TEST(VehicleMotionTest, VelocitiesMatchFiniteDifferencesSkidSteer) {
  VehicleMotion m({SteeringKind::kSkidSteer, 0.0, 0.3}, Vector2d(1, 2), -2.0,
                  PiecewiseLinear({{0, 0.0}, {2, 1.5}, {5, 1.5}, {6, 0.0}, {8, -1.0}}),
                  PiecewiseLinear({{0, 0.5}, {3, -0.4}, {7, 0.8}}), 10.0);
  CheckDerivatives(m, 9.5);
}

// A skid-steer turning in place (v = 0) keeps its rotation axis still; its centre, L away,
// circles it.
TEST(VehicleMotionTest, SkidSteerTurnsInPlaceAboutItsAxis) {
  const double L = -0.5, w = 0.6;
  VehicleMotion m({SteeringKind::kSkidSteer, 0.0, L}, Vector2d(4, 4), 0.0, PiecewiseLinear(),
                  PiecewiseLinear({{0, w}}), 12.0);
  EXPECT_FALSE(m.IsStatic());
  const Vector2d axis = m.At(0.0).axis_point;
  EXPECT_NEAR((axis - Vector2d(4 + L, 4)).norm(), 0.0, 1e-12);
  for (double t = 0.0; t < 12.0; t += 0.9) {
    const MotionState s = m.At(t);
    EXPECT_NEAR((s.axis_point - axis).norm(), 0.0, 1e-9);
    EXPECT_NEAR((s.center - axis).norm(), std::abs(L), 1e-9);
    EXPECT_NEAR(AngleDiff(s.yaw, w * t), 0.0, 1e-9);
    EXPECT_NEAR(s.center_velocity.norm(), std::abs(L * w), 1e-9);
  }
}

TEST(VehicleMotionTest, StaticVehicleNeverMoves) {
  VehicleMotion m({SteeringKind::kAckerman, 2.7, -1.35}, Vector2d(7, 8), 0.3, PiecewiseLinear(),
                  PiecewiseLinear({{0, 0.4}}), 5.0);
  EXPECT_TRUE(m.IsStatic());
  const MotionState s = m.At(3.0);
  EXPECT_EQ(s.center, Vector2d(7, 8));
  EXPECT_DOUBLE_EQ(s.yaw, 0.3);
  EXPECT_EQ(s.center_velocity.norm(), 0.0);
}

TEST(VehicleMotionTest, RejectsBadParameters) {
  EXPECT_THROW(VehicleMotion({SteeringKind::kAckerman, 0.0, -1.0}, Vector2d(0, 0), 0,
                             PiecewiseLinear(), PiecewiseLinear(), 1.0),
               std::invalid_argument);
  EXPECT_THROW(VehicleMotion({SteeringKind::kAckerman, 2.7, -1.0}, Vector2d(0, 0), 0,
                             PiecewiseLinear(), PiecewiseLinear({{0, DegToRad(85.0)}}), 1.0),
               std::invalid_argument);
  EXPECT_THROW(VehicleMotion({SteeringKind::kAckerman, 2.7, -1.0}, Vector2d(std::nan(""), 0), 0,
                             PiecewiseLinear(), PiecewiseLinear(), 1.0),
               std::invalid_argument);
}

// Beyond the tabulated span the controls of the last keyframe hold and the integration goes on.
TEST(VehicleMotionTest, ExtrapolatesPastTheTable) {
  const double R = 2.7 / std::tan(0.2);
  VehicleMotion m({SteeringKind::kAckerman, 2.7, -1.35}, Vector2d(0, 0), 0.0,
                  PiecewiseLinear({{0, 5.0}}), PiecewiseLinear({{0, 0.2}}), 2.0);
  std::vector<Vector2d> pts;
  for (double t = 2.5; t < 9.0; t += 0.5) pts.push_back(m.At(t).axis_point);
  Vector2d o;
  double r;
  FitCircle(pts, &o, &r);
  EXPECT_NEAR(r, R, 1e-6 * R);
}

}  // namespace
}  // namespace vtrack::sim
