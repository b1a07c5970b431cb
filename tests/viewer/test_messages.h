// Messages with known content for the viewer tests: an ego vehicle on a known circular arc, LADAR
// scans of known world points as a moving, rotating sensor would report them, and tracker
// output for tracks on known paths.
#pragma once

#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/object_list_t.hpp"
#include "vtrack/pose_t.hpp"
#include "vtrack/track_debug_t.hpp"
#include "vtrack/track_list_t.hpp"

namespace vtrack::viewer::testing {

// Constant speed and yaw rate: the body origin moves on a circle.
struct EgoArc {
  std::int64_t t0 = 1'600'000'000'000'000;  // [us]
  double x0 = 3.0, y0 = -2.0, yaw0 = 0.4;    // [m, m, rad]
  double v = 10.0;                          // [m/s]
  double omega = 0.3;                       // [rad/s]

  Eigen::Isometry3d WorldFromBody(std::int64_t utime) const {
    const double tau = 1e-6 * static_cast<double>(utime - t0);
    const double yaw = yaw0 + omega * tau;
    const double r = v / omega;
    Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
    m.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    m.translation() = Eigen::Vector3d(x0 + r * (std::sin(yaw) - std::sin(yaw0)),
                                      y0 - r * (std::cos(yaw) - std::cos(yaw0)), 0.0);
    return m;
  }

  vtrack::pose_t Pose(std::int64_t utime) const {
    const Eigen::Isometry3d m = WorldFromBody(utime);
    const Eigen::Quaterniond q(m.linear());
    vtrack::pose_t p{};
    p.utime = utime;
    for (int i = 0; i < 3; ++i) p.pos[i] = m.translation()(i);
    p.orientation[0] = q.w();
    p.orientation[1] = q.x();
    p.orientation[2] = q.y();
    p.orientation[3] = q.z();
    for (int i = 0; i < 3; ++i) p.pos_std[i] = -1.0;
    p.yaw_std = -1.0;
    return p;
  }
};

// The sensor's mounting on the body: ahead, a little left, up, yawed 4 degrees.
inline Eigen::Isometry3d BodyFromSensor() {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear() = Eigen::AngleAxisd(4.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  m.translation() = Eigen::Vector3d(1.2, 0.1, 1.6);
  return m;
}

// A single-plane scan whose return i hits world_points[i] at utime + dt_us[i], seen from the
// sensor on the ego vehicle at that instant.
inline vtrack::ladar_scan_t ScanOf(const EgoArc& ego, std::int64_t utime, std::int64_t seq,
                                   const std::vector<Eigen::Vector3d>& world_points,
                                   const std::vector<std::int32_t>& dt_us,
                                   std::int32_t sweep_us = 100'000) {
  vtrack::ladar_scan_t s{};
  s.utime = utime;
  s.seq = seq;
  s.sensor_id = "sick_front";
  const Eigen::Isometry3d body_from_sensor = BodyFromSensor();
  const Eigen::Quaterniond q(body_from_sensor.linear());
  for (int i = 0; i < 3; ++i) s.sensor_pos[i] = body_from_sensor.translation()(i);
  s.sensor_orientation[0] = q.w();
  s.sensor_orientation[1] = q.x();
  s.sensor_orientation[2] = q.y();
  s.sensor_orientation[3] = q.z();
  s.sweep_duration_us = sweep_us;
  s.max_range = 80.0f;
  s.num_rings = 1;
  for (std::size_t i = 0; i < world_points.size(); ++i) {
    const Eigen::Isometry3d world_from_sensor = ego.WorldFromBody(utime + dt_us[i]) * body_from_sensor;
    const Eigen::Vector3d p = world_from_sensor.inverse() * world_points[i];
    s.x.push_back(static_cast<float>(p.x()));
    s.y.push_back(static_cast<float>(p.y()));
    s.z.push_back(static_cast<float>(p.z()));
    s.intensity.push_back(0.5f);
    s.dt_us.push_back(dt_us[i]);
    s.ring.push_back(0);
  }
  s.npoints = static_cast<std::int32_t>(s.x.size());
  return s;
}

inline vtrack::ladar_scan_t EmptyScan(std::int64_t utime, std::int64_t seq) {
  return ScanOf(EgoArc{}, utime, seq, {}, {});
}

inline vtrack::track_t TrackAt(std::int64_t id, double x, double y, double theta) {
  vtrack::track_t t{};
  t.id = id;
  t.status = vtrack::track_t::STATUS_CONFIRMED;
  t.model = vtrack::track_t::MODEL_VASM;
  t.moving = true;
  t.object_class = vtrack::track_t::CLASS_VEHICLE;
  t.x = x;
  t.y = y;
  t.theta = theta;
  t.speed = 5.0;
  t.velocity_heading = theta;
  t.rear_axle_offset = -1.2;
  t.length = 4.5;
  t.width = 1.9;
  t.cov[0] = 0.04;
  t.cov[4] = 0.02;
  t.cov[8] = 0.001;
  t.num_hypotheses = 1;
  t.npred = 0;
  return t;
}

inline vtrack::track_list_t TrackList(std::int64_t utime, std::int64_t seq,
                                      std::vector<vtrack::track_t> tracks) {
  vtrack::track_list_t l{};
  l.utime = utime;
  l.scan_seq = seq;
  l.latency_us = 2500;
  l.mode = "mht";
  l.tracks = std::move(tracks);
  l.num_tracks = static_cast<std::int32_t>(l.tracks.size());
  return l;
}

// A debug message with one corner-fit entry for the track.
inline vtrack::track_debug_t DebugFor(const vtrack::track_list_t& list) {
  vtrack::track_debug_t d{};
  d.utime = list.utime;
  d.scan_seq = list.scan_seq;
  d.num_segments = static_cast<std::int32_t>(list.tracks.size());
  for (const auto& t : list.tracks) {
    vtrack::track_debug_entry_t e{};
    e.track_id = t.id;
    e.fit_kind = vtrack::track_debug_entry_t::FIT_CORNER;
    e.z[0] = t.x + 0.1;
    e.z[1] = t.y - 0.05;
    e.z[2] = t.theta + 0.01;
    e.R[0] = 0.01;
    e.R[4] = 0.01;
    e.R[8] = 0.0004;
    e.predicted[0] = t.x;
    e.predicted[1] = t.y;
    e.predicted[2] = t.theta;
    e.predicted[3] = t.length;
    e.predicted[4] = t.width;
    for (int i = 0; i < 5; ++i) e.updated[i] = e.predicted[i];
    e.updated_cov[0] = e.updated_cov[4] = 0.01;
    e.updated_cov[8] = 0.001;
    e.visible_faces = 4 | 8;
    for (double& a : e.rear_axle) a = std::numeric_limits<double>::quiet_NaN();
    e.num_edges = 1;
    e.edge_x0 = {t.x - 2.0};
    e.edge_y0 = {t.y - 1.0};
    e.edge_x1 = {t.x + 2.0};
    e.edge_y1 = {t.y - 1.0};
    e.num_points = 2;
    e.point_x = {static_cast<float>(t.x - 1.0), static_cast<float>(t.x + 1.0)};
    e.point_y = {static_cast<float>(t.y - 1.0), static_cast<float>(t.y - 1.0)};
    e.point_edge = {0, 0};
    e.num_hypotheses = 0;
    d.entries.push_back(e);
  }
  d.num_entries = static_cast<std::int32_t>(d.entries.size());
  return d;
}

inline vtrack::object_list_t TruthAt(std::int64_t utime, std::int64_t seq, std::int64_t id,
                                     double x, double y, double yaw) {
  vtrack::object_list_t l{};
  l.utime = utime;
  l.scan_seq = seq;
  l.source = "test";
  vtrack::object_t o{};
  o.id = id;
  o.object_class = vtrack::object_t::CLASS_CAR;
  o.x = x;
  o.y = y;
  o.yaw = yaw;
  o.length = 4.5;
  o.width = 1.9;
  o.height = 1.5;
  o.rear_axle_offset = -1.3;
  o.moving = true;
  o.in_labelled_region = true;
  o.num_points = -1;
  l.objects.push_back(o);
  l.num_objects = 1;
  return l;
}

}  // namespace vtrack::viewer::testing
