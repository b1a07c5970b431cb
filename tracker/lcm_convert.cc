#include "tracker/lcm_convert.h"

#include <cmath>
#include <limits>

namespace vtrack {
namespace {

// A quaternion within 1e-3 of unit length becomes its rotation. Any other one becomes the
// linear map it stands for, v -> q v q* (a rotation scaled by |q|^2), which the core refuses as
// not a rotation. (Eigen's toRotationMatrix() assumes a unit quaternion: for (w, 0, 0, 0) it
// gives the identity whatever w is, so an all-zero, unfilled orientation would pass as valid.)
Eigen::Matrix3d Rotation(const double q[4]) {
  const Eigen::Quaterniond r(q[0], q[1], q[2], q[3]);
  const double n = r.norm();
  if (std::isfinite(n) && std::abs(n - 1.0) < 1e-3) return r.normalized().toRotationMatrix();
  if (!(n > 0.0 && std::isfinite(n))) return Eigen::Matrix3d::Constant(n);  // zero, NaN, Inf
  return r.normalized().toRotationMatrix() * (n * n);
}

void BoxTo(const OrientedBox& b, double out[5]) {
  out[0] = b.center.x();
  out[1] = b.center.y();
  out[2] = b.theta;
  out[3] = b.length;
  out[4] = b.width;
}

}  // namespace

LadarScan ScanFromLcm(ladar_scan_t&& msg) {
  LadarScan s;
  s.utime = msg.utime;
  s.seq = msg.seq;
  s.sensor_id = std::move(msg.sensor_id);
  s.body_from_sensor = Eigen::Isometry3d::Identity();
  s.body_from_sensor.linear() = Rotation(msg.sensor_orientation);
  s.body_from_sensor.translation() =
      Eigen::Vector3d(msg.sensor_pos[0], msg.sensor_pos[1], msg.sensor_pos[2]);
  s.sweep_duration_us = msg.sweep_duration_us;
  s.max_range = msg.max_range;
  s.num_rings = msg.num_rings;
  s.x = std::move(msg.x);
  s.y = std::move(msg.y);
  s.z = std::move(msg.z);
  s.intensity = std::move(msg.intensity);
  s.dt_us = std::move(msg.dt_us);
  s.ring = std::move(msg.ring);
  msg.npoints = 0;
  return s;
}

void LendArrays(LadarScan&& spare, ladar_scan_t* msg) {
  msg->x = std::move(spare.x);
  msg->y = std::move(spare.y);
  msg->z = std::move(spare.z);
  msg->intensity = std::move(spare.intensity);
  msg->dt_us = std::move(spare.dt_us);
  msg->ring = std::move(spare.ring);
}

LadarScan ScanFromLcm(lcm_util::AssembledSweep&& sweep) {
  LadarScan s = ScanFromLcm(std::move(sweep.scan));
  for (const lcm_util::AzimuthArc& a : sweep.missing) s.lost_wedges.push_back({a.begin, a.end});
  return s;
}

DetectionList DetectionsFromLcm(const detection_list_t& msg) {
  DetectionList out;
  out.utime = msg.utime;
  out.seq = msg.seq;
  out.boxes.reserve(msg.detections.size());
  for (const detection_t& d : msg.detections) {
    Detection b;
    b.x = d.x;
    b.y = d.y;
    b.z = d.z;
    b.yaw = d.yaw;
    b.length = d.length;
    b.width = d.width;
    b.height = d.height;
    b.score = d.score;
    b.object_class = d.object_class;
    out.boxes.push_back(b);
  }
  return out;
}

EgoPose PoseFromLcm(const pose_t& msg) {
  EgoPose p;
  p.utime = msg.utime;
  p.world_from_body = Eigen::Isometry3d::Identity();
  p.world_from_body.linear() = Rotation(msg.orientation);
  p.world_from_body.translation() = Eigen::Vector3d(msg.pos[0], msg.pos[1], msg.pos[2]);
  return p;
}

track_t TrackToLcm(const TrackReport& r) {
  track_t t;
  t.id = r.id;
  t.status = static_cast<int8_t>(r.status);
  t.model = static_cast<int8_t>(r.model);
  t.moving = r.moving;
  t.object_class = static_cast<int8_t>(r.object_class);
  t.x = r.x;
  t.y = r.y;
  t.theta = r.theta;
  t.speed = r.speed;
  t.velocity_heading = r.velocity_heading;
  t.yaw_rate = r.yaw_rate;
  t.rear_axle_offset = r.rear_axle_offset;
  t.length = r.length;
  t.width = r.width;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) t.cov[3 * i + j] = r.cov(i, j);
  t.num_hypotheses = r.num_hypotheses;
  t.age = r.age;
  t.num_updates = r.num_updates;
  t.score = static_cast<float>(r.score);
  t.vehicle_probability = static_cast<float>(r.vehicle_probability);
  t.z = r.z;
  t.height = r.height;
  t.npred = static_cast<int32_t>(r.prediction.size());
  for (const auto& p : r.prediction) {
    t.pred_t.push_back(static_cast<float>(p.t));
    t.pred_x.push_back(p.pose(0));
    t.pred_y.push_back(p.pose(1));
    t.pred_theta.push_back(static_cast<float>(p.pose(2)));
    t.pred_pos_std.push_back(static_cast<float>(p.pos_std));
  }
  return t;
}

track_list_t TrackListToLcm(const ScanOutput& out, const std::string& mode,
                            std::int64_t latency_us) {
  track_list_t m;
  m.utime = out.utime;
  m.scan_seq = out.seq;
  m.latency_us = latency_us;
  m.mode = mode;
  m.num_tracks = static_cast<int32_t>(out.tracks.size());
  m.tracks.reserve(out.tracks.size());
  for (const auto& r : out.tracks) m.tracks.push_back(TrackToLcm(r));
  return m;
}

track_debug_t DebugToLcm(const ScanOutput& out) {
  track_debug_t m;
  m.utime = out.utime;
  m.scan_seq = out.seq;
  m.num_segments = out.num_segments;
  m.num_entries = static_cast<int32_t>(out.debug.size());
  for (const TrackDebug& d : out.debug) {
    track_debug_entry_t e;
    e.track_id = d.track_id;
    e.fit_kind = static_cast<int8_t>(d.fit_kind);
    for (int i = 0; i < 3; ++i) {
      e.z[i] = d.z(i);
      for (int j = 0; j < 3; ++j) {
        e.R[3 * i + j] = d.R(i, j);
        e.updated_cov[3 * i + j] = d.updated_cov(i, j);
      }
    }
    BoxTo(d.predicted, e.predicted);
    BoxTo(d.updated, e.updated);
    e.visible_faces = static_cast<int8_t>(d.visible_faces);
    for (int i = 0; i < 4; ++i) e.rear_axle[i] = d.rear_axle[static_cast<std::size_t>(i)];
    e.num_edges = static_cast<int32_t>(d.edges.size());
    for (const auto& ed : d.edges) {
      e.edge_x0.push_back(ed[0]);
      e.edge_y0.push_back(ed[1]);
      e.edge_x1.push_back(ed[2]);
      e.edge_y1.push_back(ed[3]);
    }
    e.num_points = static_cast<int32_t>(d.point_x.size());
    e.point_x = d.point_x;
    e.point_y = d.point_y;
    e.point_edge = d.point_edge;
    e.num_hypotheses = static_cast<int32_t>(d.hypotheses.size());
    for (const auto& h : d.hypotheses) {
      hypothesis_t hm;
      hm.index = h.index;
      hm.model = static_cast<int8_t>(h.model);
      hm.selected = h.selected;
      for (int i = 0; i < 6; ++i) {
        hm.state[i] = h.state(i);
        for (int j = 0; j < 6; ++j) hm.cov[6 * i + j] = h.cov(i, j);
      }
      hm.x = h.x;
      hm.y = h.y;
      hm.theta = h.theta;
      hm.rear_axle_offset = h.rear_axle_offset;
      hm.score = h.score;
      hm.nis = h.nis;
      hm.consecutive_misses = h.consecutive_misses;
      hm.inside_fraction = static_cast<float>(h.inside_fraction);
      hm.noise_scale = static_cast<float>(h.noise_scale);
      e.hypotheses.push_back(hm);
    }
    m.entries.push_back(std::move(e));
  }
  return m;
}

}  // namespace vtrack
