#include "sensor_driver/sim/ladar.h"

#include <boost/random/exponential_distribution.hpp>
#include <boost/random/normal_distribution.hpp>
#include <boost/random/uniform_01.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "base/angle.h"
#include "base/pose.h"

namespace vtrack::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kGround = -1;
constexpr int kNothing = -2;

std::string Bad(const std::string& key, double value, const std::string& why) {
  std::ostringstream os;
  os << key << " = " << value << ": " << why;
  return os.str();
}

// Angle wrapped to [0, 2 pi).
double Wrap2Pi(double a) {
  double r = std::fmod(a, 2.0 * kPi);
  if (r < 0.0) r += 2.0 * kPi;
  if (r >= 2.0 * kPi) r = 0.0;
  return r;
}

int BinOf(double azimuth) {
  const int b = static_cast<int>(Wrap2Pi(azimuth) * (LadarSimulator::kAzimuthBins / (2.0 * kPi)));
  return std::min(b, LadarSimulator::kAzimuthBins - 1);
}

// Horizontal interval [h_in, h_out] of the ray o + h u (|u| = 1) inside the footprint of an
// object in state st. False if the ray misses it or it lies behind.
bool FootprintInterval(const SceneObject& obj, const ObjectState& st, const Eigen::Vector2d& o,
                       const Eigen::Vector2d& u, double* h_in, double* h_out) {
  const Eigen::Vector2d q = o - st.center;
  if (obj.shape == Shape::kCylinder) {
    const double r = 0.5 * obj.length;
    const double b = u.dot(q);
    const double disc = b * b - (q.squaredNorm() - r * r);
    if (disc < 0.0) return false;
    const double sq = std::sqrt(disc);
    *h_in = -b - sq;
    *h_out = -b + sq;
    return *h_out > 0.0;
  }
  // Slab test in the box frame.
  const double c = std::cos(st.yaw), s = std::sin(st.yaw);
  const double qx = c * q.x() + s * q.y(), qy = -s * q.x() + c * q.y();
  const double wx = c * u.x() + s * u.y(), wy = -s * u.x() + c * u.y();
  double lo = -kInf, hi = kInf;
  auto slab = [&](double qc, double wc, double half) {
    if (std::abs(wc) < 1e-12) return std::abs(qc) <= half;
    double t1 = (-half - qc) / wc, t2 = (half - qc) / wc;
    if (t1 > t2) std::swap(t1, t2);
    lo = std::max(lo, t1);
    hi = std::min(hi, t2);
    return lo <= hi;
  };
  if (!slab(qx, wx, 0.5 * obj.length) || !slab(qy, wy, 0.5 * obj.width)) return false;
  *h_in = lo;
  *h_out = hi;
  return hi > 0.0;
}

std::vector<Eigen::Vector2d> Footprint(const SceneObject& obj, const ObjectState& st) {
  const Eigen::Vector2d a(std::cos(st.yaw), std::sin(st.yaw));
  const Eigen::Vector2d n(-a.y(), a.x());
  const Eigen::Vector2d hl = 0.5 * obj.length * a, hw = 0.5 * obj.width * n;
  return {st.center + hl + hw, st.center - hl + hw, st.center - hl - hw, st.center + hl - hw};
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Parameters

int LadarParams::NumColumns() const {
  if (!(resolution_deg > 0.0) || !(fov_deg > 0.0)) return 0;
  if (fov_deg >= 360.0 - 1e-9) return static_cast<int>(std::llround(360.0 / resolution_deg));
  return static_cast<int>(std::floor(fov_deg / resolution_deg + 1e-9)) + 1;
}

Eigen::Isometry3d LadarParams::BodyFromSensor() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = QuaternionFromRpy(DegToRad(mount_roll_deg), DegToRad(mount_pitch_deg),
                                 DegToRad(mount_yaw_deg))
                   .toRotationMatrix();
  T.translation() = mount_xyz;
  return T;
}

std::string LadarParams::Validate() const {
  auto finite = [](double v) { return std::isfinite(v); };
  if (name.empty()) return "name: must not be empty";
  if (!finite(rate_hz) || rate_hz <= 0.0 || rate_hz > 200.0)
    return Bad("rate_hz", rate_hz, "must be in (0, 200] Hz");
  if (!finite(azimuth_start_deg) || std::abs(azimuth_start_deg) > 360.0)
    return Bad("azimuth_start_deg", azimuth_start_deg, "must be in [-360, 360] deg");
  if (!finite(fov_deg) || fov_deg <= 0.0 || fov_deg > 360.0)
    return Bad("fov_deg", fov_deg, "must be in (0, 360] deg");
  if (!finite(resolution_deg) || resolution_deg < 0.01 || resolution_deg > 10.0)
    return Bad("resolution_deg", resolution_deg, "must be in [0.01, 10] deg");
  if (resolution_deg > fov_deg) return Bad("resolution_deg", resolution_deg, "must be <= fov_deg");
  if (elevations_deg.empty() || elevations_deg.size() > 256)
    return Bad("elevations_deg", static_cast<double>(elevations_deg.size()),
               "needs 1 to 256 layers");
  for (std::size_t i = 0; i < elevations_deg.size(); ++i) {
    const double e = elevations_deg[i];
    if (!finite(e) || std::abs(e) > 89.0)
      return Bad("elevations_deg[" + std::to_string(i) + "]", e, "must be in [-89, 89] deg");
    if (i > 0 && e <= elevations_deg[i - 1])
      return Bad("elevations_deg[" + std::to_string(i) + "]", e,
                 "must be greater than the previous layer (ascending, ring 0 lowest)");
  }
  if (!finite(min_range) || min_range < 0.0) return Bad("min_range", min_range, "must be >= 0 m");
  if (!finite(max_range) || max_range <= min_range || max_range > 1000.0)
    return Bad("max_range", max_range, "must be in (min_range, 1000] m");
  if (!finite(range_noise) || range_noise < 0.0 || range_noise > 5.0)
    return Bad("range_noise", range_noise, "must be in [0, 5] m");
  if (!finite(dropout) || dropout < 0.0 || dropout >= 1.0)
    return Bad("dropout", dropout, "must be in [0, 1)");
  if (!finite(spurious) || spurious < 0.0 || spurious >= 1.0)
    return Bad("spurious", spurious, "must be in [0, 1)");
  if (!mount_xyz.allFinite() || mount_xyz.head<2>().norm() > 20.0)
    return Bad("mount.x/y", mount_xyz.head<2>().norm(), "must be finite and within 20 m of the body origin");
  if (!(mount_xyz.z() > 0.05) || mount_xyz.z() > 10.0)
    return Bad("mount.z", mount_xyz.z(), "must be in (0.05, 10] m above the ground");
  if (!finite(mount_roll_deg) || std::abs(mount_roll_deg) > 45.0)
    return Bad("mount.roll_deg", mount_roll_deg, "must be in [-45, 45] deg");
  if (!finite(mount_pitch_deg) || std::abs(mount_pitch_deg) > 45.0)
    return Bad("mount.pitch_deg", mount_pitch_deg, "must be in [-45, 45] deg");
  if (!finite(mount_yaw_deg) || std::abs(mount_yaw_deg) > 360.0)
    return Bad("mount.yaw_deg", mount_yaw_deg, "must be in [-360, 360] deg");
  const double rays = static_cast<double>(NumColumns()) * elevations_deg.size();
  if (rays > 4e6) return Bad("rays per sweep", rays, "must be <= 4e6 (columns x layers)");
  return "";
}

bool LadarPreset(const std::string& name, LadarParams* out) {
  LadarParams p;
  p.name = name;
  if (name == "single_plane") {
    p.rate_hz = 25.0;
    p.azimuth_start_deg = -90.0;  // right to left, as a SICK LMS
    p.fov_deg = 180.0;
    p.resolution_deg = 0.5;
    p.clockwise = false;
    p.elevations_deg = {0.0};
    p.min_range = 0.3;
    p.max_range = 80.0;
    p.range_noise = 0.02;
    p.mount_xyz = {3.7, 0.0, 0.5};  // front bumper of a car with a 2.8 m wheelbase
  } else if (name == "velodyne64") {
    p.rate_hz = 10.0;
    p.azimuth_start_deg = 180.0;  // starts and ends behind the vehicle, turns clockwise
    p.fov_deg = 360.0;
    p.resolution_deg = 360.0 / 2048.0;
    p.clockwise = true;
    p.elevations_deg.clear();
    for (int i = 0; i < 64; ++i) p.elevations_deg.push_back(-24.8 + i * (26.8 / 63.0));
    p.min_range = 1.0;
    p.max_range = 120.0;
    p.range_noise = 0.02;
    p.mount_xyz = {1.2, 0.0, 1.73};
  } else {
    return false;
  }
  *out = p;
  return true;
}

std::vector<std::string> LadarPresetNames() { return {"single_plane", "velodyne64"}; }

// ---------------------------------------------------------------------------------------------
// Simulator

LadarSimulator::LadarSimulator(const LadarParams& params) : params_(params) {
  const std::string err = params_.Validate();
  if (!err.empty()) throw std::invalid_argument("sensor '" + params_.name + "': " + err);
  body_from_sensor_ = params_.BodyFromSensor();
  const int n = params_.NumColumns();
  const double sign = params_.clockwise ? -1.0 : 1.0;
  const double us_per_deg = 1e6 / (360.0 * params_.rate_hz);
  for (int j = 0; j < n; ++j) {
    const double az = DegToRad(params_.azimuth_start_deg + sign * j * params_.resolution_deg);
    col_az_.push_back(az);
    col_cos_.push_back(std::cos(az));
    col_sin_.push_back(std::sin(az));
    col_dt_us_.push_back(
        static_cast<std::int32_t>(std::llround(j * params_.resolution_deg * us_per_deg)));
  }
  for (double e : params_.elevations_deg) {
    const double r = DegToRad(e);
    layer_sin_.push_back(std::sin(r));
    layer_cos_.push_back(std::cos(r));
    layer_tan_.push_back(std::tan(r));
  }
  const double sweep_s = SweepDurationUs() * 1e-6;
  num_sub_ = std::max(1, static_cast<int>(std::ceil(sweep_s / kSubIntervalS - 1e-9)));
}

int LadarSimulator::SubIntervalOf(double tau) const {
  const double sweep_s = SweepDurationUs() * 1e-6;
  if (sweep_s <= 0.0) return 0;
  return std::clamp(static_cast<int>(tau / sweep_s * num_sub_), 0, num_sub_ - 1);
}

void LadarSimulator::BuildIndex(const Scene& scene, double t0) {
  const int n_obj = static_cast<int>(scene.objects.size());
  const double sweep_s = SweepDurationUs() * 1e-6;
  sub_sensor_xy_.resize(num_sub_ + 1);
  sub_states_.resize(static_cast<std::size_t>(num_sub_ + 1) * n_obj);
  for (int s = 0; s <= num_sub_; ++s) {
    const double t = t0 + sweep_s * s / num_sub_;
    const Eigen::Isometry3d world_from_sensor = scene.WorldFromBody(t) * body_from_sensor_;
    sub_sensor_xy_[s] = world_from_sensor.translation().head<2>();
    for (int i = 0; i < n_obj; ++i) {
      sub_states_[static_cast<std::size_t>(s) * n_obj + i] = scene.StateOf(scene.objects[i], t);
    }
  }

  constexpr int B = kAzimuthBins;
  bin_offsets_.assign(static_cast<std::size_t>(num_sub_) * (B + 1), 0);
  bin_items_.clear();
  spans_.resize(n_obj);
  const double bins_per_rad = B / (2.0 * kPi);
  for (int s = 0; s < num_sub_; ++s) {
    int* offsets = &bin_offsets_[static_cast<std::size_t>(s) * (B + 1)];
    for (int i = 0; i < n_obj; ++i) {
      const SceneObject& obj = scene.objects[i];
      const ObjectState& a = sub_states_[static_cast<std::size_t>(s) * n_obj + i];
      const ObjectState& b = sub_states_[static_cast<std::size_t>(s + 1) * n_obj + i];
      const Eigen::Vector2d& pa = sub_sensor_xy_[s];
      const Eigen::Vector2d& pb = sub_sensor_xy_[s + 1];
      const double radius = obj.BoundingRadius();
      const double da = (a.center - pa).norm(), db = (b.center - pb).norm();
      const double d_min = std::min(da, db) - radius;
      spans_[i] = {0, 0};
      if (d_min > params_.max_range + kIndexMarginM) continue;
      if (d_min <= 2.0 * kIndexMarginM) {
        spans_[i] = {0, B};  // sensor at or inside the footprint: every direction
      } else {
        // Relative positions of the footprint move linearly between the sub-interval's ends
        // (up to far less than the margin), and the azimuth of a linearly moving point is
        // monotonic, so the extreme azimuths at the two ends bound the whole sub-interval.
        const double ref = std::atan2(a.center.y() - pa.y(), a.center.x() - pa.x());
        double lo = kInf, hi = -kInf;
        auto add = [&](const Eigen::Vector2d& v, double half) {
          const double az = AngleDiff(std::atan2(v.y(), v.x()), ref);
          lo = std::min(lo, az - half);
          hi = std::max(hi, az + half);
        };
        if (obj.shape == Shape::kCylinder) {
          add(a.center - pa, std::asin(std::min(1.0, (radius + kIndexMarginM) / da)));
          add(b.center - pb, std::asin(std::min(1.0, (radius + kIndexMarginM) / db)));
        } else {
          for (const auto& c : Footprint(obj, a)) add(c - pa, 0.0);
          for (const auto& c : Footprint(obj, b)) add(c - pb, 0.0);
          const double margin = std::asin(std::min(1.0, kIndexMarginM / d_min));
          lo -= margin;
          hi += margin;
        }
        if (hi - lo >= kPi) {
          spans_[i] = {0, B};
        } else {
          const int first = BinOf(ref + lo);
          const int count = std::min(B, static_cast<int>((hi - lo) * bins_per_rad) + 2);
          spans_[i] = {first, count};
        }
      }
      for (int k = 0; k < spans_[i].second; ++k) ++offsets[(spans_[i].first + k) % B + 1];
    }
    for (int k = 0; k < B; ++k) offsets[k + 1] += offsets[k];
    const int base = static_cast<int>(bin_items_.size());
    bin_items_.resize(base + offsets[B]);
    std::vector<int> fill(offsets, offsets + B);
    for (int i = 0; i < n_obj; ++i) {
      for (int k = 0; k < spans_[i].second; ++k) {
        const int bin = (spans_[i].first + k) % B;
        bin_items_[base + fill[bin]++] = i;
      }
    }
    for (int k = 0; k <= B; ++k) offsets[k] += base;
  }
}

void LadarSimulator::GatherIntervals(const Scene& scene, int s, double azimuth,
                                     const Eigen::Vector2d& o, const Eigen::Vector2d& u, double t,
                                     int column) {
  intervals_.clear();
  const int bin = BinOf(azimuth);
  const int* offsets = &bin_offsets_[static_cast<std::size_t>(s) * (kAzimuthBins + 1)];
  for (int k = offsets[bin]; k < offsets[bin + 1]; ++k) {
    const int i = bin_items_[k];
    const SceneObject& obj = scene.objects[i];
    if (column_stamp_[i] != column) {
      column_state_[i] = obj.moving() ? scene.StateOf(obj, t) : sub_states_[i];
      column_stamp_[i] = column;
    }
    double h_in, h_out;
    if (FootprintInterval(obj, column_state_[i], o, u, &h_in, &h_out)) {
      intervals_.push_back({std::max(h_in, 0.0), h_out, obj.height, obj.penetration, i});
    }
  }
}

void LadarSimulator::FirstHit(double o_z, double slope, double* h_out, int* object) {
  double best = kInf;
  int who = kNothing;
  const double ground = slope < 0.0 ? o_z / -slope : kInf;  // the ground plane z = 0
  if (slope < 0.0) {
    best = ground;
    who = kGround;
  }
  const Interval* winner = nullptr;
  for (const Interval& iv : intervals_) {
    if (iv.h_in >= best) continue;
    // Where along the footprint is the ray's height z(h) = o_z + slope h within [0, height]?
    double lo = iv.h_in, hi = std::min(iv.h_out, best);
    if (slope > 0.0) {
      hi = std::min(hi, (iv.height - o_z) / slope);
    } else if (slope < 0.0) {
      lo = std::max(lo, (o_z - iv.height) / -slope);  // below the top; above ground is h < best
    } else if (o_z > iv.height) {
      continue;
    }
    if (lo <= hi) {
      best = lo;
      who = iv.object;
      winner = &iv;
    }
  }
  if (winner && winner->penetration > 0.0) {
    boost::random::exponential_distribution<double> depth(1.0 / winner->penetration);
    best = std::min({best + depth(rng_), winner->h_out, ground});  // not through the ground
  }
  *h_out = best;
  *object = who;
}

double LadarSimulator::Uniform01() { return boost::random::uniform_01<double>()(rng_); }

void LadarSimulator::Emit(double range_true, int object, int layer, float dir_x, float dir_y,
                          float dir_z, std::int32_t dt_us, const Scene& scene,
                          vtrack::ladar_scan_t* scan, std::vector<int>* hits) {
  const LadarParams& p = params_;
  double range = range_true;
  double reflectance;
  int counted = object;
  if (p.spurious > 0.0 && Uniform01() < p.spurious) {
    const double far = std::min(range_true, p.max_range);
    range = p.min_range + Uniform01() * (far - p.min_range);
    reflectance = kSpuriousReflectance;
    counted = kNothing;
  } else {
    if (object == kNothing || range_true > p.max_range) return;
    if (p.dropout > 0.0 && Uniform01() < p.dropout) return;
    if (p.range_noise > 0.0) range += p.range_noise * boost::random::normal_distribution<double>()(rng_);
    reflectance = object == kGround ? kGroundReflectance : scene.objects[object].reflectance;
  }
  if (range < p.min_range || range > p.max_range) return;
  scan->x[n_] = static_cast<float>(range * dir_x);
  scan->y[n_] = static_cast<float>(range * dir_y);
  scan->z[n_] = static_cast<float>(range * dir_z);
  scan->intensity[n_] = static_cast<float>(reflectance * (1.0 - 0.5 * range / p.max_range));
  scan->dt_us[n_] = dt_us;
  scan->ring[n_] = static_cast<std::int16_t>(layer);
  ++n_;
  if (counted >= 0) ++(*hits)[counted];
}

void LadarSimulator::Sweep(const Scene& scene, double t0, std::uint64_t seed,
                           vtrack::ladar_scan_t* scan, std::vector<int>* hits) {
  const LadarParams& p = params_;
  rng_.seed(seed);
  const int n_obj = static_cast<int>(scene.objects.size());
  hits->assign(n_obj, 0);
  column_state_.resize(n_obj);
  column_stamp_.assign(n_obj, -1);
  BuildIndex(scene, t0);

  scan->sensor_id = p.name;
  for (int i = 0; i < 3; ++i) scan->sensor_pos[i] = p.mount_xyz[i];
  const Eigen::Quaterniond q(body_from_sensor_.linear());
  scan->sensor_orientation[0] = q.w();
  scan->sensor_orientation[1] = q.x();
  scan->sensor_orientation[2] = q.y();
  scan->sensor_orientation[3] = q.z();
  scan->sweep_duration_us = SweepDurationUs();
  scan->max_range = static_cast<float>(p.max_range);
  scan->num_rings = static_cast<std::int16_t>(p.NumLayers());
  // At most one return per ray: size the arrays for that, fill, then trim (no reallocation).
  const std::size_t capacity = static_cast<std::size_t>(NumColumns()) * p.NumLayers();
  for (auto* v : {&scan->x, &scan->y, &scan->z, &scan->intensity}) v->resize(capacity);
  scan->dt_us.resize(capacity);
  scan->ring.resize(capacity);
  n_ = 0;

  const int layers = p.NumLayers();
  const double mount_yaw = DegToRad(p.mount_yaw_deg);
  for (int j = 0; j < NumColumns(); ++j) {
    const std::int32_t dt_us = col_dt_us_[j];
    const double tau = dt_us * 1e-6;
    const double t = t0 + tau;
    const int s = SubIntervalOf(tau);
    const MotionState ego = scene.EgoAt(t);
    const double c = std::cos(ego.yaw), sn = std::sin(ego.yaw);
    const Eigen::Vector2d o(ego.axis_point.x() + c * p.mount_xyz.x() - sn * p.mount_xyz.y(),
                            ego.axis_point.y() + sn * p.mount_xyz.x() + c * p.mount_xyz.y());
    const double o_z = p.mount_xyz.z();  // flat ground: the body never rolls or pitches
    if (p.IsLevel()) {
      // Every layer of the column shares one horizontal direction: cast the footprints once.
      const double azimuth = ego.yaw + mount_yaw + col_az_[j];
      const Eigen::Vector2d u(std::cos(azimuth), std::sin(azimuth));
      GatherIntervals(scene, s, azimuth, o, u, t, j);
      for (int l = 0; l < layers; ++l) {
        double h;
        int who;
        FirstHit(o_z, layer_tan_[l], &h, &who);
        Emit(h / layer_cos_[l], who, l, static_cast<float>(layer_cos_[l] * col_cos_[j]),
             static_cast<float>(layer_cos_[l] * col_sin_[j]), static_cast<float>(layer_sin_[l]),
             dt_us, scene, scan, hits);
      }
    } else {
      const Eigen::Matrix3d world_from_sensor_rot =
          Eigen::AngleAxisd(ego.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
          body_from_sensor_.linear();
      for (int l = 0; l < layers; ++l) {
        const Eigen::Vector3d d_s(layer_cos_[l] * col_cos_[j], layer_cos_[l] * col_sin_[j],
                                  layer_sin_[l]);
        const Eigen::Vector3d d_w = world_from_sensor_rot * d_s;
        const double horiz = d_w.head<2>().norm();
        double h;
        int who;
        if (horiz < 1e-9) {  // straight up or down: only the ground can answer
          intervals_.clear();
          h = d_w.z() < 0.0 ? o_z / -d_w.z() : kInf;
          who = d_w.z() < 0.0 ? kGround : kNothing;
          Emit(h, who, l, static_cast<float>(d_s.x()), static_cast<float>(d_s.y()),
               static_cast<float>(d_s.z()), dt_us, scene, scan, hits);
          continue;
        }
        const Eigen::Vector2d u = d_w.head<2>() / horiz;
        GatherIntervals(scene, s, std::atan2(u.y(), u.x()), o, u, t, j);
        FirstHit(o_z, d_w.z() / horiz, &h, &who);
        Emit(h / horiz, who, l, static_cast<float>(d_s.x()), static_cast<float>(d_s.y()),
             static_cast<float>(d_s.z()), dt_us, scene, scan, hits);
      }
    }
  }
  for (auto* v : {&scan->x, &scan->y, &scan->z, &scan->intensity}) v->resize(n_);
  scan->dt_us.resize(n_);
  scan->ring.resize(n_);
  scan->npoints = static_cast<std::int32_t>(n_);
}

}  // namespace vtrack::sim
