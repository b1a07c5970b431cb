#include "sensor_driver/sim/scenario.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <set>
#include <sstream>

#include "base/angle.h"

#ifndef VTRACK_SOURCE_DIR
#define VTRACK_SOURCE_DIR ""
#endif

namespace vtrack::sim {
namespace {

namespace fs = std::filesystem;

struct Doc {
  std::string file;
  YAML::Node root;
};

std::string Fmt(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

// Levenshtein distance, for "did you mean" on unknown keys.
int EditDistance(const std::string& a, const std::string& b) {
  std::vector<int> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = static_cast<int>(j);
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = static_cast<int>(i);
    for (std::size_t j = 1; j <= b.size(); ++j) {
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

bool ContainsNode(const YAML::Node& tree, const YAML::Node& x) {
  if (tree.is(x)) return true;
  if (tree.IsMap()) {
    for (const auto& kv : tree) {
      if (ContainsNode(kv.first, x) || ContainsNode(kv.second, x)) return true;
    }
  } else if (tree.IsSequence()) {
    for (const auto& e : tree) {
      if (ContainsNode(e, x)) return true;
    }
  }
  return false;
}

// Reads values out of the (merged) YAML tree and reports every problem with file:line:col and
// the key path.
class Reader {
 public:
  explicit Reader(const std::vector<Doc>* docs) : docs_(docs) {}

  [[noreturn]] void Fail(const YAML::Node& node, const std::string& path,
                         const std::string& msg) const {
    throw ScenarioError(Where(node) + ": " + path + ": " + msg);
  }

  std::string Where(const YAML::Node& node) const {
    std::string file = docs_->front().file;
    for (const Doc& d : *docs_) {
      if (node.IsDefined() && ContainsNode(d.root, node)) {
        file = d.file;
        break;
      }
    }
    const YAML::Mark m = node.IsDefined() ? node.Mark() : YAML::Mark::null_mark();
    if (m.is_null()) return file;
    return file + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1);
  }

  void ExpectMap(const YAML::Node& n, const std::string& path) const {
    if (!n.IsMap()) Fail(n, path, "expected a map of keys (key: value)");
  }
  void ExpectSeq(const YAML::Node& n, const std::string& path) const {
    if (!n.IsSequence()) Fail(n, path, "expected a list (- item)");
  }

  // Refuses keys not in allowed, and repeated keys.
  void CheckKeys(const YAML::Node& map, const std::string& path,
                 const std::vector<std::string>& allowed) const {
    ExpectMap(map, path);
    std::set<std::string> seen;
    for (const auto& kv : map) {
      if (!kv.first.IsScalar()) Fail(kv.first, path, "keys must be plain names");
      const std::string key = kv.first.Scalar();
      const std::string at = path.empty() ? key : path + "." + key;
      if (!seen.insert(key).second) Fail(kv.first, at, "key given twice");
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
        std::string hint;
        int best = 3;
        for (const auto& a : allowed) {
          const int d = EditDistance(key, a);
          if (d < best) {
            best = d;
            hint = " (did you mean '" + a + "'?)";
          }
        }
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        Fail(kv.first, at, "unknown key" + hint + "; allowed here: " + list);
      }
    }
  }

  static bool Has(const YAML::Node& map, const char* key) { return map[key].IsDefined(); }

  // True if n (map's value at path at) is defined; false if not and the caller has a default;
  // refuses a missing key without a default.
  bool Given(const YAML::Node& map, const YAML::Node& n, const std::string& at,
             bool has_default) const {
    if (n.IsDefined()) return true;
    if (!has_default) Fail(map, at, "required key is missing");
    return false;
  }

  static std::string Join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }

  // A number in [lo, hi] (open ends if lo_open/hi_open); def if absent, required if !def.
  double Num(const YAML::Node& map, const std::string& path, const char* key,
             std::optional<double> def, double lo, double hi, bool lo_open = false,
             bool hi_open = false) const {
    const YAML::Node n = map[key];
    const std::string at = Join(path, key);
    if (!Given(map, n, at, def.has_value())) return *def;
    const double v = ScalarNumber(n, at);
    const bool ok = (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
    if (!ok) {
      Fail(n, at + " = " + Fmt(v),
           std::string("must be in ") + (lo_open ? "(" : "[") + Fmt(lo) + ", " + Fmt(hi) +
               (hi_open ? ")" : "]"));
    }
    return v;
  }

  double ScalarNumber(const YAML::Node& n, const std::string& at) const {
    if (!n.IsScalar()) Fail(n, at, "expected a number");
    double v;
    try {
      v = n.as<double>();
    } catch (const YAML::Exception&) {
      Fail(n, at, "expected a number, got '" + n.Scalar() + "'");
    }
    if (!std::isfinite(v)) Fail(n, at, "expected a finite number, got '" + n.Scalar() + "'");
    return v;
  }

  std::int64_t Int(const YAML::Node& map, const std::string& path, const char* key,
                   std::optional<std::int64_t> def, std::int64_t lo, std::int64_t hi) const {
    const YAML::Node n = map[key];
    const std::string at = Join(path, key);
    if (!Given(map, n, at, def.has_value())) return *def;
    if (!n.IsScalar()) Fail(n, at, "expected an integer");
    std::int64_t v;
    try {
      v = n.as<std::int64_t>();
    } catch (const YAML::Exception&) {
      Fail(n, at, "expected an integer, got '" + n.Scalar() + "'");
    }
    if (v < lo || v > hi) {
      Fail(n, at + " = " + std::to_string(v),
           "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
    return v;
  }

  bool Bool(const YAML::Node& map, const std::string& path, const char* key, bool def) const {
    const YAML::Node n = map[key];
    if (!n.IsDefined()) return def;
    try {
      if (n.IsScalar()) return n.as<bool>();
    } catch (const YAML::Exception&) {
    }
    Fail(n, Join(path, key), "expected true or false, got '" + (n.IsScalar() ? n.Scalar() : "") + "'");
  }

  std::string Str(const YAML::Node& map, const std::string& path, const char* key,
                  std::optional<std::string> def) const {
    const YAML::Node n = map[key];
    const std::string at = Join(path, key);
    if (!Given(map, n, at, def.has_value())) return *def;
    if (!n.IsScalar()) Fail(n, at, "expected a string");
    return n.Scalar();
  }

  // One of choices.
  std::string Choice(const YAML::Node& map, const std::string& path, const char* key,
                     std::optional<std::string> def,
                     const std::vector<std::string>& choices) const {
    const std::string v = Str(map, path, key, def);
    if (std::find(choices.begin(), choices.end(), v) == choices.end()) {
      std::string list;
      for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
      Fail(map[key].IsDefined() ? map[key] : map, Join(path, key) + " = " + v,
           "must be one of: " + list);
    }
    return v;
  }

  // [x, y] as a two-element list.
  Eigen::Vector2d Point(const YAML::Node& map, const std::string& path, const char* key) const {
    const YAML::Node n = map[key];
    const std::string at = Join(path, key);
    if (!n.IsDefined()) Fail(map, at, "required key is missing");
    if (!n.IsSequence() || n.size() != 2) Fail(n, at, "expected [x, y]");
    const double x = ScalarNumber(n[0], at + "[0]"), y = ScalarNumber(n[1], at + "[1]");
    if (std::abs(x) > 1e5 || std::abs(y) > 1e5) Fail(n, at, "coordinates must be within 1e5 m");
    return {x, y};
  }

 private:
  const std::vector<Doc>* docs_;
};

constexpr double kCoord = 1e5;  // [m] bound on coordinates

// Per-class defaults: dimensions [m], wheelbase [m], rotation axis offset L [m], reflectance.
struct ClassDefaults {
  double length, width, height, wheelbase, axis, reflectance;
};
ClassDefaults DefaultsFor(ObjectClass c) {
  switch (c) {
    case ObjectClass::kCar: return {4.5, 1.8, 1.5, 2.7, -1.35, 0.5};
    case ObjectClass::kVan: return {5.0, 2.0, 2.1, 3.0, -1.5, 0.5};
    case ObjectClass::kTruck: return {8.0, 2.5, 3.2, 5.0, -2.0, 0.45};
    case ObjectClass::kSkidSteer: return {2.6, 1.6, 1.3, 0.0, 0.0, 0.4};
    case ObjectClass::kWall: return {0.0, 0.3, 3.0, 0.0, 0.0, 0.35};
    case ObjectClass::kPole: return {0.3, 0.3, 4.0, 0.0, 0.0, 0.6};
    case ObjectClass::kBush: return {1.6, 1.6, 1.2, 0.0, 0.0, 0.25};
  }
  return {4.5, 1.8, 1.5, 2.7, -1.35, 0.5};
}

ObjectClass VehicleClassFrom(const std::string& s) {
  if (s == "van") return ObjectClass::kVan;
  if (s == "truck") return ObjectClass::kTruck;
  if (s == "skid_steer") return ObjectClass::kSkidSteer;
  return ObjectClass::kCar;
}
const std::vector<std::string> kVehicleClasses = {"car", "van", "truck", "skid_steer"};

class Builder {
 public:
  Builder(const std::vector<Doc>* docs, const YAML::Node& root, double duration)
      : r_(docs), root_(root), duration_(duration) {}

  void Sensors(Scenario* sc) {
    const YAML::Node sensors = root_["sensors"];
    if (sensors.IsDefined()) {
      r_.ExpectMap(sensors, "sensors");
      for (const auto& kv : sensors) {
        const std::string name = kv.first.Scalar();
        sc->sensors[name] = Sensor(kv.second, "sensors." + name, name);
      }
    }
    sc->default_sensor = r_.Str(root_, "", "sensor", std::nullopt);
    LadarParams unused;
    if (!sc->sensors.count(sc->default_sensor) && !LadarPreset(sc->default_sensor, &unused)) {
      r_.Fail(root_["sensor"], "sensor = " + sc->default_sensor,
              "is neither a key of `sensors` nor a built-in preset (" + PresetList() + ")");
    }
  }

  void Truth(Scenario* sc) {
    const YAML::Node t = root_["truth"];
    if (!t.IsDefined()) return;
    r_.CheckKeys(t, "truth", {"labelled_radius", "min_points"});
    sc->truth.labelled_radius = r_.Num(t, "truth", "labelled_radius", 50.0, 0.0, 1000.0, true);
    sc->truth.min_points = static_cast<int>(r_.Int(t, "truth", "min_points", 3, 0, 100000));
  }

  void Ego(Scenario* sc) {
    const YAML::Node e = root_["ego"];
    if (!e.IsDefined()) r_.Fail(root_, "ego", "required key is missing");
    const std::string p = "ego";
    r_.CheckKeys(e, p, {"start", "wheelbase", "length", "width", "profile", "pose_rate_hz",
                        "pose_noise"});
    const double wheelbase = r_.Num(e, p, "wheelbase", 2.8, 0.5, 20.0);
    sc->scene.ego.length = r_.Num(e, p, "length", 4.6, 0.5, 30.0);
    sc->scene.ego.width = r_.Num(e, p, "width", 1.9, 0.3, 5.0);
    double yaw;
    const Eigen::Vector2d body = Pose(e, p, "start", &yaw);
    // The body origin is the rear axle (the rotation axis); place the centre half a wheelbase ahead.
    VehicleMotion::Params mp{SteeringKind::kAckerman, wheelbase, -0.5 * wheelbase};
    const Eigen::Vector2d a(std::cos(yaw), std::sin(yaw));
    PiecewiseLinear speed, turn;
    Profile(e, p, SteeringKind::kAckerman, &speed, &turn);
    sc->scene.ego.motion = MakeMotion(e, p, mp, body + 0.5 * wheelbase * a, yaw, speed, turn);
    sc->pose_rate_hz = r_.Num(e, p, "pose_rate_hz", 100.0, 1.0, 1000.0);
    const YAML::Node n = e["pose_noise"];
    if (n.IsDefined()) {
      const std::string q = p + ".pose_noise";
      r_.CheckKeys(n, q, {"position", "yaw_deg", "correlation_time"});
      sc->pose_noise.position = r_.Num(n, q, "position", 0.0, 0.0, 10.0);
      sc->pose_noise.yaw_deg = r_.Num(n, q, "yaw_deg", 0.0, 0.0, 45.0);
      sc->pose_noise.correlation_time = r_.Num(n, q, "correlation_time", 2.0, 0.0, 3600.0, true);
    }
  }

  void Vehicles(Scenario* sc) {
    // Explicit ids first, so that automatic ones never collide with them.
    ForEachItem(root_["vehicles"], "vehicles", [&](const YAML::Node& v, const std::string& p) {
      r_.ExpectMap(v, p);
      if (Reader::Has(v, "id")) {
        const std::int64_t id = r_.Int(v, p, "id", std::nullopt, 1, 1'000'000'000);
        if (!explicit_ids_.insert(id).second) {
          r_.Fail(v["id"], p + ".id = " + std::to_string(id), "is used twice");
        }
      }
    });
    ForEachItem(root_["vehicles"], "vehicles", [&](const YAML::Node& v, const std::string& p) {
      r_.CheckKeys(v, p, {"id", "class", "steering", "length", "width", "height", "wheelbase",
                          "rear_axle_offset", "rotation_axis_offset", "reflectance", "start",
                          "profile"});
      SceneObject o = VehicleBody(v, p);
      o.id = Reader::Has(v, "id") ? v["id"].as<std::int64_t>() : NextId();
      const SteeringKind kind = Steering(v, p, o.object_class);
      VehicleMotion::Params mp = Kinematics(v, p, o, kind);
      o.rotation_axis_offset = mp.rotation_axis_offset;
      double yaw;
      const Eigen::Vector2d c = Pose(v, p, "start", &yaw);
      PiecewiseLinear speed, turn;
      Profile(v, p, kind, &speed, &turn);
      o.center = c;
      o.yaw = yaw;
      auto motion = MakeMotion(v, p, mp, c, yaw, speed, turn);
      if (!motion->IsStatic()) o.motion = std::move(motion);
      sc->scene.objects.push_back(o);
    });
  }

  void Traffic(Scenario* sc) {
    ForEachItem(root_["traffic"], "traffic", [&](const YAML::Node& g, const std::string& p) {
      r_.ExpectMap(g, p);
      const std::string kind = r_.Choice(g, p, "kind", std::nullopt, {"lane", "ring"});
      const std::vector<std::string> common = {"kind", "class", "count", "speed", "length",
                                               "width", "height", "wheelbase",
                                               "rear_axle_offset", "reflectance"};
      std::vector<std::string> keys = common;
      if (kind == "lane") {
        keys.insert(keys.end(), {"start", "spacing"});
      } else {
        keys.insert(keys.end(), {"center", "radius", "clockwise", "start_angle_deg"});
      }
      r_.CheckKeys(g, p, keys);
      const int count = static_cast<int>(r_.Int(g, p, "count", std::nullopt, 1, 10000));
      const double speed = r_.Num(g, p, "speed", std::nullopt, -50.0, 50.0);
      SceneObject proto = VehicleBody(g, p);
      if (proto.object_class == ObjectClass::kSkidSteer) {
        r_.Fail(g["class"], p + ".class", "traffic generators drive Ackerman vehicles; "
                                          "list a skid_steer under `vehicles`");
      }
      VehicleMotion::Params mp = Kinematics(g, p, proto, SteeringKind::kAckerman);
      proto.rotation_axis_offset = mp.rotation_axis_offset;
      const double L = mp.rotation_axis_offset;
      for (int k = 0; k < count; ++k) {
        SceneObject o = proto;
        o.id = NextId();
        double yaw, steer = 0.0;
        Eigen::Vector2d axis;
        if (kind == "lane") {
          double yaw0;
          const Eigen::Vector2d c0 = Pose(g, p, "start", &yaw0);
          const double spacing = r_.Num(g, p, "spacing", std::nullopt, 0.0, 1e4, true);
          if (spacing < proto.length) {
            r_.Fail(g["spacing"], p + ".spacing = " + Fmt(spacing),
                    "must be at least the vehicle length " + Fmt(proto.length) + " m");
          }
          yaw = yaw0;
          const Eigen::Vector2d a(std::cos(yaw), std::sin(yaw));
          axis = c0 - k * spacing * a + L * a;
        } else {
          const Eigen::Vector2d centre = r_.Point(g, p, "center");
          const double radius = r_.Num(g, p, "radius", std::nullopt, 1.0, 1e4);
          const bool cw = r_.Bool(g, p, "clockwise", false);
          const double a0 = DegToRad(r_.Num(g, p, "start_angle_deg", 0.0, -360.0, 360.0));
          const double phi = a0 + (cw ? -1.0 : 1.0) * 2.0 * kPi * k / count;
          axis = centre + radius * Eigen::Vector2d(std::cos(phi), std::sin(phi));
          yaw = phi + (cw ? -0.5 : 0.5) * kPi;
          // The rear axle drives the circle of this radius: tan(delta) = wheelbase / radius (the
          // kinematic bicycle). The turning centre is on the steered side whatever the sign of v.
          steer = std::atan(mp.wheelbase / radius) * (cw ? -1.0 : 1.0);
          if (std::abs(steer) >= DegToRad(60.0)) {
            r_.Fail(g["radius"], p + ".radius = " + Fmt(radius),
                    "is too tight for the wheelbase (steering >= 60 deg)");
          }
          if (count * proto.length > 2.0 * kPi * radius) {
            r_.Fail(g["count"], p + ".count = " + std::to_string(count),
                    "vehicles do not fit on a circle of radius " + Fmt(radius) + " m");
          }
        }
        const Eigen::Vector2d a(std::cos(yaw), std::sin(yaw));
        o.center = axis - L * a;
        o.yaw = WrapToPi(yaw);
        auto motion = std::make_shared<VehicleMotion>(
            mp, o.center, o.yaw, PiecewiseLinear({{0.0, speed}}), PiecewiseLinear({{0.0, steer}}),
            duration_ + 1.0);
        if (!motion->IsStatic()) o.motion = std::move(motion);
        sc->scene.objects.push_back(o);
      }
    });
  }

  void Parked(Scenario* sc) {
    ForEachItem(root_["parked"], "parked", [&](const YAML::Node& v, const std::string& p) {
      r_.CheckKeys(v, p, {"class", "x", "y", "yaw_deg", "length", "width", "height", "wheelbase",
                          "rear_axle_offset", "rotation_axis_offset", "reflectance", "count",
                          "spacing", "direction_deg", "skip"});
      SceneObject proto = VehicleBody(v, p);
      const SteeringKind kind = proto.object_class == ObjectClass::kSkidSteer
                                    ? SteeringKind::kSkidSteer
                                    : SteeringKind::kAckerman;
      proto.rotation_axis_offset = Kinematics(v, p, proto, kind).rotation_axis_offset;
      proto.yaw = DegToRad(r_.Num(v, p, "yaw_deg", 0.0, -360.0, 360.0));
      for (const Eigen::Vector2d& c : Row(v, p)) {
        SceneObject o = proto;
        o.id = NextId();
        o.center = c;
        sc->scene.objects.push_back(o);
      }
    });
  }

  void Walls(Scenario* sc) {
    const ClassDefaults d = DefaultsFor(ObjectClass::kWall);
    ForEachItem(root_["walls"], "walls", [&](const YAML::Node& w, const std::string& p) {
      r_.CheckKeys(w, p, {"from", "to", "thickness", "height", "reflectance"});
      const Eigen::Vector2d a = r_.Point(w, p, "from"), b = r_.Point(w, p, "to");
      if ((b - a).norm() < 0.1) r_.Fail(w, p, "from and to must be at least 0.1 m apart");
      SceneObject o;
      o.id = NextId();
      o.object_class = ObjectClass::kWall;
      o.shape = Shape::kBox;
      o.center = 0.5 * (a + b);
      o.yaw = std::atan2(b.y() - a.y(), b.x() - a.x());
      o.width = r_.Num(w, p, "thickness", d.width, 0.05, 10.0);
      // from/to are the centreline's end points; the wall reaches half its thickness beyond them
      // so that two walls sharing an end point meet in a closed corner.
      o.length = (b - a).norm() + o.width;
      o.height = r_.Num(w, p, "height", d.height, 0.1, 100.0);
      o.reflectance = r_.Num(w, p, "reflectance", d.reflectance, 0.0, 1.0);
      o.rotation_axis_offset = std::nan("");
      sc->scene.objects.push_back(o);
    });
  }

  void Round(Scenario* sc, const char* key, ObjectClass cls) {
    const ClassDefaults d = DefaultsFor(cls);
    ForEachItem(root_[key], key, [&](const YAML::Node& v, const std::string& p) {
      std::vector<std::string> keys = {"x", "y", "radius", "height", "reflectance", "count",
                                       "spacing", "direction_deg", "skip"};
      if (cls == ObjectClass::kBush) keys.push_back("penetration");
      r_.CheckKeys(v, p, keys);
      SceneObject proto;
      proto.object_class = cls;
      proto.shape = Shape::kCylinder;
      proto.length = proto.width = 2.0 * r_.Num(v, p, "radius", 0.5 * d.length, 0.01, 50.0);
      proto.height = r_.Num(v, p, "height", d.height, 0.05, 100.0);
      proto.reflectance = r_.Num(v, p, "reflectance", d.reflectance, 0.0, 1.0);
      proto.penetration =
          cls == ObjectClass::kBush ? r_.Num(v, p, "penetration", 0.3, 0.0, 10.0) : 0.0;
      proto.rotation_axis_offset = std::nan("");
      for (const Eigen::Vector2d& c : Row(v, p)) {
        SceneObject o = proto;
        o.id = NextId();
        o.center = c;
        sc->scene.objects.push_back(o);
      }
    });
  }

 private:
  // Calls fn(item, item_path) for each item of the list at path (none if list is absent),
  // item_path being "path[i]". Refuses a list that is not a sequence.
  template <class Fn>
  void ForEachItem(const YAML::Node& list, const std::string& path, Fn fn) {
    if (!list.IsDefined()) return;
    r_.ExpectSeq(list, path);
    for (std::size_t i = 0; i < list.size(); ++i) {
      fn(list[i], path + "[" + std::to_string(i) + "]");
    }
  }

  std::int64_t NextId() {
    while (explicit_ids_.count(next_id_)) ++next_id_;
    return next_id_++;
  }

  static std::string PresetList() {
    std::string s;
    for (const auto& n : LadarPresetNames()) s += (s.empty() ? "" : ", ") + n;
    return s;
  }

  LadarParams Sensor(const YAML::Node& n, const std::string& p, const std::string& name) {
    r_.CheckKeys(n, p, {"preset", "rate_hz", "azimuth_start_deg", "fov_deg", "resolution_deg",
                        "clockwise", "elevations_deg", "layers", "min_range", "max_range",
                        "range_noise", "dropout", "spurious", "mount"});
    LadarParams s;
    if (Reader::Has(n, "preset")) {
      const std::string preset = r_.Str(n, p, "preset", std::nullopt);
      if (!LadarPreset(preset, &s)) {
        r_.Fail(n["preset"], p + ".preset = " + preset, "unknown preset; known: " + PresetList());
      }
    }
    s.name = name;
    // Range checks are LadarParams::Validate()'s; here only types, so that limits live in one place.
    const double inf = std::numeric_limits<double>::infinity();
    auto num = [&](const char* key, double* field) { *field = r_.Num(n, p, key, *field, -inf, inf); };
    num("rate_hz", &s.rate_hz);
    num("azimuth_start_deg", &s.azimuth_start_deg);
    num("fov_deg", &s.fov_deg);
    num("resolution_deg", &s.resolution_deg);
    s.clockwise = r_.Bool(n, p, "clockwise", s.clockwise);
    num("min_range", &s.min_range);
    num("max_range", &s.max_range);
    num("range_noise", &s.range_noise);
    num("dropout", &s.dropout);
    num("spurious", &s.spurious);
    if (Reader::Has(n, "elevations_deg") && Reader::Has(n, "layers")) {
      r_.Fail(n["layers"], p + ".layers", "give either elevations_deg or layers, not both");
    }
    if (Reader::Has(n, "elevations_deg")) {
      const YAML::Node e = n["elevations_deg"];
      r_.ExpectSeq(e, p + ".elevations_deg");
      s.elevations_deg.clear();
      for (std::size_t i = 0; i < e.size(); ++i) {
        s.elevations_deg.push_back(
            r_.ScalarNumber(e[i], p + ".elevations_deg[" + std::to_string(i) + "]"));
      }
    }
    if (Reader::Has(n, "layers")) {
      const YAML::Node l = n["layers"];
      const std::string q = p + ".layers";
      r_.CheckKeys(l, q, {"count", "min_deg", "max_deg"});
      const int count = static_cast<int>(r_.Int(l, q, "count", std::nullopt, 1, 256));
      const double lo = r_.Num(l, q, "min_deg", std::nullopt, -89.0, 89.0);
      const double hi = r_.Num(l, q, "max_deg", std::nullopt, -89.0, 89.0);
      if (count > 1 && !(hi > lo)) r_.Fail(l, q, "max_deg must be greater than min_deg");
      s.elevations_deg.clear();
      for (int i = 0; i < count; ++i) {
        s.elevations_deg.push_back(count == 1 ? lo : lo + i * (hi - lo) / (count - 1));
      }
    }
    if (Reader::Has(n, "mount")) {
      const YAML::Node m = n["mount"];
      const std::string q = p + ".mount";
      r_.CheckKeys(m, q, {"x", "y", "z", "roll_deg", "pitch_deg", "yaw_deg"});
      s.mount_xyz.x() = r_.Num(m, q, "x", s.mount_xyz.x(), -inf, inf);
      s.mount_xyz.y() = r_.Num(m, q, "y", s.mount_xyz.y(), -inf, inf);
      s.mount_xyz.z() = r_.Num(m, q, "z", s.mount_xyz.z(), -inf, inf);
      s.mount_roll_deg = r_.Num(m, q, "roll_deg", s.mount_roll_deg, -inf, inf);
      s.mount_pitch_deg = r_.Num(m, q, "pitch_deg", s.mount_pitch_deg, -inf, inf);
      s.mount_yaw_deg = r_.Num(m, q, "yaw_deg", s.mount_yaw_deg, -inf, inf);
    }
    const std::string err = s.Validate();
    if (!err.empty()) {
      // Point at the offending key: Validate() names it before " = ".
      std::string key = err.substr(0, err.find(' '));
      key = key.substr(0, key.find('['));
      YAML::Node at = n;
      if (key.rfind("mount.", 0) == 0 && Reader::Has(n, "mount")) {
        const YAML::Node m = n["mount"];
        const std::string sub = key.substr(6);
        at = m[sub].IsDefined() ? m[sub] : m;
      } else if (key == "elevations_deg" && Reader::Has(n, "layers")) {
        at = n["layers"];
      } else if (n[key].IsDefined()) {
        at = n[key];
      }
      r_.Fail(at, p, err);
    }
    return s;
  }

  // The box and class of a vehicle entry (vehicles, traffic, parked).
  SceneObject VehicleBody(const YAML::Node& v, const std::string& p) {
    SceneObject o;
    o.object_class = VehicleClassFrom(r_.Choice(v, p, "class", std::string("car"), kVehicleClasses));
    const ClassDefaults d = DefaultsFor(o.object_class);
    o.shape = Shape::kBox;
    o.length = r_.Num(v, p, "length", d.length, 0.5, 30.0);
    o.width = r_.Num(v, p, "width", d.width, 0.3, 5.0);
    o.height = r_.Num(v, p, "height", d.height, 0.2, 6.0);
    o.reflectance = r_.Num(v, p, "reflectance", d.reflectance, 0.0, 1.0);
    return o;
  }

  SteeringKind Steering(const YAML::Node& v, const std::string& p, ObjectClass cls) {
    const std::string def = cls == ObjectClass::kSkidSteer ? "skid_steer" : "ackerman";
    return r_.Choice(v, p, "steering", def, {"ackerman", "skid_steer"}) == "skid_steer"
               ? SteeringKind::kSkidSteer
               : SteeringKind::kAckerman;
  }

  VehicleMotion::Params Kinematics(const YAML::Node& v, const std::string& p,
                                   const SceneObject& o, SteeringKind kind) {
    const ClassDefaults d = DefaultsFor(o.object_class);
    VehicleMotion::Params mp;
    mp.kind = kind;
    const double half = 0.5 * o.length;
    if (kind == SteeringKind::kAckerman) {
      if (Reader::Has(v, "rotation_axis_offset")) {
        r_.Fail(v["rotation_axis_offset"], p + ".rotation_axis_offset",
                "is for skid-steer vehicles; an Ackerman vehicle has rear_axle_offset");
      }
      const double wb_default = d.wheelbase > 0.0 ? std::min(d.wheelbase, 0.8 * o.length)
                                                  : 0.6 * o.length;
      mp.wheelbase = r_.Num(v, p, "wheelbase", wb_default, 0.3, o.length);
      const double axis_default = d.wheelbase > 0.0 ? std::max(d.axis, -half) : -0.5 * mp.wheelbase;
      mp.rotation_axis_offset = r_.Num(v, p, "rear_axle_offset", axis_default, -half, half);
      if (mp.rotation_axis_offset + mp.wheelbase > half + 1e-9) {
        r_.Fail(v, p, "rear_axle_offset + wheelbase = " + Fmt(mp.rotation_axis_offset + mp.wheelbase) +
                          " m puts the front axle outside the vehicle (half length " + Fmt(half) + " m)");
      }
    } else {
      if (Reader::Has(v, "rear_axle_offset") || Reader::Has(v, "wheelbase")) {
        r_.Fail(Reader::Has(v, "wheelbase") ? v["wheelbase"] : v["rear_axle_offset"], p,
                "a skid-steer vehicle has rotation_axis_offset, not wheelbase/rear_axle_offset");
      }
      mp.wheelbase = 0.0;
      mp.rotation_axis_offset = r_.Num(v, p, "rotation_axis_offset", d.axis, -half, half);
    }
    return mp;
  }

  // {x, y, yaw_deg} under key; returns the point and sets *yaw [rad].
  Eigen::Vector2d Pose(const YAML::Node& map, const std::string& path, const char* key,
                       double* yaw) {
    const YAML::Node n = map[key];
    const std::string p = Reader::Join(path, key);
    if (!n.IsDefined()) r_.Fail(map, p, "required key is missing");
    r_.CheckKeys(n, p, {"x", "y", "yaw_deg"});
    *yaw = DegToRad(r_.Num(n, p, "yaw_deg", 0.0, -360.0, 360.0));
    return {r_.Num(n, p, "x", std::nullopt, -kCoord, kCoord),
            r_.Num(n, p, "y", std::nullopt, -kCoord, kCoord)};
  }

  // profile: [{t, speed, steer_deg | yaw_rate_deg}, ...]
  void Profile(const YAML::Node& v, const std::string& path, SteeringKind kind,
               PiecewiseLinear* speed, PiecewiseLinear* turn) {
    const YAML::Node list = v["profile"];
    if (!list.IsDefined()) return;
    const std::string p = path + ".profile";
    r_.ExpectSeq(list, p);
    const char* turn_key = kind == SteeringKind::kAckerman ? "steer_deg" : "yaw_rate_deg";
    const char* other_key = kind == SteeringKind::kAckerman ? "yaw_rate_deg" : "steer_deg";
    std::vector<PiecewiseLinear::Key> sk, tk;
    double last_t = 0.0;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const YAML::Node k = list[i];
      const std::string q = p + "[" + std::to_string(i) + "]";
      r_.ExpectMap(k, q);
      if (Reader::Has(k, other_key)) {
        r_.Fail(k[other_key], Reader::Join(q, other_key),
                kind == SteeringKind::kAckerman
                    ? "an Ackerman vehicle is steered with steer_deg"
                    : "a skid-steer vehicle is turned with yaw_rate_deg");
      }
      r_.CheckKeys(k, q, {"t", "speed", turn_key});
      const double t = r_.Num(k, q, "t", std::nullopt, 0.0, 1e5);
      if (t < last_t) {
        r_.Fail(k["t"], q + ".t = " + Fmt(t),
                "is earlier than the previous keyframe's t = " + Fmt(last_t));
      }
      last_t = t;
      if (!Reader::Has(k, "speed") && !Reader::Has(k, turn_key)) {
        r_.Fail(k, q, std::string("a keyframe needs speed and/or ") + turn_key);
      }
      if (Reader::Has(k, "speed")) sk.push_back({t, r_.Num(k, q, "speed", std::nullopt, -50.0, 50.0)});
      if (Reader::Has(k, turn_key)) {
        const double value = kind == SteeringKind::kAckerman
                                 ? r_.Num(k, q, turn_key, std::nullopt, -60.0, 60.0, true, true)
                                 : r_.Num(k, q, turn_key, std::nullopt, -360.0, 360.0);
        tk.push_back({t, DegToRad(value)});
      }
    }
    *speed = PiecewiseLinear(sk);
    *turn = PiecewiseLinear(tk);
  }

  std::shared_ptr<const VehicleMotion> MakeMotion(const YAML::Node& v, const std::string& p,
                                                  const VehicleMotion::Params& mp,
                                                  const Eigen::Vector2d& c, double yaw,
                                                  const PiecewiseLinear& speed,
                                                  const PiecewiseLinear& turn) {
    try {
      return std::make_shared<VehicleMotion>(mp, c, yaw, speed, turn, duration_ + 1.0);
    } catch (const std::invalid_argument& e) {
      r_.Fail(v, p, e.what());
    }
  }

  // Positions of a row: (x, y) then count - 1 more every spacing along direction_deg, minus skip.
  std::vector<Eigen::Vector2d> Row(const YAML::Node& v, const std::string& p) {
    const Eigen::Vector2d first(r_.Num(v, p, "x", std::nullopt, -kCoord, kCoord),
                                r_.Num(v, p, "y", std::nullopt, -kCoord, kCoord));
    const int count = static_cast<int>(r_.Int(v, p, "count", 1, 1, 10000));
    const double spacing = r_.Num(v, p, "spacing", count > 1 ? std::nullopt : std::optional(0.0),
                                  0.0, 1e4, count > 1);
    const double dir = DegToRad(r_.Num(v, p, "direction_deg", 0.0, -360.0, 360.0));
    std::set<std::int64_t> skip;
    if (Reader::Has(v, "skip")) {
      const YAML::Node s = v["skip"];
      r_.ExpectSeq(s, p + ".skip");
      for (std::size_t i = 0; i < s.size(); ++i) {
        const std::string q = p + ".skip[" + std::to_string(i) + "]";
        const double k = r_.ScalarNumber(s[i], q);
        if (k != std::floor(k) || k < 0 || k >= count) {
          r_.Fail(s[i], q + " = " + Fmt(k), "must be an index in [0, count)");
        }
        skip.insert(static_cast<std::int64_t>(k));
      }
    }
    std::vector<Eigen::Vector2d> out;
    const Eigen::Vector2d step = spacing * Eigen::Vector2d(std::cos(dir), std::sin(dir));
    for (int k = 0; k < count; ++k) {
      if (!skip.count(k)) out.push_back(first + k * step);
    }
    return out;
  }

  Reader r_;
  YAML::Node root_;
  double duration_;
  std::set<std::int64_t> explicit_ids_;
  std::int64_t next_id_ = 1;
};

Scenario LoadScenarioChecked(const std::string& path, std::optional<double> duration_override,
                             int depth);

YAML::Node Merge(const YAML::Node& base, const YAML::Node& over) {
  if (!base.IsMap() || !over.IsMap()) return over;
  YAML::Node out(YAML::NodeType::Map);
  for (const auto& kv : base) out[kv.first.Scalar()] = kv.second;
  for (const auto& kv : over) {
    const std::string k = kv.first.Scalar();
    const YAML::Node b = base[k];
    out[k] = b.IsDefined() ? Merge(b, kv.second) : kv.second;
  }
  return out;
}

YAML::Node ParseFile(const std::string& path) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw ScenarioError(path + ": cannot read the scenario file");
  } catch (const YAML::ParserException& e) {
    throw ScenarioError(path + ":" + std::to_string(e.mark.line + 1) + ":" +
                        std::to_string(e.mark.column + 1) + ": YAML syntax error: " + e.msg);
  }
}

// The file's tree with its `extends` chain merged in; docs gets every file involved.
YAML::Node LoadTree(const std::string& path, int depth, std::vector<Doc>* docs) {
  YAML::Node root = ParseFile(path);
  docs->push_back({path, root});
  Reader r(docs);
  if (!root.IsMap()) r.Fail(root, "(top level)", "a scenario file is a map of keys (key: value)");
  const YAML::Node ext = root["extends"];
  if (!ext.IsDefined()) return root;
  if (depth >= 4) r.Fail(ext, "extends", "chain is longer than 4 files (a cycle?)");
  const std::string base_name = r.Str(root, "", "extends", std::nullopt);
  std::string base_path;
  const fs::path sibling = fs::path(path).parent_path() / (base_name + ".yaml");
  if (base_name.find('/') == std::string::npos && fs::is_regular_file(sibling)) {
    base_path = sibling.string();
  } else {
    try {
      base_path = ResolveScenarioPath(base_name);
    } catch (const ScenarioError& e) {
      r.Fail(ext, "extends = " + base_name, e.what());
    }
  }
  // The base must be a valid scenario by itself: its errors are reported against its own file.
  LoadScenarioChecked(base_path, std::nullopt, depth + 1);
  const YAML::Node base = LoadTree(base_path, depth + 1, docs);
  YAML::Node over(YAML::NodeType::Map);
  for (const auto& kv : root) {
    if (kv.first.Scalar() != "extends") over[kv.first.Scalar()] = kv.second;
  }
  return Merge(base, over);
}

}  // namespace

LadarParams Scenario::Sensor(const std::string& which) const {
  const std::string n = which.empty() ? default_sensor : which;
  if (auto it = sensors.find(n); it != sensors.end()) return it->second;
  LadarParams p;
  if (LadarPreset(n, &p)) return p;
  std::set<std::string> available;  // the scenario's sensors and the presets, once each
  for (const auto& kv : sensors) available.insert(kv.first);
  for (const auto& s : LadarPresetNames()) available.insert(s);
  std::string names;
  for (const auto& s : available) names += (names.empty() ? "" : ", ") + s;
  throw std::invalid_argument("no sensor '" + n + "' in scenario '" + name + "'; available: " +
                              names);
}

Scenario LoadScenario(const std::string& path, std::optional<double> duration_override) {
  try {
    return LoadScenarioChecked(path, duration_override, 0);
  } catch (const YAML::Exception& e) {
    // Every expected problem is reported with its key above; this catches what yaml-cpp alone
    // notices (e.g. subscripting a scalar), so that a bad file never escapes as a crash.
    throw ScenarioError(path + ":" + std::to_string(e.mark.line + 1) + ":" +
                        std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
}

namespace {
Scenario LoadScenarioChecked(const std::string& path, std::optional<double> duration_override,
                             int depth) {
  std::vector<Doc> docs;
  const YAML::Node root = LoadTree(path, depth, &docs);
  Reader r(&docs);
  r.CheckKeys(root, "", {"name", "description", "extends", "duration", "start_utime", "seed",
                         "truth", "sensor", "sensors", "ego", "vehicles", "traffic", "parked",
                         "walls", "poles", "bushes"});
  Scenario sc;
  sc.path = path;
  const YAML::Node own = docs.front().root;  // the name belongs to this file, not to its base
  sc.name = own["name"].IsDefined() ? r.Str(own, "", "name", std::nullopt)
                                     : fs::path(path).stem().string();
  sc.description = r.Str(root, "", "description", std::string());
  sc.duration = r.Num(root, "", "duration", std::nullopt, 0.0, 3600.0, true);
  if (duration_override) {
    if (!(*duration_override > 0.0 && *duration_override <= 3600.0)) {
      throw ScenarioError("duration override = " + Fmt(*duration_override) +
                          " s: must be in (0, 3600]");
    }
    sc.duration = *duration_override;
  }
  sc.start_utime = r.Int(root, "", "start_utime", sc.start_utime, 0, 4'000'000'000'000'000);
  sc.seed = static_cast<std::uint64_t>(
      r.Int(root, "", "seed", 1, 0, std::numeric_limits<std::int64_t>::max()));
  Builder b(&docs, root, sc.duration);
  b.Truth(&sc);
  b.Sensors(&sc);
  b.Ego(&sc);
  b.Vehicles(&sc);
  b.Traffic(&sc);
  b.Parked(&sc);
  b.Walls(&sc);
  b.Round(&sc, "poles", ObjectClass::kPole);
  b.Round(&sc, "bushes", ObjectClass::kBush);
  if (sc.scene.objects.size() > 20000) {
    throw ScenarioError(path + ": " + std::to_string(sc.scene.objects.size()) +
                        " objects: at most 20000 are supported");
  }
  return sc;
}
}  // namespace

std::string ResolveScenarioPath(const std::string& name) {
  if (name.empty()) throw ScenarioError("empty scenario name");
  std::error_code ec;
  if (fs::is_regular_file(name, ec)) return name;
  std::vector<fs::path> dirs;
  if (const char* env = std::getenv("VTRACK_SCENARIO_DIR"); env && *env) dirs.emplace_back(env);
  dirs.emplace_back("config/scenarios");
  if (std::string(VTRACK_SOURCE_DIR).size()) dirs.emplace_back(fs::path(VTRACK_SOURCE_DIR) / "config/scenarios");
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) dirs.push_back(exe.parent_path().parent_path() / "share/vtrack/config/scenarios");
  std::string searched;
  for (const auto& d : dirs) {
    for (const fs::path& f : {d / (name + ".yaml"), d / name}) {
      if (fs::is_regular_file(f, ec)) return f.string();
    }
    searched += "\n  " + (d / (name + ".yaml")).string();
  }
  throw ScenarioError("no scenario '" + name + "': not a file, and not found in" + searched);
}

}  // namespace vtrack::sim
