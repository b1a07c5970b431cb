// A small seeded 2-D scene for the tracker's unit tests: rectangles with known motion, a
// rotating single-plane LADAR on a moving ego vehicle (each return at its own time), and the ego
// pose stream. Independent of the project's simulator so that the core is tested on its own.
#pragma once

#include <Eigen/Geometry>

#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "base/angle.h"
#include "base/box.h"
#include "tracker/core/scan.h"

namespace vtrack::testing {

// An object whose box at time t [s] is given by a function.
struct SceneObject {
  int id = 0;
  std::function<OrientedBox(double)> box_at;
};

// Ackermann vehicle: rear axle at L (< 0) from the centre, speed v of the rear axle, constant
// yaw rate w, starting at centre c0 with heading th0.
inline std::function<OrientedBox(double)> AckermannPath(Eigen::Vector2d c0, double th0, double v,
                                                        double w, double L, double length = 4.5,
                                                        double width = 1.8) {
  return [=](double t) {
    const Eigen::Vector2d axle0 = c0 + L * Eigen::Vector2d(std::cos(th0), std::sin(th0));
    Eigen::Vector2d axle;
    const double th = th0 + w * t;
    if (std::abs(w) < 1e-9) {
      axle = axle0 + v * t * Eigen::Vector2d(std::cos(th0), std::sin(th0));
    } else {
      const double r = v / w;
      axle = axle0 + r * Eigen::Vector2d(std::sin(th) - std::sin(th0), -std::cos(th) + std::cos(th0));
    }
    OrientedBox b;
    b.center = axle - L * Eigen::Vector2d(std::cos(th), std::sin(th));
    b.theta = WrapToPi(th);
    b.length = length;
    b.width = width;
    return b;
  };
}

struct SceneConfig {
  double scan_hz = 10.0;
  double angle_step_deg = 0.25;
  double range_noise = 0.02;  // [m] 1-sigma
  double max_range = 60.0;
  double ego_speed = 3.0;     // [m/s] along +x
  double pose_hz = 100.0;
  std::int64_t t0_us = 1'700'000'000'000'000;
};

class SyntheticScene {
 public:
  SyntheticScene(SceneConfig cfg, std::vector<SceneObject> objects, unsigned seed)
      : cfg_(cfg), objects_(std::move(objects)), rng_(seed) {}

  Eigen::Isometry3d EgoAt(double t) const {
    Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
    p.translation() = Eigen::Vector3d(cfg_.ego_speed * t, 0.0, 0.0);
    return p;
  }
  EgoPose PoseAt(double t) const {
    return {cfg_.t0_us + static_cast<std::int64_t>(std::llround(t * 1e6)), EgoAt(t)};
  }
  std::int64_t Utime(double t) const {
    return cfg_.t0_us + static_cast<std::int64_t>(std::llround(t * 1e6));
  }

  // The scan starting at t [s]: one revolution, return k at azimuth k * step at its own time.
  LadarScan ScanAt(double t, std::int64_t seq) {
    LadarScan s;
    s.utime = Utime(t);
    s.seq = seq;
    s.sensor_id = "synthetic";
    s.sweep_duration_us = static_cast<std::int32_t>(1e6 / cfg_.scan_hz);
    s.max_range = static_cast<float>(cfg_.max_range);
    s.num_rings = 1;
    const int n = static_cast<int>(360.0 / cfg_.angle_step_deg);
    std::normal_distribution<double> noise(0.0, cfg_.range_noise);
    for (int k = 0; k < n; ++k) {
      const double frac = static_cast<double>(k) / n;
      const double tk = t + frac / cfg_.scan_hz;
      const Eigen::Isometry3d ego = EgoAt(tk);
      const Eigen::Vector2d o = ego.translation().head<2>();
      const double az = DegToRad(k * cfg_.angle_step_deg) - kPi;
      const Eigen::Vector2d dir_body(std::cos(az), std::sin(az));
      const Eigen::Vector2d dir = ego.linear().topLeftCorner<2, 2>() * dir_body;
      double best = cfg_.max_range;
      for (const auto& obj : objects_) best = std::min(best, RayBox(o, dir, obj.box_at(tk)));
      if (best >= cfg_.max_range) continue;
      const double r = best + noise(rng_);
      s.x.push_back(static_cast<float>(r * dir_body.x()));
      s.y.push_back(static_cast<float>(r * dir_body.y()));
      s.z.push_back(0.0f);
      s.intensity.push_back(0.5f);
      s.dt_us.push_back(static_cast<std::int32_t>(std::llround(frac / cfg_.scan_hz * 1e6)));
      s.ring.push_back(0);
    }
    return s;
  }

  const std::vector<SceneObject>& objects() const { return objects_; }

 private:
  // Distance along the ray to the box boundary (slab method), or +inf.
  static double RayBox(const Eigen::Vector2d& o, const Eigen::Vector2d& d, const OrientedBox& b) {
    const Eigen::Vector2d lo = b.ToBoxFrame(o);
    const Eigen::Vector2d ld(d.dot(b.Axis()), d.dot(b.Normal()));
    const double h[2] = {0.5 * b.length, 0.5 * b.width};
    double tmin = -1e300, tmax = 1e300;
    for (int i = 0; i < 2; ++i) {
      if (std::abs(ld(i)) < 1e-12) {
        if (std::abs(lo(i)) > h[i]) return 1e300;
        continue;
      }
      double t1 = (-h[i] - lo(i)) / ld(i), t2 = (h[i] - lo(i)) / ld(i);
      if (t1 > t2) std::swap(t1, t2);
      tmin = std::max(tmin, t1);
      tmax = std::min(tmax, t2);
    }
    if (tmax < tmin || tmin <= 0.0) return 1e300;
    return tmin;
  }

  SceneConfig cfg_;
  std::vector<SceneObject> objects_;
  std::mt19937 rng_;
};

}  // namespace vtrack::testing
