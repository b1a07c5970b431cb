// Per-return times and the skew of a sweeping sensor on a moving ego: every return, placed in the
// world with the ego pose at its own time (computed analytically here, not by the simulator),
// lands on the surface it came from; placed with the pose at the sweep's start it is displaced
// by the ego's motion since, as in a real sweep.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "sensor_driver/sim/ladar.h"
#include "sensor_driver/sim/scene.h"
#include "base/angle.h"

namespace vtrack::sim {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kWheelbase = 2.8;

Scene MovingEgo(const Vector2d& body, double yaw, double speed, double steer) {
  Scene s;
  const Vector2d a(std::cos(yaw), std::sin(yaw));
  s.ego.motion = std::make_shared<VehicleMotion>(
      VehicleMotion::Params{SteeringKind::kAckerman, kWheelbase, -0.5 * kWheelbase},
      body + 0.5 * kWheelbase * a, yaw, PiecewiseLinear({{0.0, speed}}),
      PiecewiseLinear({{0.0, steer}}), 5.0);
  return s;
}

SceneObject Wall(std::int64_t id, const Vector2d& from, const Vector2d& to) {
  SceneObject o;
  o.id = id;
  o.object_class = ObjectClass::kWall;
  o.center = 0.5 * (from + to);
  o.yaw = std::atan2(to.y() - from.y(), to.x() - from.x());
  o.length = (to - from).norm();
  o.width = 0.2;
  o.height = 5.0;
  return o;
}

// One level layer at 0 deg, 360 deg, 10 Hz, clockwise from behind (the velodyne64 preset's
// timing), 1 m up, 1.2 m ahead of the rear axle.
LadarParams OneLayer360() {
  LadarParams p;
  const bool known = LadarPreset("velodyne64", &p);
  EXPECT_TRUE(known);
  p.elevations_deg = {0.0};
  p.range_noise = 0.0;
  p.max_range = 120.0;
  p.mount_xyz = Vector3d(1.2, 0.0, 1.0);
  return p;
}

struct Sweep {
  vtrack::ladar_scan_t scan;
  std::vector<int> hits;
};

Sweep Cast(const LadarParams& p, const Scene& scene, double t0) {
  LadarSimulator sim(p);
  Sweep s;
  sim.Sweep(scene, t0, 11, &s.scan, &s.hits);
  return s;
}

// dt_us of every return is the firing time of its column, recovered from the return's azimuth:
// the head turns at 360 deg * rate, clockwise from 180 deg (multi-layer) or counter-clockwise
// from -90 deg (single plane).
TEST(SweepTest, ReturnTimesFollowTheTurningHead) {
  for (const std::string preset : {"velodyne64", "single_plane"}) {
    SCOPED_TRACE(preset);
    LadarParams p;
    ASSERT_TRUE(LadarPreset(preset, &p));
    p.range_noise = 0.0;
    if (preset == "single_plane") {  // tilt it down so that the ground answers every column
      p.mount_pitch_deg = 20.0;
      p.mount_xyz = Vector3d(0, 0, 1.0);
    }
    const Scene scene = MovingEgo(Vector2d(0, 0), 0.3, 0.0, 0.0);
    const Sweep s = Cast(p, scene, 0.0);
    ASSERT_GT(s.scan.npoints, p.NumColumns() / 2);
    const double sign = p.clockwise ? -1.0 : 1.0;
    const double deg_per_us = 360.0 * p.rate_hz * 1e-6;
    EXPECT_EQ(s.scan.sweep_duration_us,
              std::llround((p.NumColumns() - 1) * p.resolution_deg / deg_per_us));
    std::int32_t last = 0;
    for (int i = 0; i < s.scan.npoints; ++i) {
      const std::int32_t dt = s.scan.dt_us[i];
      ASSERT_GE(dt, last);  // returns come in firing order
      ASSERT_LE(dt, s.scan.sweep_duration_us);
      last = dt;
      const double az = RadToDeg(std::atan2(s.scan.y[i], s.scan.x[i]));
      // Column of this azimuth, and the time the head pointed there.
      const long per_rev = std::lround(360.0 / p.resolution_deg);
      double k = std::fmod(sign * (az - p.azimuth_start_deg) / p.resolution_deg, per_rev);
      if (k < 0) k += per_rev;
      const long j = std::lround(k) % per_rev;  // +-180 deg is column 0 either way
      // float32 coordinates at up to 120 m resolve the azimuth to ~1e-3 deg (0.01 column).
      ASSERT_NEAR(std::remainder(k - j, static_cast<double>(per_rev)), 0.0, 0.02)
          << "azimuth " << az << " is not a column";
      EXPECT_EQ(dt, std::llround(j * p.resolution_deg / deg_per_us));
    }
  }
}

// Driving straight at 10 m/s towards a wall: with the pose at each return's time every return is
// on the wall; with the pose at the sweep's start the wall seems v * dt nearer for each return.
TEST(SweepTest, StraightMotionSkewsAsARealSweep) {
  const double v = 10.0, t0 = 1.0;
  const Vector2d body0(0.0, 0.0);
  Scene scene = MovingEgo(body0, 0.0, v, 0.0);
  scene.objects.push_back(Wall(1, Vector2d(40.1, -50), Vector2d(40.1, 50)));  // face at x = 40
  const LadarParams p = OneLayer360();
  const Sweep s = Cast(p, scene, t0);
  ASSERT_GT(s.hits[0], 100);
  double max_skew = 0.0;
  for (int i = 0; i < s.scan.npoints; ++i) {
    const double dt = s.scan.dt_us[i] * 1e-6;
    // Analytic ego: straight line, heading 0; the sensor 1.2 m ahead of the body origin.
    const double sensor_x_true = body0.x() + v * (t0 + dt) + 1.2;
    const double sensor_x_start = body0.x() + v * t0 + 1.2;
    const double x_true = sensor_x_true + s.scan.x[i];
    const double x_naive = sensor_x_start + s.scan.x[i];
    EXPECT_NEAR(x_true, 40.0, 1e-3);
    EXPECT_NEAR(x_naive, 40.0 - v * dt, 1e-3);
    max_skew = std::max(max_skew, 40.0 - x_naive);
  }
  EXPECT_GT(max_skew, 0.5);  // the wall ahead is swept half a revolution in, 50+ ms later
}

// Turning at constant steering inside a square room: the analytic circular ego pose at each
// return's time puts every return on a wall face; the sweep-start pose does not (rotation skew).
TEST(SweepTest, TurningMotionSkewsAsARealSweep) {
  const double v = 8.0, steer = DegToRad(15.0), yaw0 = 0.4, t0 = 0.7;
  const Vector2d body0(-5.0, 3.0);
  Scene scene = MovingEgo(body0, yaw0, v, steer);
  scene.objects.push_back(Wall(1, Vector2d(-40.1, -40.1), Vector2d(40.1, -40.1)));
  scene.objects.push_back(Wall(2, Vector2d(40.1, -40.1), Vector2d(40.1, 40.1)));
  scene.objects.push_back(Wall(3, Vector2d(40.1, 40.1), Vector2d(-40.1, 40.1)));
  scene.objects.push_back(Wall(4, Vector2d(-40.1, 40.1), Vector2d(-40.1, -40.1)));
  const LadarParams p = OneLayer360();
  const Sweep s = Cast(p, scene, t0);
  ASSERT_EQ(s.scan.npoints, p.NumColumns());  // the room answers every ray

  // Rear axle on a circle of radius R = wheelbase / tan(steer) about C (left of the start
  // heading), at angular rate omega = v tan(steer) / wheelbase.
  const double R = kWheelbase / std::tan(steer), omega = v * std::tan(steer) / kWheelbase;
  const Vector2d C = body0 + R * Vector2d(-std::sin(yaw0), std::cos(yaw0));
  auto sensor_pose = [&](double t, Vector2d* pos, double* yaw) {
    *yaw = yaw0 + omega * t;
    const Vector2d axle = C + R * Vector2d(std::sin(*yaw), -std::cos(*yaw));
    *pos = axle + 1.2 * Vector2d(std::cos(*yaw), std::sin(*yaw));
  };
  auto wall_distance = [](const Vector2d& q) {  // to the nearest face of the room (|x| or |y| = 40)
    return std::min(std::abs(std::abs(q.x()) - 40.0), std::abs(std::abs(q.y()) - 40.0));
  };
  Vector2d start_pos;
  double start_yaw;
  sensor_pose(t0, &start_pos, &start_yaw);
  double max_naive = 0.0;
  for (int i = 0; i < s.scan.npoints; ++i) {
    const double t = t0 + s.scan.dt_us[i] * 1e-6;
    Vector2d pos;
    double yaw;
    sensor_pose(t, &pos, &yaw);
    const Vector2d q(s.scan.x[i], s.scan.y[i]);
    const Vector2d world = pos + Eigen::Rotation2Dd(yaw) * q;
    EXPECT_LT(wall_distance(world), 1e-3) << "return " << i;
    const Vector2d naive = start_pos + Eigen::Rotation2Dd(start_yaw) * q;
    max_naive = std::max(max_naive, wall_distance(naive));
  }
  EXPECT_GT(max_naive, 1.0);
}

// Objects move during the sweep too: a car crossing at 15 m/s is hit where it is at each
// return's own time.
TEST(SweepTest, TargetsMoveDuringTheSweep) {
  Scene scene = MovingEgo(Vector2d(0, 0), 0.0, 0.0, 0.0);
  SceneObject car;
  car.id = 7;
  car.center = Vector2d(15.0, -4.0);
  car.yaw = DegToRad(90.0);
  car.length = 4.5;
  car.width = 1.8;
  car.height = 1.5;
  const double v = 15.0;
  car.motion = std::make_shared<VehicleMotion>(
      VehicleMotion::Params{SteeringKind::kAckerman, 2.7, -1.35}, car.center, car.yaw,
      PiecewiseLinear({{0.0, v}}), PiecewiseLinear(), 5.0);
  scene.objects.push_back(car);
  const LadarParams p = OneLayer360();
  const double t0 = 0.2;
  const Sweep s = Cast(p, scene, t0);
  ASSERT_GT(s.hits[0], 20);
  // Distance from a point to the car's rectangle at time t (centre moving north at v).
  auto distance_to_car = [&](const Vector2d& q, double t) {
    const Vector2d c = car.center + Vector2d(0.0, v * t);
    const Vector2d d = q - c;  // car frame: length along +y
    const double ex = std::abs(d.y()) - 0.5 * car.length, ey = std::abs(d.x()) - 0.5 * car.width;
    return Vector2d(std::max(ex, 0.0), std::max(ey, 0.0)).norm() + std::min(std::max(ex, ey), 0.0);
  };
  double max_at_start = 0.0;
  for (int i = 0; i < s.scan.npoints; ++i) {
    const Vector2d q = Vector2d(1.2, 0.0) + Vector2d(s.scan.x[i], s.scan.y[i]);
    const double t = t0 + s.scan.dt_us[i] * 1e-6;
    if (distance_to_car(q, t) > 0.5) continue;  // not a car return (nothing else is there)
    EXPECT_NEAR(distance_to_car(q, t), 0.0, 1e-3);
    max_at_start = std::max(max_at_start, std::abs(distance_to_car(q, t0)));
  }
  EXPECT_GT(max_at_start, 0.3);  // at the sweep's start the car was elsewhere
}

}  // namespace
}  // namespace vtrack::sim
