#include "tests/log_tools/synthetic_run.h"

#include <cmath>
#include <limits>

#include "lcmtypes/util/log_reader.h"
#include "vtrack/ladar_scan_t.hpp"

namespace vtrack::testing {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

vtrack::object_t Object(std::int64_t id, std::int8_t cls, double x, double y, double yaw) {
  vtrack::object_t o{};
  o.id = id;
  o.object_class = cls;
  o.x = x;
  o.y = y;
  o.z = 0.0;
  o.yaw = yaw;
  o.length = 4.5;
  o.width = 1.8;
  o.height = 1.5;
  o.rear_axle_offset = kNaN;
  o.in_labelled_region = true;
  o.num_points = 50;
  return o;
}

vtrack::track_t Track(std::int64_t id, std::int8_t status, std::int8_t cls, double x, double y,
                      double theta) {
  vtrack::track_t t{};
  t.id = id;
  t.status = status;
  t.model = vtrack::track_t::MODEL_ISM;
  t.object_class = cls;
  t.x = x;
  t.y = y;
  t.theta = theta;
  t.rear_axle_offset = kNaN;
  t.z = kNaN;  // no detector's box measured it (track_t)
  t.height = kNaN;
  t.length = 4.5;
  t.width = 1.8;
  for (int i = 0; i < 9; ++i) t.cov[i] = 0.0;
  t.cov[0] = t.cov[4] = 0.04;
  t.cov[8] = 0.01;
  t.num_hypotheses = 1;
  t.npred = 0;
  return t;
}

}  // namespace

TruthState CarA(double t) {
  const double w = kSpeed / kRadius;
  const double yaw = w * t;
  const Eigen::Vector2d axle(kRadius * std::sin(yaw), kRadius - kRadius * std::cos(yaw));
  const Eigen::Vector2d h(std::cos(yaw), std::sin(yaw)), n(-std::sin(yaw), std::cos(yaw));
  TruthState s;
  // axle = centre + L h  =>  centre = axle - L h;  d/dt: v h - L w n.
  s.centre = axle - kRearAxle * h;
  s.velocity = kSpeed * h - kRearAxle * w * n;
  s.yaw = std::remainder(yaw, 2 * kPi);
  s.yaw_rate = w;
  return s;
}

std::vector<vtrack::object_list_t> SyntheticTruth() {
  std::vector<vtrack::object_list_t> out;
  for (int k = -1; k < kScans; ++k) {
    const double t = k < 0 ? -1.0 : k * 0.1;
    vtrack::object_list_t list{};
    list.utime = k < 0 ? kUtime0 - 1'000'000 : kUtime0 + k * kScanPeriodUs;
    list.scan_seq = k;
    list.source = "sim:synthetic";
    const TruthState a = CarA(t);
    vtrack::object_t A = Object(1, vtrack::object_t::CLASS_CAR, a.centre.x(), a.centre.y(), a.yaw);
    A.vx = a.velocity.x();
    A.vy = a.velocity.y();
    A.speed = kSpeed;
    A.yaw_rate = a.yaw_rate;
    A.rear_axle_offset = kRearAxle;
    A.moving = true;
    list.objects.push_back(A);
    list.objects.push_back(Object(2, vtrack::object_t::CLASS_CAR, 10.0, -5.0, 0.3));
    list.objects.push_back(Object(3, vtrack::object_t::CLASS_PEDESTRIAN, -10.0, 5.0, 0.0));
    vtrack::object_t C = Object(4, vtrack::object_t::CLASS_CAR, 30.0, 30.0, 1.0);
    C.in_labelled_region = false;
    list.objects.push_back(C);
    list.num_objects = static_cast<std::int32_t>(list.objects.size());
    out.push_back(list);
  }
  return out;
}

std::vector<vtrack::track_list_t> SyntheticTracks(const std::string& mode, double offset_m) {
  std::vector<vtrack::track_list_t> out;
  const double deg2 = 2.0 * kPi / 180.0;
  for (int k = 0; k <= kScans; ++k) {
    const bool extra = k == kScans;  // the list with no ground truth
    const double t = k * 0.1;
    vtrack::track_list_t list{};
    list.utime = extra ? kUtime0 + 100'000'000 : kUtime0 + k * kScanPeriodUs;
    list.scan_seq = k;
    list.latency_us = 1000;
    list.mode = mode;
    const TruthState a = CarA(t);
    vtrack::track_t t1 = Track(1, vtrack::track_t::STATUS_CONFIRMED, vtrack::track_t::CLASS_VEHICLE,
                               a.centre.x() + offset_m, a.centre.y(), a.yaw + deg2);
    t1.model = vtrack::track_t::MODEL_VASM;
    t1.moving = true;
    t1.speed = a.velocity.norm() + 0.5;
    t1.velocity_heading = std::atan2(a.velocity.y(), a.velocity.x());
    t1.yaw_rate = a.yaw_rate + 0.01;
    t1.rear_axle_offset = kRearAxle + 0.1;
    t1.cov[0] = offset_m * offset_m;
    t1.cov[4] = 0.01;
    t1.cov[8] = deg2 * deg2;
    for (int i = 0; i <= 6; ++i) {
      const double dt = 0.5 * i;
      const TruthState f = CarA(t + dt);
      t1.pred_t.push_back(static_cast<float>(dt));
      t1.pred_x.push_back(f.centre.x() + 1.0);
      t1.pred_y.push_back(f.centre.y());
      t1.pred_theta.push_back(static_cast<float>(f.yaw));
      t1.pred_pos_std.push_back(0.5f);
    }
    t1.npred = static_cast<std::int32_t>(t1.pred_t.size());
    list.tracks.push_back(t1);
    list.tracks.push_back(Track(2, vtrack::track_t::STATUS_CONFIRMED, vtrack::track_t::CLASS_VEHICLE,
                                10.0, -5.0, 0.3 - kPi));
    list.tracks.push_back(Track(3, vtrack::track_t::STATUS_CONFIRMED, vtrack::track_t::CLASS_OTHER,
                                50.0, 50.0, 0.0));
    list.tracks.push_back(Track(4, vtrack::track_t::STATUS_CONFIRMED, vtrack::track_t::CLASS_VEHICLE,
                                -9.8, 5.0, 0.0));
    list.tracks.push_back(Track(5, vtrack::track_t::STATUS_CONFIRMED, vtrack::track_t::CLASS_VEHICLE,
                                30.5, 30.0, 1.0));
    list.tracks.push_back(Track(6, vtrack::track_t::STATUS_TENTATIVE, vtrack::track_t::CLASS_VEHICLE,
                                -30.0, -30.0, 0.0));
    list.tracks.push_back(Track(7, vtrack::track_t::STATUS_CONFIRMED, vtrack::track_t::CLASS_VEHICLE,
                                -20.0, 10.0, 0.0));
    list.num_tracks = static_cast<std::int32_t>(list.tracks.size());
    out.push_back(list);
  }
  return out;
}

void WriteSyntheticRun(const std::string& run_path) {
  lcm_util::LogWriter w(run_path);
  vtrack::ladar_scan_t scan{};
  scan.utime = kUtime0 - 50'000;
  scan.sensor_id = "synthetic";
  scan.sensor_orientation[0] = 1.0;
  scan.sweep_duration_us = 100'000;
  scan.max_range = 100.0f;
  scan.num_rings = 1;
  scan.npoints = 0;
  w.WriteMessage(scan.utime, "LADAR_SCAN", scan);
  for (const auto& list : SyntheticTruth()) {
    vtrack::pose_t pose{};
    pose.utime = list.utime;
    pose.orientation[0] = 1.0;
    for (int i = 0; i < 3; ++i) pose.pos_std[i] = -1.0;
    pose.yaw_std = -1.0;
    w.WriteMessage(list.utime, "EGO_POSE", pose);
    w.WriteMessage(list.utime, "GROUND_TRUTH", list);
  }
}

void WriteSyntheticTracks(const std::string& tracks_path, const std::string& mode, double offset_m) {
  lcm_util::LogWriter w(tracks_path);
  for (const auto& list : SyntheticTracks(mode, offset_m)) {
    w.WriteMessage(list.utime + list.latency_us, "TRACKS", list);
  }
}

}  // namespace vtrack::testing
