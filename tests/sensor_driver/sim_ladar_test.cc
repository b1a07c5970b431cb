// The LADAR ray-caster against geometry computed independently here (2-D ray-segment and
// ray-circle intersections, ground-plane ranges), and its error model against Monte Carlo counts.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "sensor_driver/sim/ladar.h"
#include "sensor_driver/sim/scene.h"
#include "base/angle.h"

namespace vtrack::sim {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
constexpr double kInf = std::numeric_limits<double>::infinity();

// A scene with a parked ego whose body origin (rear axle) is at `body` facing `yaw`.
Scene MakeScene(const Vector2d& body, double yaw) {
  Scene s;
  const double wb = 2.8;
  const Vector2d a(std::cos(yaw), std::sin(yaw));
  s.ego.motion = std::make_shared<VehicleMotion>(
      VehicleMotion::Params{SteeringKind::kAckerman, wb, -0.5 * wb}, body + 0.5 * wb * a, yaw,
      PiecewiseLinear(), PiecewiseLinear(), 1.0);
  return s;
}

SceneObject Box(std::int64_t id, const Vector2d& c, double yaw, double length, double width,
                double height) {
  SceneObject o;
  o.id = id;
  o.object_class = ObjectClass::kCar;
  o.shape = Shape::kBox;
  o.center = c;
  o.yaw = yaw;
  o.length = length;
  o.width = width;
  o.height = height;
  return o;
}

SceneObject Cylinder(std::int64_t id, const Vector2d& c, double radius, double height,
                     double penetration = 0.0) {
  SceneObject o;
  o.id = id;
  o.object_class = penetration > 0 ? ObjectClass::kBush : ObjectClass::kPole;
  o.shape = Shape::kCylinder;
  o.center = c;
  o.length = o.width = 2 * radius;
  o.height = height;
  o.penetration = penetration;
  return o;
}

// A single-plane scanner at the body origin, 0.5 m up, level, 180 deg ahead.
LadarParams Planar(double res_deg, double noise) {
  LadarParams p;
  p.name = "test_plane";
  p.rate_hz = 25.0;
  p.azimuth_start_deg = -90.0;
  p.fov_deg = 180.0;
  p.resolution_deg = res_deg;
  p.clockwise = false;
  p.elevations_deg = {0.0};
  p.min_range = 0.3;
  p.max_range = 80.0;
  p.range_noise = noise;
  p.mount_xyz = Vector3d(0.0, 0.0, 0.5);
  return p;
}

// Corners of a box footprint, counter-clockwise from front-left (as base/box.h).
std::array<Vector2d, 4> Corners(const SceneObject& o) {
  const Vector2d a(std::cos(o.yaw), std::sin(o.yaw)), n(-a.y(), a.x());
  const Vector2d l = 0.5 * o.length * a, w = 0.5 * o.width * n;
  return {o.center + l + w, o.center - l + w, o.center - l - w, o.center + l - w};
}

// Range along the ray o + r u to segment [a, b], or +inf.
double RaySegment(const Vector2d& o, const Vector2d& u, const Vector2d& a, const Vector2d& b) {
  const Vector2d e = b - a;
  const double den = u.x() * e.y() - u.y() * e.x();
  if (std::abs(den) < 1e-15) return kInf;
  const Vector2d q = a - o;
  const double r = (q.x() * e.y() - q.y() * e.x()) / den;
  const double s = (q.x() * u.y() - q.y() * u.x()) / den;
  return (r > 0 && s >= 0 && s <= 1) ? r : kInf;
}

double RayCircle(const Vector2d& o, const Vector2d& u, const Vector2d& c, double radius) {
  const Vector2d q = o - c;
  const double b = u.dot(q), disc = b * b - (q.squaredNorm() - radius * radius);
  if (disc < 0) return kInf;
  const double r = -b - std::sqrt(disc);
  return r > 0 ? r : kInf;
}

double PointSegmentDistance(const Vector2d& p, const Vector2d& a, const Vector2d& b) {
  const Vector2d e = b - a;
  const double s = std::clamp((p - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
  return (a + s * e - p).norm();
}

struct Sweep {
  vtrack::ladar_scan_t scan;
  std::vector<int> hits;
};

Sweep Cast(const LadarParams& p, const Scene& scene, std::uint64_t seed, double t0 = 0.0) {
  LadarSimulator sim(p);
  Sweep s;
  sim.Sweep(scene, t0, seed, &s.scan, &s.hits);
  return s;
}

// A box seen from the sensor: every return lies on a face whose outward side faces the sensor
// (Eq. 15's visibility with zero slant), none on the far faces, and each visible face gets
// exactly the rays that geometry sends to it.
TEST(LadarTest, BoxReturnsOnlyOnVisibleFacesWithinNoise) {
  Scene scene = MakeScene(Vector2d(0, 0), 0.0);
  scene.objects.push_back(Box(1, Vector2d(12.0, 3.0), DegToRad(30.0), 4.5, 1.8, 1.5));
  const auto corners = Corners(scene.objects[0]);
  const Vector2d sensor(0, 0);
  // Faces in box.h order: front (c3->c0), left (c0->c1), rear (c1->c2), right (c2->c3).
  const std::array<std::pair<int, int>, 4> faces{{{3, 0}, {0, 1}, {1, 2}, {2, 3}}};
  auto visible = [&](int f) {
    const Vector2d a = corners[faces[f].first], b = corners[faces[f].second];
    const Vector2d e = b - a, outward(e.y(), -e.x());  // corners run ccw: right of a->b is out
    return outward.dot(sensor - 0.5 * (a + b)) > 0;
  };
  int n_visible = 0;
  for (int f = 0; f < 4; ++f) n_visible += visible(f);
  ASSERT_EQ(n_visible, 2);  // a corner view
  // The face a ray from the sensor along u hits first, and the range there (-1 and kInf if none).
  auto first_hit = [&](const Vector2d& u) {
    double best = kInf;
    int face = -1;
    for (int f = 0; f < 4; ++f) {
      const double r = RaySegment(sensor, u, corners[faces[f].first], corners[faces[f].second]);
      if (r < best) best = r, face = f;
    }
    return std::make_pair(face, best);
  };

  // Expected rays per face, noise-free, from the ray-segment intersections.
  const LadarParams clean = Planar(0.25, 0.0);
  std::array<int, 4> expected{0, 0, 0, 0};
  for (int j = 0; j < clean.NumColumns(); ++j) {
    const double az = DegToRad(-90.0 + j * 0.25);
    const int face = first_hit(Vector2d(std::cos(az), std::sin(az))).first;
    if (face >= 0) ++expected[face];
  }
  const Sweep s0 = Cast(clean, scene, 1);
  std::array<int, 4> got{0, 0, 0, 0};
  for (int i = 0; i < s0.scan.npoints; ++i) {
    const Vector2d p(s0.scan.x[i], s0.scan.y[i]);
    int nearest = 0;
    double dmin = kInf;
    for (int f = 0; f < 4; ++f) {
      const double d = PointSegmentDistance(p, corners[faces[f].first], corners[faces[f].second]);
      if (d < dmin) dmin = d, nearest = f;
    }
    EXPECT_LT(dmin, 1e-4);
    ++got[nearest];
  }
  EXPECT_EQ(got, expected);
  EXPECT_EQ(s0.hits[0], s0.scan.npoints);
  for (int f = 0; f < 4; ++f) {
    if (!visible(f)) {
      EXPECT_EQ(got[f], 0) << "face " << f;
    }
  }

  // With noise: still only on visible faces, within 5 sigma, residuals ~ N(0, sigma^2), pooled
  // over seeds.
  const double sigma = 0.03;
  const LadarParams noisy = Planar(0.25, sigma);
  double sum = 0, sum2 = 0;
  int n = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const Sweep s = Cast(noisy, scene, seed);
    for (int i = 0; i < s.scan.npoints; ++i) {
      const Vector2d p(s.scan.x[i], s.scan.y[i]);
      const double az = std::atan2(p.y(), p.x());
      const auto [face, best] = first_hit(Vector2d(std::cos(az), std::sin(az)));
      ASSERT_GE(face, 0) << "a return where no face is";
      EXPECT_TRUE(visible(face));
      const double res = p.norm() - best;
      EXPECT_LT(std::abs(res), 5 * sigma);
      sum += res;
      sum2 += res * res;
      ++n;
    }
  }
  ASSERT_GT(n, 1000);
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_LT(std::abs(mean), 4 * sigma / std::sqrt(n));
  EXPECT_NEAR(sd, sigma, 0.1 * sigma);
}

// A pole in front of the box: in its shadow the rays stop on the pole; every return is at the
// first surface that the geometry here says the ray meets, and the per-object counts agree.
TEST(LadarTest, NearerObjectOccludes) {
  Scene scene = MakeScene(Vector2d(0, 0), 0.0);
  scene.objects.push_back(Box(1, Vector2d(15.0, 2.0), 0.0, 4.5, 1.8, 1.5));
  scene.objects.push_back(Cylinder(2, Vector2d(6.0, 1.4), 0.3, 3.0));
  const auto corners = Corners(scene.objects[0]);
  const Vector2d sensor(0, 0);
  const LadarParams p = Planar(0.1, 0.0);
  const Sweep s = Cast(p, scene, 3);
  std::array<int, 3> expected{0, 0, 0};  // box, pole, nothing
  int shadowed = 0;
  for (int j = 0; j < p.NumColumns(); ++j) {
    const double az = DegToRad(-90.0 + j * 0.1);
    const Vector2d u(std::cos(az), std::sin(az));
    double box = kInf;
    for (int f = 0; f < 4; ++f) box = std::min(box, RaySegment(sensor, u, corners[f], corners[(f + 1) % 4]));
    const double pole = RayCircle(sensor, u, Vector2d(6.0, 1.4), 0.3);
    if (pole < kInf && box < kInf) ++shadowed;
    ++expected[pole < box ? 1 : (box < kInf ? 0 : 2)];
  }
  ASSERT_GT(shadowed, 5);  // the pole does hide part of the box
  EXPECT_EQ(s.hits[0], expected[0]);
  EXPECT_EQ(s.hits[1], expected[1]);
  EXPECT_EQ(s.scan.npoints, expected[0] + expected[1]);
  for (int i = 0; i < s.scan.npoints; ++i) {
    const Vector2d q(s.scan.x[i], s.scan.y[i]);
    const Vector2d u = q.normalized();
    double first = RayCircle(sensor, u, Vector2d(6.0, 1.4), 0.3);
    for (int f = 0; f < 4; ++f) first = std::min(first, RaySegment(sensor, u, corners[f], corners[(f + 1) % 4]));
    EXPECT_NEAR(q.norm(), first, 1e-4);
  }
}

// A multi-layer sensor over empty ground: returns from the downward layers only, each on z = 0 at
// range h / sin(-elevation), tagged with its layer; none beyond max_range.
TEST(LadarTest, GroundReturnsPerLayer) {
  LadarParams p;
  p.name = "test_multi";
  p.fov_deg = 360.0;
  p.resolution_deg = 1.0;
  p.elevations_deg.clear();
  for (int i = 0; i < 16; ++i) p.elevations_deg.push_back(-15.0 + 2.0 * i);  // -15 .. +15
  p.min_range = 1.0;
  p.max_range = 30.0;
  p.range_noise = 0.0;
  p.mount_xyz = Vector3d(0.0, 0.0, 1.73);
  const Scene scene = MakeScene(Vector2d(5, -3), 0.6);
  const Sweep s = Cast(p, scene, 5);
  int expected_layers = 0;
  for (double e : p.elevations_deg) {
    if (e < 0 && 1.73 / std::sin(DegToRad(-e)) <= p.max_range) ++expected_layers;
  }
  EXPECT_EQ(s.scan.npoints, expected_layers * p.NumColumns());
  EXPECT_EQ(s.scan.num_rings, 16);
  for (int i = 0; i < s.scan.npoints; ++i) {
    const double e = p.elevations_deg.at(s.scan.ring[i]);
    EXPECT_LT(e, 0.0);
    EXPECT_NEAR(s.scan.z[i], -1.73, 1e-5);
    const double range = std::sqrt(s.scan.x[i] * s.scan.x[i] + s.scan.y[i] * s.scan.y[i] +
                                   s.scan.z[i] * s.scan.z[i]);
    EXPECT_NEAR(range, 1.73 / std::sin(DegToRad(-e)), 1e-4);
    EXPECT_LE(range, p.max_range);
  }
}

// Rays see the top of a low box from above, and pass over an object lower than a level
// single-plane scanner.
TEST(LadarTest, RoofsAndHeights) {
  LadarParams p;
  p.name = "test_multi";
  p.resolution_deg = 0.5;
  p.elevations_deg = {-30.0, -20.0, -10.0, -5.0};
  p.range_noise = 0.0;
  p.mount_xyz = Vector3d(0.0, 0.0, 2.0);
  Scene scene = MakeScene(Vector2d(0, 0), 0.0);
  scene.objects.push_back(Box(1, Vector2d(3.5, 0.0), 0.0, 2.0, 4.0, 1.0));  // x 2.5..4.5
  const Sweep s = Cast(p, scene, 7);
  int roof = 0, side = 0;
  for (int i = 0; i < s.scan.npoints; ++i) {
    const double x = s.scan.x[i], y = s.scan.y[i], z = s.scan.z[i] + 2.0;
    if (x > 2.4 && x < 4.6 && std::abs(y) < 2.1 && z > 1e-3) {
      EXPECT_LE(z, 1.0 + 1e-4);
      // On the roof (z = 1) or on the near face (x = 2.5).
      const bool on_roof = std::abs(z - 1.0) < 1e-4, on_face = std::abs(x - 2.5) < 1e-4;
      EXPECT_TRUE(on_roof || on_face) << x << " " << y << " " << z;
      roof += on_roof;
      side += on_face && !on_roof;
    }
  }
  EXPECT_GT(roof, 10);
  EXPECT_GT(side, 10);

  // A 0.3 m high kerb-stone box in front of a level scanner 0.5 m up is never hit.
  Scene low = MakeScene(Vector2d(0, 0), 0.0);
  low.objects.push_back(Box(1, Vector2d(5.0, 0.0), 0.0, 1.0, 6.0, 0.3));
  const Sweep s2 = Cast(Planar(0.5, 0.0), low, 1);
  EXPECT_EQ(s2.hits[0], 0);
  EXPECT_EQ(s2.scan.npoints, 0);
}

// A single-plane scanner pitched 10 deg down, 1 m up, sees the ground at the range its tilted
// ray geometry gives; the message's mounting pose maps every return onto z = 0.
TEST(LadarTest, TiltedMountHitsGroundWhereGeometrySays) {
  LadarParams p = Planar(1.0, 0.0);
  p.mount_xyz = Vector3d(2.0, 0.5, 1.0);
  p.mount_pitch_deg = 10.0;  // nose down
  p.mount_yaw_deg = 5.0;
  p.max_range = 50.0;
  const double yaw = 0.8;
  const Scene scene = MakeScene(Vector2d(3, 4), yaw);
  const Sweep s = Cast(p, scene, 2);
  ASSERT_GT(s.scan.npoints, 100);
  const Eigen::Quaterniond q(s.scan.sensor_orientation[0], s.scan.sensor_orientation[1],
                             s.scan.sensor_orientation[2], s.scan.sensor_orientation[3]);
  const Vector3d t(s.scan.sensor_pos[0], s.scan.sensor_pos[1], s.scan.sensor_pos[2]);
  const Eigen::Matrix3d world_from_body = Eigen::AngleAxisd(yaw, Vector3d::UnitZ()).toRotationMatrix();
  for (int i = 0; i < s.scan.npoints; ++i) {
    const Vector3d ps(s.scan.x[i], s.scan.y[i], s.scan.z[i]);
    const Vector3d pw = world_from_body * (q * ps + t) + Vector3d(3, 4, 0);
    EXPECT_NEAR(pw.z(), 0.0, 1e-4);
    // Sensor-frame direction (cos az, sin az, 0) pitched down: d_z = -sin(10 deg) cos(az), so the
    // ground is at range 1 / (sin(10 deg) cos(az)).
    const double az = std::atan2(ps.y(), ps.x());
    EXPECT_NEAR(ps.norm(), 1.0 / (std::sin(DegToRad(10.0)) * std::cos(az)), 1e-4);
    EXPECT_NEAR(ps.z(), 0.0, 1e-5);
  }
}

// Error model: dropouts and spurious returns at their configured rates (binomial bounds), and
// spurious returns always in front of the surface.
TEST(LadarTest, DropoutAndSpuriousRates) {
  Scene scene = MakeScene(Vector2d(0, 0), 0.0);
  scene.objects.push_back(Box(1, Vector2d(20.0, 0.0), 0.0, 1.0, 200.0, 3.0));  // wall across
  LadarParams p = Planar(0.5, 0.0);
  // Rays that reach the wall's face x = 19.5 within max_range and its half-length 100 m.
  int rays = 0;
  for (int j = 0; j < p.NumColumns(); ++j) {
    const double az = DegToRad(-90.0 + 0.5 * j);
    if (std::cos(az) > 1e-9 && 19.5 / std::cos(az) <= p.max_range &&
        std::abs(19.5 * std::tan(az)) <= 100.0) {
      ++rays;
    }
  }
  ASSERT_EQ(Cast(p, scene, 1).scan.npoints, rays);
  const int seeds = 50;
  const double n = static_cast<double>(rays) * seeds;

  p.dropout = 0.3;
  double kept = 0;
  for (int seed = 1; seed <= seeds; ++seed) kept += Cast(p, scene, seed).scan.npoints;
  EXPECT_NEAR(kept / n, 0.7, 5 * std::sqrt(0.3 * 0.7 / n));

  p.dropout = 0.0;
  p.spurious = 0.1;
  double early = 0, wall = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    const Sweep s = Cast(p, scene, seed);
    int on_wall = 0;
    for (int i = 0; i < s.scan.npoints; ++i) {
      const double x = s.scan.x[i];
      EXPECT_GE(std::hypot(s.scan.x[i], s.scan.y[i]), p.min_range - 1e-4);
      if (x < 19.5 - 1e-4) {
        ++early;  // spurious: in front of the wall (or, on rays that miss it, within max_range)
      } else {
        EXPECT_NEAR(x, 19.5, 1e-4);
        ++on_wall;
      }
    }
    EXPECT_EQ(s.hits[0], on_wall);  // spurious returns are not counted on the object
    wall += on_wall;
  }
  // Every ray may return spuriously, including those that miss the wall.
  const double all_rays = static_cast<double>(p.NumColumns()) * seeds;
  EXPECT_NEAR(early / all_rays, 0.1, 5 * std::sqrt(0.1 * 0.9 / all_rays));
  EXPECT_NEAR(wall / n, 0.9, 5 * std::sqrt(0.1 * 0.9 / n));
}

// A bush lets rays in: returns lie inside its footprint, about `penetration` past the entry.
TEST(LadarTest, BushPenetration) {
  Scene scene = MakeScene(Vector2d(0, 0), 0.0);
  scene.objects.push_back(Cylinder(1, Vector2d(8.0, 0.0), 1.5, 2.0, 0.3));
  LadarParams p = Planar(0.1, 0.0);
  double depth = 0;
  int n = 0;
  for (int seed = 1; seed <= 20; ++seed) {
    const Sweep s = Cast(p, scene, seed);
    for (int i = 0; i < s.scan.npoints; ++i) {
      const Vector2d q(s.scan.x[i], s.scan.y[i]);
      EXPECT_LE((q - Vector2d(8.0, 0.0)).norm(), 1.5 + 1e-4);
      const double entry = RayCircle(Vector2d(0, 0), q.normalized(), Vector2d(8.0, 0.0), 1.5);
      depth += q.norm() - entry;
      ++n;
    }
  }
  ASSERT_GT(n, 500);
  EXPECT_NEAR(depth / n, 0.3, 0.05);  // exponential mean 0.3 m, slightly truncated at the exit
}

TEST(LadarTest, SameSeedSameSweepOtherSeedDiffers) {
  Scene scene = MakeScene(Vector2d(0, 0), 0.0);
  scene.objects.push_back(Box(1, Vector2d(10.0, 1.0), 0.4, 4.5, 1.8, 1.5));
  LadarParams p = Planar(0.25, 0.05);
  p.dropout = 0.1;
  p.spurious = 0.05;
  const Sweep a = Cast(p, scene, 42), b = Cast(p, scene, 42), c = Cast(p, scene, 43);
  EXPECT_EQ(a.scan.x, b.scan.x);
  EXPECT_EQ(a.scan.y, b.scan.y);
  EXPECT_EQ(a.scan.dt_us, b.scan.dt_us);
  EXPECT_EQ(a.hits, b.hits);
  EXPECT_NE(a.scan.x, c.scan.x);
}

TEST(LadarTest, ValidationNamesTheKey) {
  auto error = [](auto mutate) {
    LadarParams p;
    mutate(&p);
    return p.Validate();
  };
  EXPECT_EQ(error([](LadarParams*) {}), "");
  EXPECT_NE(error([](LadarParams* p) { p->rate_hz = 0; }).find("rate_hz = 0"), std::string::npos);
  EXPECT_NE(error([](LadarParams* p) { p->elevations_deg = {1.0, 0.5}; }).find("elevations_deg[1]"),
            std::string::npos);
  EXPECT_NE(error([](LadarParams* p) { p->mount_xyz.z() = -1; }).find("mount.z"), std::string::npos);
  EXPECT_NE(error([](LadarParams* p) { p->dropout = 1.0; }).find("dropout"), std::string::npos);
  EXPECT_NE(error([](LadarParams* p) { p->max_range = std::nan(""); }).find("max_range"),
            std::string::npos);
  EXPECT_NE(error([](LadarParams* p) { p->resolution_deg = 0.001; }).find("resolution_deg"),
            std::string::npos);
  LadarParams bad;
  bad.fov_deg = 400;
  EXPECT_THROW(LadarSimulator{bad}, std::invalid_argument);
  for (const auto& name : LadarPresetNames()) {
    LadarParams p;
    ASSERT_TRUE(LadarPreset(name, &p));
    EXPECT_EQ(p.Validate(), "") << name;
  }
  LadarParams v;
  ASSERT_TRUE(LadarPreset("velodyne64", &v));
  EXPECT_EQ(v.NumLayers(), 64);
  EXPECT_EQ(v.NumColumns(), 2048);
  EXPECT_FALSE(LadarPreset("no_such_sensor", &v));
}

}  // namespace
}  // namespace vtrack::sim
