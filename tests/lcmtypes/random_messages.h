// Messages filled with seeded random, non-trivial content, for round-trip and bus tests.
#pragma once

#include <random>

#include "tests/support/encode.h"
#include "vtrack/detection_list_t.hpp"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/object_list_t.hpp"
#include "vtrack/pose_t.hpp"
#include "vtrack/track_debug_t.hpp"
#include "vtrack/track_list_t.hpp"
#include "vtrack/tracker_status_t.hpp"

namespace vtrack::testing {

class RandomMessages {
 public:
  explicit RandomMessages(unsigned seed) : rng_(seed) {}

  double D(double lo = -100, double hi = 100) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
  float F(double lo = -100, double hi = 100) { return static_cast<float>(D(lo, hi)); }
  int I(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }

  pose_t Pose() {
    pose_t m{};
    m.utime = 1'600'000'000'000'000LL + I(0, 1'000'000);
    for (int i = 0; i < 3; ++i) {
      m.pos[i] = D(); m.vel[i] = D(-20, 20); m.rotation_rate[i] = D(-1, 1);
      m.accel[i] = D(-5, 5); m.pos_std[i] = D(0, 1);
    }
    m.orientation[0] = 1; m.orientation[1] = D(-0.1, 0.1); m.orientation[2] = D(-0.1, 0.1); m.orientation[3] = D(-1, 1);
    m.yaw_std = D(0, 0.1);
    return m;
  }

  ladar_scan_t Scan(int npoints) {
    ladar_scan_t m{};
    m.utime = 1'600'000'000'000'000LL + I(0, 1'000'000);
    m.seq = I(0, 1 << 30);
    m.sensor_id = "velodyne_hdl64";
    m.sensor_pos[0] = 0.8; m.sensor_pos[2] = 1.73;
    m.sensor_orientation[0] = 1;
    m.sweep_duration_us = 100000; m.max_range = 120; m.num_rings = 64;
    m.npoints = npoints;
    m.x.resize(npoints); m.y.resize(npoints); m.z.resize(npoints); m.intensity.resize(npoints);
    m.dt_us.resize(npoints); m.ring.resize(npoints);
    for (int i = 0; i < npoints; ++i) {
      m.x[i] = F(); m.y[i] = F(); m.z[i] = F(-3, 3); m.intensity[i] = F(0, 1);
      m.dt_us[i] = I(0, 100000); m.ring[i] = static_cast<int16_t>(I(0, 63));
    }
    return m;
  }

  object_t Object(int64_t id) {
    object_t o{};
    o.id = id; o.object_class = object_t::CLASS_CAR;
    o.x = D(); o.y = D(); o.z = D(-1, 1); o.yaw = D(-3, 3); o.length = D(3, 6); o.width = D(1.5, 2.2);
    o.height = D(1.3, 2); o.vx = D(-15, 15); o.vy = D(-15, 15); o.speed = D(-5, 15);
    o.yaw_rate = D(-0.5, 0.5); o.rear_axle_offset = D(-2, 0); o.moving = true;
    o.in_labelled_region = I(0, 1) == 1; o.num_points = I(-1, 500);
    return o;
  }

  object_list_t ObjectList(int n) {
    object_list_t m{};
    m.utime = 1'600'000'000'000'000LL + I(0, 1'000'000);
    m.scan_seq = I(0, 1000); m.source = "sim:test"; m.num_objects = n;
    for (int i = 0; i < n; ++i) m.objects.push_back(Object(i));
    return m;
  }

  track_t Track(int64_t id, int npred) {
    track_t t{};
    t.id = id; t.status = track_t::STATUS_CONFIRMED; t.model = track_t::MODEL_VASM; t.moving = true;
    t.object_class = track_t::CLASS_VEHICLE; t.x = D(); t.y = D(); t.theta = D(-3, 3); t.speed = D(0, 15);
    t.velocity_heading = D(-3, 3); t.yaw_rate = D(-1, 1); t.rear_axle_offset = D(-2, 2);
    t.length = D(3, 6); t.width = D(1.5, 2.5);
    for (double& c : t.cov) c = D(-1, 1);
    t.num_hypotheses = I(1, 4); t.age = D(0, 100); t.num_updates = I(0, 1000); t.score = static_cast<float>(D(-5, 20));
    t.z = D(-3, 1); t.height = D(1, 3);
    t.npred = npred;
    for (int i = 0; i < npred; ++i) {
      t.pred_t.push_back(0.1f * i); t.pred_x.push_back(D()); t.pred_y.push_back(D());
      t.pred_theta.push_back(F(-3, 3)); t.pred_pos_std.push_back(F(0, 3));
    }
    return t;
  }

  track_list_t TrackList(int n) {
    track_list_t m{};
    m.utime = 1'600'000'000'000'000LL + I(0, 1'000'000);
    m.scan_seq = I(0, 1000); m.latency_us = I(0, 10000); m.mode = "mht"; m.num_tracks = n;
    for (int i = 0; i < n; ++i) m.tracks.push_back(Track(i, I(0, 31)));
    return m;
  }

  hypothesis_t Hypothesis(int index) {
    hypothesis_t h{};
    h.index = index; h.model = static_cast<int8_t>(I(0, 1)); h.selected = index == 0;
    for (double& s : h.state) s = D();
    for (double& c : h.cov) c = D();
    h.x = D(); h.y = D(); h.theta = D(-3, 3); h.rear_axle_offset = D(-2, 2); h.score = D(0, 10);
    h.nis = D(0, 20); h.consecutive_misses = I(0, 5); h.inside_fraction = F(0, 1); h.noise_scale = F(0.5, 4);
    return h;
  }

  track_debug_t Debug(int n) {
    track_debug_t m{};
    m.utime = 1'600'000'000'000'000LL; m.scan_seq = 7; m.num_segments = I(0, 100); m.num_entries = n;
    for (int k = 0; k < n; ++k) {
      track_debug_entry_t e{};
      e.track_id = k; e.fit_kind = track_debug_entry_t::FIT_CORNER;
      for (double& v : e.z) v = D();
      for (double& v : e.R) v = D();
      for (double& v : e.predicted) v = D();
      for (double& v : e.updated) v = D();
      for (double& v : e.updated_cov) v = D();
      e.visible_faces = 5;
      for (double& v : e.rear_axle) v = D();
      e.num_edges = I(0, 2);
      for (int i = 0; i < e.num_edges; ++i) {
        e.edge_x0.push_back(D()); e.edge_y0.push_back(D()); e.edge_x1.push_back(D()); e.edge_y1.push_back(D());
      }
      e.num_points = I(0, 300);
      for (int i = 0; i < e.num_points; ++i) {
        e.point_x.push_back(F()); e.point_y.push_back(F()); e.point_edge.push_back(static_cast<int8_t>(I(-1, 1)));
      }
      e.num_hypotheses = I(1, 4);
      for (int i = 0; i < e.num_hypotheses; ++i) e.hypotheses.push_back(Hypothesis(i));
      m.entries.push_back(e);
    }
    return m;
  }

  detection_t Detection() {
    detection_t d{};
    d.object_class = static_cast<int8_t>(I(0, 3)); d.score = F(-2, 20);
    d.x = D(-80, 80); d.y = D(-80, 80); d.z = D(-3, 1); d.yaw = D(-3, 3);
    d.length = D(3, 6); d.width = D(1.5, 2.5); d.height = D(1.3, 2.2);
    return d;
  }

  detection_list_t DetectionList(int n) {
    detection_list_t m{};
    m.utime = 1'600'000'000'000'000LL + I(0, 1'000'000);
    m.seq = I(0, 1000); m.source = "pointrcnn"; m.num_detections = n;
    for (int i = 0; i < n; ++i) m.detections.push_back(Detection());
    return m;
  }

  tracker_status_t Status() {
    tracker_status_t m{};
    m.utime = 1'600'000'000'000'000LL; m.wall_utime = m.utime + 5; m.mode = "ism";
    m.scans_received = 100; m.scans_processed = 98; m.scans_dropped = 2; m.poses_received = 1000;
    m.decode_errors = 1; m.resets = 1;
    const char* reasons[] = {"nan_point", "empty_scan", "stale_pose"};
    m.num_reasons = 3;
    for (int i = 0; i < 3; ++i) { m.reject_reason.push_back(reasons[i]); m.reject_count.push_back(I(0, 50)); }
    m.last_latency_ms = D(0, 5); m.median_latency_ms = D(0, 5);
    m.tracks_tentative = 3; m.tracks_confirmed = 10; m.tracks_coasting = 1;
    return m;
  }

 private:
  std::mt19937_64 rng_;
};

}  // namespace vtrack::testing
