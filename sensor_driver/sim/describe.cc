#include "sensor_driver/sim/describe.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>

#include <Eigen/Geometry>

#include "base/angle.h"
#include "lcmtypes/util/text.h"

namespace vtrack::sim {
namespace {

using lcm_util::Format;

struct PathSummary {
  MotionState start, end;
  double turned = 0.0;  // [rad] total heading change, signed
  double min_speed = 0.0, max_speed = 0.0;
  double distance = 0.0;  // [m] travelled by the rotation axis
  Eigen::AlignedBox2d box;  // [m] region swept by the centre
};

PathSummary Summarise(const VehicleMotion& m, double duration) {
  PathSummary s;
  s.start = m.At(0.0);
  MotionState prev = s.start;
  s.min_speed = s.max_speed = prev.speed;
  s.box.extend(prev.center);
  constexpr double kStep = 0.05;
  for (double t = kStep; t <= duration + 1e-9; t += kStep) {
    const MotionState cur = m.At(t);
    s.turned += AngleDiff(cur.yaw, prev.yaw);
    s.distance += (cur.axis_point - prev.axis_point).norm();
    s.min_speed = std::min(s.min_speed, cur.speed);
    s.max_speed = std::max(s.max_speed, cur.speed);
    s.box.extend(cur.center);
    prev = cur;
  }
  s.end = m.At(duration);
  return s;
}

struct Footprint {
  Eigen::Vector2d c;
  double yaw, half_l, half_w, radius;
  int index;  // into scene.objects; -1 for the ego
};

// Separating-axis test of two rectangles; returns the smallest overlap along the four axes
// (<= 0: separated).
double OverlapDepth(const Footprint& p, const Footprint& q) {
  double depth = 1e9;
  for (const Footprint* f : {&p, &q}) {
    for (int k = 0; k < 2; ++k) {
      const double ang = f->yaw + k * 0.5 * kPi;
      const Eigen::Vector2d axis(std::cos(ang), std::sin(ang));
      auto extent = [&](const Footprint& g) {
        const double ca = std::abs(std::cos(g.yaw - ang)), sa = std::abs(std::sin(g.yaw - ang));
        return g.half_l * ca + g.half_w * sa;
      };
      const double d = std::abs(axis.dot(q.c - p.c));
      depth = std::min(depth, extent(p) + extent(q) - d);
    }
  }
  return depth;
}

}  // namespace

std::vector<Overlap> FindOverlaps(const Scenario& sc, double step, double tolerance) {
  std::vector<Overlap> found;
  std::set<std::pair<int, int>> seen;
  const Scene& scene = sc.scene;
  auto name = [&](int i) {
    if (i < 0) return std::string("ego");
    const SceneObject& o = scene.objects[i];
    return Format("%s %lld", ObjectClassName(o.object_class), static_cast<long long>(o.id));
  };
  std::vector<Footprint> all(scene.objects.size());
  std::vector<int> movers;
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    if (scene.objects[i].moving()) movers.push_back(static_cast<int>(i));
  }
  for (double t = 0.0; t <= sc.duration + 1e-9; t += step) {
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
      const SceneObject& o = scene.objects[i];
      if (t > 0.0 && !o.moving()) continue;  // static footprints are computed once
      const ObjectState s = scene.StateOf(o, t);
      all[i] = {s.center, s.yaw, 0.5 * o.length, 0.5 * o.width, o.BoundingRadius(), static_cast<int>(i)};
    }
    const MotionState e = scene.EgoAt(t);
    const Footprint ego{e.center, e.yaw, 0.5 * scene.ego.length, 0.5 * scene.ego.width,
                        0.5 * std::hypot(scene.ego.length, scene.ego.width), -1};
    auto check = [&](const Footprint& m) {
      for (const Footprint& f : all) {
        if (f.index == m.index || (m.c - f.c).norm() > m.radius + f.radius) continue;
        const double depth = OverlapDepth(m, f);
        if (depth <= tolerance) continue;
        const auto key = std::minmax(m.index, f.index);
        if (seen.insert(key).second) found.push_back({t, name(key.first), name(key.second), depth});
      }
    };
    for (int i : movers) check(all[i]);
    check(ego);
  }
  return found;
}

void Describe(const Simulator& sim, std::ostream& out) {
  const Scenario& sc = sim.scenario();
  const LadarParams& p = sim.sensor();
  out << "scenario " << sc.name << " (" << sc.path << ")\n";
  if (!sc.description.empty()) out << "  " << sc.description << "\n";
  out << Format("  duration %.2f s, seed %llu, start_utime %lld\n", sc.duration,
                static_cast<unsigned long long>(sim.seed()),
                static_cast<long long>(sc.start_utime));
  out << Format("  sensor %s: %d layers x %d columns, %.1f Hz, fov %.0f deg, max range %.0f m, "
                "noise %.3f m, dropout %.3f, spurious %.3f; mounted at (%.2f, %.2f, %.2f)\n",
                p.name.c_str(), p.NumLayers(), p.NumColumns(), p.rate_hz, p.fov_deg, p.max_range,
                p.range_noise, p.dropout, p.spurious, p.mount_xyz.x(), p.mount_xyz.y(),
                p.mount_xyz.z());
  out << Format("  %d scans, %d poses at %.0f Hz (noise %.3f m, %.3f deg)\n", sim.NumScans(),
                sim.NumPoses(), sim.pose_rate_hz(), sim.pose_noise().position,
                sim.pose_noise().yaw_deg);
  std::map<std::string, int> count, moving;
  for (const auto& o : sc.scene.objects) {
    ++count[ObjectClassName(o.object_class)];
    if (o.moving()) ++moving[ObjectClassName(o.object_class)];
  }
  out << "  objects:";
  for (const auto& [k, v] : count) out << " " << v << " " << k << " (" << moving[k] << " moving);";
  out << "\n";
  auto path = [&](const char* who, const VehicleMotion& m, bool body_origin) {
    PathSummary s = Summarise(m, sc.duration);
    if (body_origin) {
      s.start.center = s.start.axis_point;
      s.end.center = s.end.axis_point;
    }
    out << Format("  %-12s start (%7.2f, %7.2f) %7.1f deg -> end (%7.2f, %7.2f) %7.1f deg; "
                  "turned %+7.1f deg over %6.1f m; speed %.1f..%.1f m/s; centre within "
                  "x [%.1f, %.1f] y [%.1f, %.1f]\n",
                  who, s.start.center.x(), s.start.center.y(), RadToDeg(s.start.yaw),
                  s.end.center.x(), s.end.center.y(), RadToDeg(s.end.yaw), RadToDeg(s.turned),
                  s.distance, s.min_speed, s.max_speed, s.box.min().x(), s.box.max().x(),
                  s.box.min().y(), s.box.max().y());
  };
  out << "  paths (box centre; the ego's is its body origin, the rear axle):\n";
  path("ego", *sc.scene.ego.motion, true);
  for (const auto& o : sc.scene.objects) {
    if (!o.moving()) continue;
    const std::string who =
        Format("%s %lld", ObjectClassName(o.object_class), static_cast<long long>(o.id));
    path(who.c_str(), *o.motion, false);
  }
  const auto overlaps = FindOverlaps(sc);
  for (const auto& ov : overlaps) {
    out << Format("  WARNING: %s and %s overlap (%.2f m) at t = %.1f s\n", ov.a.c_str(),
                  ov.b.c_str(), ov.depth, ov.t);
  }
  if (overlaps.empty()) out << "  no overlapping footprints (checked every 0.1 s)\n";
}

}  // namespace vtrack::sim
