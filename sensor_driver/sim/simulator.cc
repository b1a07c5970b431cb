#include "sensor_driver/sim/simulator.h"

#include <boost/random/normal_distribution.hpp>

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "base/angle.h"
#include "vtrack/object_t.hpp"

namespace vtrack::sim {
namespace {

std::uint64_t SplitMix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

template <class T>
std::string Str(T v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

LadarParams SensorWithOverrides(const Scenario& sc, const RunOptions& o) {
  LadarParams p = sc.Sensor(o.sensor);
  if (o.range_noise) p.range_noise = *o.range_noise;
  if (o.dropout) p.dropout = *o.dropout;
  if (o.spurious) p.spurious = *o.spurious;
  const std::string err = p.Validate();
  if (!err.empty()) throw std::invalid_argument("sensor '" + p.name + "': " + err);
  return p;
}

}  // namespace

std::uint64_t MixSeed(std::uint64_t a, std::uint64_t b, std::uint64_t c) {
  return SplitMix(SplitMix(SplitMix(a) ^ b) ^ c);
}

std::int8_t ObjectClassCode(ObjectClass c) {
  switch (c) {
    case ObjectClass::kCar: return vtrack::object_t::CLASS_CAR;
    case ObjectClass::kVan: return vtrack::object_t::CLASS_VAN;
    case ObjectClass::kTruck: return vtrack::object_t::CLASS_TRUCK;
    case ObjectClass::kSkidSteer: return vtrack::object_t::CLASS_SKID_STEER;
    case ObjectClass::kWall: return vtrack::object_t::CLASS_WALL;
    case ObjectClass::kPole: return vtrack::object_t::CLASS_POLE;
    case ObjectClass::kBush: return vtrack::object_t::CLASS_BUSH;
  }
  return vtrack::object_t::CLASS_UNKNOWN;
}

Simulator::Simulator(Scenario scenario, const RunOptions& options)
    : scenario_(std::move(scenario)),
      ladar_(SensorWithOverrides(scenario_, options)),
      seed_(options.seed.value_or(scenario_.seed)),
      pose_rate_hz_(options.pose_rate_hz.value_or(scenario_.pose_rate_hz)),
      pose_noise_(scenario_.pose_noise) {
  if (!(pose_rate_hz_ >= 1.0 && pose_rate_hz_ <= 1000.0)) {
    throw std::invalid_argument("pose rate = " + Str(pose_rate_hz_) + " Hz: must be in [1, 1000]");
  }
  if (options.pose_noise_position) pose_noise_.position = *options.pose_noise_position;
  if (options.pose_noise_yaw_deg) pose_noise_.yaw_deg = *options.pose_noise_yaw_deg;
  if (!(pose_noise_.position >= 0.0 && pose_noise_.position <= 10.0)) {
    throw std::invalid_argument("pose noise position = " + Str(pose_noise_.position) +
                                " m: must be in [0, 10]");
  }
  if (!(pose_noise_.yaw_deg >= 0.0 && pose_noise_.yaw_deg <= 45.0)) {
    throw std::invalid_argument("pose noise yaw = " + Str(pose_noise_.yaw_deg) +
                                " deg: must be in [0, 45]");
  }
  run_us_ = std::llround(scenario_.duration * 1e6);
  while (PoseOffsetUs(num_poses_) < run_us_) ++num_poses_;
  const std::int64_t last_pose = PoseOffsetUs(num_poses_ - 1);
  while (ScanPublishOffsetUs(num_scans_) <= last_pose) ++num_scans_;
  // The sweeps a pose at the highest rate allowed (1 kHz, its last pose the last whole
  // millisecond before the run's end) would keep.
  const std::int64_t last_pose_at_1khz = (run_us_ - 1) / 1000 * 1000;
  num_sweeps_in_run_ = num_scans_;
  while (ScanPublishOffsetUs(num_sweeps_in_run_) <= last_pose_at_1khz) ++num_sweeps_in_run_;
  if (num_scans_ == 0) {
    throw std::invalid_argument("scenario '" + scenario_.name + "' lasts " +
                                Str(scenario_.duration) + " s: too short for one sweep of '" +
                                ladar_.params().name + "'");
  }
}

std::int64_t Simulator::ScanOffsetUs(int i) const {
  return std::llround(i * 1e6 / ladar_.params().rate_hz);
}

std::int64_t Simulator::ScanPublishOffsetUs(int i) const {
  return ScanOffsetUs(i) + ladar_.SweepDurationUs();
}

std::int64_t Simulator::PoseOffsetUs(int k) const { return std::llround(k * 1e6 / pose_rate_hz_); }

void Simulator::MakeScan(int i, std::int64_t run_start_utime, std::int64_t seq,
                         vtrack::ladar_scan_t* scan, vtrack::object_list_t* truth) {
  const std::int64_t offset = ScanOffsetUs(i);
  const double t0 = offset * 1e-6;
  const Scene& scene = scenario_.scene;
  ladar_.Sweep(scene, t0, MixSeed(seed_, kScanStream, static_cast<std::uint64_t>(i)), scan, &hits_);
  scan->utime = run_start_utime + offset;
  scan->seq = seq;

  const Eigen::Vector2d sensor_xy =
      (scene.WorldFromBody(t0) * ladar_.params().BodyFromSensor()).translation().head<2>();
  truth->utime = scan->utime;
  truth->scan_seq = seq;
  truth->source = "sim:" + scenario_.name;
  truth->objects.resize(scene.objects.size());
  for (std::size_t n = 0; n < scene.objects.size(); ++n) {
    const SceneObject& o = scene.objects[n];
    const ObjectState s = scene.StateOf(o, t0);
    vtrack::object_t& g = truth->objects[n];
    g.id = o.id;
    g.object_class = ObjectClassCode(o.object_class);
    g.x = s.center.x();
    g.y = s.center.y();
    g.z = 0.0;
    g.yaw = WrapToPi(s.yaw);
    g.length = o.length;
    g.width = o.width;
    g.height = o.height;
    g.vx = s.velocity.x();
    g.vy = s.velocity.y();
    g.speed = s.speed;
    g.yaw_rate = s.yaw_rate;
    g.rear_axle_offset = IsVehicleClass(o.object_class) ? o.rotation_axis_offset : std::nan("");
    g.moving = o.moving();
    g.num_points = hits_[n];
    g.in_labelled_region = (s.center - sensor_xy).norm() <= scenario_.truth.labelled_radius &&
                           hits_[n] >= scenario_.truth.min_points;
  }
  truth->num_objects = static_cast<std::int32_t>(truth->objects.size());
}

void Simulator::AdvanceNoiseTo(int k) {
  const double sp = pose_noise_.position, sy = DegToRad(pose_noise_.yaw_deg);
  if (sp == 0.0 && sy == 0.0) return;
  boost::random::normal_distribution<double> n01;
  if (k < noise_k_ || noise_k_ < 0) {
    // Stationary start: the first sample has the process's full variance.
    noise_rng_.seed(MixSeed(seed_, kPoseStream, 0));
    noise_k_ = 0;
    noise_x_ = sp * n01(noise_rng_);
    noise_y_ = sp * n01(noise_rng_);
    noise_yaw_ = sy * n01(noise_rng_);
  }
  // First-order Gauss-Markov: n_k = phi n_{k-1} + sigma sqrt(1 - phi^2) w_k keeps variance sigma^2.
  const double phi = std::exp(-1.0 / (pose_rate_hz_ * pose_noise_.correlation_time));
  const double q = std::sqrt(1.0 - phi * phi);
  for (; noise_k_ < k; ++noise_k_) {
    noise_x_ = phi * noise_x_ + sp * q * n01(noise_rng_);
    noise_y_ = phi * noise_y_ + sp * q * n01(noise_rng_);
    noise_yaw_ = phi * noise_yaw_ + sy * q * n01(noise_rng_);
  }
}

void Simulator::MakePose(int k, std::int64_t run_start_utime, vtrack::pose_t* pose) {
  const std::int64_t offset = PoseOffsetUs(k);
  const MotionState m = scenario_.scene.EgoAt(offset * 1e-6);
  AdvanceNoiseTo(k);
  const double yaw = m.yaw + noise_yaw_;
  pose->utime = run_start_utime + offset;
  pose->pos[0] = m.axis_point.x() + noise_x_;
  pose->pos[1] = m.axis_point.y() + noise_y_;
  pose->pos[2] = 0.0;
  // The body origin is the rotation axis: its velocity is along the heading.
  pose->vel[0] = m.speed * std::cos(m.yaw);
  pose->vel[1] = m.speed * std::sin(m.yaw);
  pose->vel[2] = 0.0;
  pose->orientation[0] = std::cos(0.5 * yaw);
  pose->orientation[1] = 0.0;
  pose->orientation[2] = 0.0;
  pose->orientation[3] = std::sin(0.5 * yaw);
  pose->rotation_rate[0] = 0.0;
  pose->rotation_rate[1] = 0.0;
  pose->rotation_rate[2] = m.yaw_rate;
  // Kinematic acceleration of the body origin in the body frame (tangential, centripetal); no
  // gravity term.
  pose->accel[0] = m.accel;
  pose->accel[1] = m.speed * m.yaw_rate;
  pose->accel[2] = 0.0;
  pose->pos_std[0] = pose_noise_.position;
  pose->pos_std[1] = pose_noise_.position;
  pose->pos_std[2] = 0.0;
  pose->yaw_std = DegToRad(pose_noise_.yaw_deg);
}

}  // namespace vtrack::sim
