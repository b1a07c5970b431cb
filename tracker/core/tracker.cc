#include "tracker/core/tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "tracker/core/angle.h"

namespace vtrack {
namespace {

std::string Str(std::int64_t v) { return std::to_string(v); }

// The bin of a contour key bin * 2^32 + range^2 (range^2 < 2^32, bin of either sign).
std::int64_t FloorDiv32(std::int64_t key) {
  return key >= 0 ? key / (std::int64_t{1} << 32) : -((-key + (std::int64_t{1} << 32) - 1) / (std::int64_t{1} << 32));
}

}  // namespace

bool InputParams::Validate(std::string* error) const {
  auto check = [&](bool ok, const char* field, double value, const char* unit, const char* req) {
    return internal::CheckParam(ok, "input", field, value, unit, req, error);
  };
  return check(max_pose_wait_us >= 0, "max_pose_wait_us", static_cast<double>(max_pose_wait_us),
               "us", ">= 0") &&
         check(max_extrapolation_us >= 0, "max_extrapolation_us",
               static_cast<double>(max_extrapolation_us), "us", ">= 0") &&
         check(time_jump_reset_us > 0, "time_jump_reset_us",
               static_cast<double>(time_jump_reset_us), "us", "> 0") &&
         check(max_queued_scans >= 1, "max_queued_scans", max_queued_scans, "", ">= 1") &&
         check(pose_history_us >= 1'000'000, "pose_history_us",
               static_cast<double>(pose_history_us), "us", ">= 1000000") &&
         check(max_sweep_duration_us > 0, "max_sweep_duration_us",
               static_cast<double>(max_sweep_duration_us), "us", "> 0");
}

bool TrackerParams::Validate(std::string* error) const {
  auto local = [&](const std::string& e) {
    if (!e.empty() && error) *error = e;
    return e.empty();
  };
  return input.Validate(error) && local(preprocess.FirstProblem()) &&
         local(segmentation.FirstProblem()) && local(association.FirstProblem()) &&
         fit.Validate(error) && ism.Validate(error) && vasm.Validate(error) &&
         ekf.Validate(error) && shape.Validate(error) && manager.Validate(error);
}

Tracker::Tracker(const TrackerParams& params, bool debug)
    : params_(params),
      debug_(debug),
      preprocessor_(params.preprocess),
      segmenter_(params.segmentation),
      associator_(params.association),
      poses_(params.input.pose_history_us) {
  std::string error;
  if (!params_.Validate(&error)) throw std::invalid_argument(error);
  ekf_ = std::make_unique<Ekf>(params_.ism, params_.vasm, params_.ekf);
  manager_ = std::make_unique<TrackManager>(params_.manager, *ekf_, params_.fit, params_.shape);
}

std::vector<TrackerEvent> Tracker::TakeEvents() {
  std::vector<TrackerEvent> e;
  e.swap(events_);
  return e;
}

void Tracker::Reject(const std::string& reason, std::int64_t count, const std::string& message) {
  if (count <= 0) return;
  rejects_[reason] += count;
  if (events_.size() < 1000) events_.push_back({reason, message});
}

void Tracker::Reset(const std::string& why) {
  ++resets_;
  scans_dropped_ += static_cast<std::int64_t>(queue_.size());
  queue_.clear();
  poses_.Clear();
  manager_->Clear();
  have_scan_ = false;
  have_time_ = false;
  have_seq_ = false;
  events_.push_back({"reset", "tracker reset: " + why});
}

// Detects a jump back in message time (a looped log) and resets; returns true if it did.
bool Tracker::CheckTime(std::int64_t utime, const char* what) {
  if (have_time_ && utime < latest_utime_ - params_.input.time_jump_reset_us) {
    Reset(std::string(what) + " time jumped back by " +
          Str((latest_utime_ - utime) / 1000) + " ms (looped log?)");
    latest_utime_ = utime;
    have_time_ = true;
    return true;
  }
  // A jump forward longer than any track may coast (a clock step, a log that skips ahead): no
  // track can survive it, and predicting them across it would only let stale tracks (with huge
  // covariances) catch the new returns.
  const std::int64_t forward_us = std::max(
      params_.input.time_jump_reset_us,
      static_cast<std::int64_t>(
          std::max(params_.manager.coast_max_s, params_.manager.parked_coast_max_s) * 1e6));
  if (have_time_ && utime > latest_utime_ + forward_us) {
    Reset(std::string(what) + " time jumped forward by " + Str((utime - latest_utime_) / 1000) + " ms");
    latest_utime_ = utime;
    have_time_ = true;
    return true;
  }
  if (!have_time_ || utime > latest_utime_) latest_utime_ = utime;
  have_time_ = true;
  return false;
}

void Tracker::AddPose(const EgoPose& pose, std::vector<ScanOutput>* out) {
  ++poses_received_;
  const Eigen::Matrix4d& m = pose.world_from_body.matrix();
  const Eigen::Matrix3d R = pose.world_from_body.linear();
  if (!m.allFinite() || (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-3) {
    Reject("invalid_pose", 1, "pose at " + Str(pose.utime) + " is not finite or not a rotation");
    return;
  }
  CheckTime(pose.utime, "pose");
  switch (poses_.Add(pose.utime, pose.world_from_body)) {
    case PoseHistory::AddResult::kOk: break;
    case PoseHistory::AddResult::kDuplicate:
      Reject("pose_repeated", 1, "pose at " + Str(pose.utime) + " repeats the previous time");
      return;
    case PoseHistory::AddResult::kOutOfOrder:
      Reject("pose_out_of_order", 1,
             "pose at " + Str(pose.utime) + " is older than " + Str(poses_.newest_utime()));
      return;
  }
  ProcessReady(false, out);
}

void Tracker::AddScan(LadarScan&& scan, std::vector<ScanOutput>* out) {
  ++scans_received_;
  // Scans lost on the way (LCM drops a datagram, or a fragmented message with a fragment
  // missing, without a word) show as gaps in the sensor's seq: counted as "scan_seq_gap", one per
  // missing scan. A jump of more than kMaxSeqGap is a renumbered sensor, not loss.
  constexpr std::uint64_t kMaxSeqGap = 100'000;
  if (have_seq_ && scan.seq > last_seq_) {
    const std::uint64_t gap = static_cast<std::uint64_t>(scan.seq) - static_cast<std::uint64_t>(last_seq_) - 1;
    if (gap > 0 && gap <= kMaxSeqGap) {
      Reject("scan_seq_gap", static_cast<std::int64_t>(gap),
             Str(static_cast<std::int64_t>(gap)) + " scans missing before scan " + Str(scan.seq));
    }
  }
  if (!have_seq_ || scan.seq > last_seq_) last_seq_ = scan.seq;
  have_seq_ = true;
  const std::size_t n = scan.x.size();
  auto drop = [&](const char* reason, const std::string& msg) {
    ++scans_dropped_;
    Reject(reason, 1, "scan " + Str(scan.seq) + " at " + Str(scan.utime) + ": " + msg);
  };
  if (scan.y.size() != n || scan.z.size() != n ||
      (!scan.dt_us.empty() && scan.dt_us.size() != n) ||
      (!scan.ring.empty() && scan.ring.size() != n)) {
    return drop("bad_scan", "arrays of different lengths");
  }
  if (scan.sweep_duration_us < 0 || scan.sweep_duration_us > params_.input.max_sweep_duration_us) {
    return drop("bad_scan", "sweep_duration_us " + Str(scan.sweep_duration_us) + " out of range");
  }
  if (!scan.body_from_sensor.matrix().allFinite()) {
    return drop("bad_scan", "mounting pose is not finite");
  }
  const Eigen::Matrix3d mount = scan.body_from_sensor.linear();
  if ((mount.transpose() * mount - Eigen::Matrix3d::Identity()).norm() > 1e-3) {
    return drop("bad_scan", "mounting orientation is not a rotation");
  }
  if (n == 0) return drop("empty_scan", "no returns");
  if (static_cast<std::int64_t>(n) > params_.preprocess.max_points) {
    return drop("huge_scan", Str(static_cast<std::int64_t>(n)) + " returns > max_points " +
                                 Str(params_.preprocess.max_points));
  }
  CheckTime(scan.utime, "scan");
  if (have_scan_ && scan.utime <= last_scan_utime_) {
    return drop(scan.utime == last_scan_utime_ ? "scan_repeated" : "scan_out_of_order",
                "not after the previous scan at " + Str(last_scan_utime_));
  }
  last_scan_utime_ = scan.utime;
  have_scan_ = true;
  if (static_cast<int>(queue_.size()) >= params_.input.max_queued_scans) {
    ++scans_dropped_;
    Reject("scan_overrun", 1, "scan queue full (no pose for " + Str(queue_.size()) +
                                  " scans): dropped scan at " + Str(queue_.front().utime));
    queue_.pop_front();
  }
  queue_.push_back(std::move(scan));
  ProcessReady(false, out);
}

void Tracker::Flush(std::vector<ScanOutput>* out) { ProcessReady(true, out); }

void Tracker::ProcessReady(bool flush, std::vector<ScanOutput>* out) {
  while (!queue_.empty()) {
    const LadarScan& s = queue_.front();
    const bool ready = !poses_.empty() && poses_.newest_utime() >= s.end_utime();
    const bool forced = flush || latest_utime_ >= s.end_utime() + params_.input.max_pose_wait_us;
    if (!ready && !forced) break;
    ScanOutput o;
    if (Process(s, !ready, &o)) {
      ++scans_processed_;
      out->push_back(std::move(o));
    } else {
      ++scans_dropped_;
    }
    queue_.pop_front();
  }
}

bool Tracker::Process(const LadarScan& scan, bool forced, ScanOutput* out) {
  const PreprocessResult pre = preprocessor_.Run(
      scan, poses_, forced ? params_.input.max_extrapolation_us : 0, &points_);
  const std::string at = "scan " + Str(scan.seq) + " at " + Str(scan.utime);
  if (pre.status == CompensationStatus::kNoPose) {
    const bool stale = pre.failed_lookup == PoseHistory::LookupStatus::kTooFarAhead;
    Reject(stale ? "stale_pose" : "pose_missing", 1,
           at + (stale ? ": newest pose at " + Str(poses_.newest_utime()) + " is too old"
                       : ": no pose covers the sweep"));
    return false;
  }
  if (pre.status == CompensationStatus::kExtrapolated) {
    Reject("pose_extrapolated", 1, at + ": pose extrapolated past " + Str(poses_.newest_utime()));
  }
  Reject("nan_point", pre.stats.nonfinite, at + ": " + Str(pre.stats.nonfinite) + " NaN/Inf returns dropped");
  Reject("bad_point_time", pre.stats.bad_time,
         at + ": " + Str(pre.stats.bad_time) + " returns with dt_us outside the sweep dropped");
  out->utime = scan.utime;
  out->seq = scan.seq;
  out->stats = pre.stats;

  segmenter_.Run(points_, scan.num_rings <= 1, pre.sensor_xy, &segments_);
  JoinGrazingPieces(points_, pre.sensor_xy, params_.association, &segments_);
  const std::int64_t mid = scan.utime + scan.sweep_duration_us / 2;
  manager_->Predict(mid, &predicted_);
  associator_.Run(predicted_, points_, segments_, pre.sensor_xy, &association_);
  out->num_segments = static_cast<std::int32_t>(segments_.segments.size());

  const bool multi_ring = scan.num_rings > 1;
  auto fill = [&](const std::vector<std::int32_t>& idx) {
    PointSet& ps = point_set_;
    ps.x.resize(idx.size());
    ps.y.resize(idx.size());
    const std::size_t i0 = static_cast<std::size_t>(idx.front());
    ps.origin = Eigen::Vector2d(std::round(points_.x[i0]), std::round(points_.y[i0]));
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector2d hi = -lo;
    double dt_sum = 0.0;
    const bool has_dt = scan.dt_us.size() == scan.size();
    for (std::size_t k = 0; k < idx.size(); ++k) {
      const auto i = static_cast<std::size_t>(idx[k]);
      const Eigen::Vector2d p(points_.x[i], points_.y[i]);
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
      ps.x[k] = static_cast<float>(p.x() - ps.origin.x());
      ps.y[k] = static_cast<float>(p.y() - ps.origin.y());
      if (has_dt) dt_sum += scan.dt_us[static_cast<std::size_t>(points_.index[i])];
    }
    ps.extent = (hi - lo).norm();
    ps.outline = multi_ring && params_.manager.fit_contour_deg > 0.0;
    ps.mean_utime = scan.utime + static_cast<std::int64_t>(std::llround(dt_sum / idx.size()));
    // The outline the sensor sees: per bearing bin (fit_contour_deg, seen from the sensor) the
    // nearest return. A 3-D cloud also holds roofs, windows and returns stacked in columns;
    // the edge / corner fit (Section 2.4) wants the visible outline, as a single-plane scanner
    // gives it. It also bounds the fit's cost.
    const double res = DegToRad(params_.manager.fit_contour_deg);
    if (res > 0.0 && ps.x.size() > 1) {
      const Eigen::Vector2d s = pre.sensor_xy - ps.origin;
      const Eigen::Vector2d mid = 0.5 * (lo + hi) - ps.origin - s;
      const Eigen::Vector2d ref = mid.normalized();
      // Bins uniform in tan(bearing - ref) (no atan2 per return; within +-30 deg of the
      // segment's middle, as wide as res to within 33%); the key orders by bin, then range^2.
      const double inv_res = 1.0 / std::tan(res);
      thin_.clear();
      for (std::size_t k = 0; k < ps.x.size(); ++k) {
        const double dx = ps.x[k] - s.x(), dy = ps.y[k] - s.y();
        const double u = dx * ref.x() + dy * ref.y(), w = -dx * ref.y() + dy * ref.x();
        const double t = u > 1e-6 ? w / u : (w >= 0 ? 1e6 : -1e6);
        const auto bin = static_cast<std::int64_t>(std::floor(std::clamp(t, -1e6, 1e6) * inv_res));
        const auto r2 = static_cast<std::int64_t>((dx * dx + dy * dy) * 1e4);  // [cm^2]
        thin_.emplace_back(bin * (std::int64_t{1} << 32) + r2, static_cast<std::int32_t>(k));
      }
      std::sort(thin_.begin(), thin_.end());
      // 3-D clouds: the outline takes, per bin, the nearest return that stands on a vertical
      // face: another return of the bin lies within support_range of its range at a height
      // differing by support_height or more. A ring that grazes a horizontal surface (a roof,
      // a bonnet) hits it at a fixed distance from the sensor, so those returns move with the
      // ego vehicle; fitted as an edge they make a parked car look like a mover. Faces are hit
      // by several rings at nearly the same range.
      //
      // Unless no bin of the segment has such support and its returns lie at ranges spread over
      // more than contour_arc_span: one ring seen over something nearer (the roof line of a car
      // behind another), which a grazed roof or bonnet, at one range, cannot give. Then the
      // nearest return per bin.
      const double support_r2 = params_.manager.contour_support_range;
      auto range_of = [&](std::size_t a) {
        return std::sqrt(static_cast<double>(thin_[a].first - FloorDiv32(thin_[a].first) * (std::int64_t{1} << 32)) * 1e-4);
      };
      thin_x_.clear();
      thin_y_.clear();
      auto outline = [&](double support_h) {
      std::size_t k = 0;
      while (k < thin_.size()) {
        std::size_t end = k + 1;
        while (end < thin_.size() && FloorDiv32(thin_[end].first) == FloorDiv32(thin_[k].first)) ++end;
        std::size_t pick = k;
        if (support_h > 0.0) {
          pick = end;
          for (std::size_t a = k; a < end && pick == end; ++a) {
            const double ra = range_of(a);
            const float ha = points_.height[static_cast<std::size_t>(idx[static_cast<std::size_t>(thin_[a].second)])];
            for (std::size_t b = k; b < end; ++b) {
              if (b == a) continue;
              const double rb = range_of(b);
              if (rb > ra + support_r2) break;  // sorted by range
              const float hb = points_.height[static_cast<std::size_t>(idx[static_cast<std::size_t>(thin_[b].second)])];
              if (std::abs(rb - ra) <= support_r2 && std::abs(hb - ha) >= support_h) {
                pick = a;
                break;
              }
            }
          }
        }
        if (pick < end) {
          const auto src = static_cast<std::size_t>(thin_[pick].second);
          thin_x_.push_back(ps.x[src]);
          thin_y_.push_back(ps.y[src]);
        }
        k = end;
      }
      };
      outline(multi_ring ? params_.manager.contour_support_height : 0.0);
      if (thin_x_.empty() && multi_ring && params_.manager.contour_support_height > 0.0) {
        // The span of one ring: rings grazing a bonnet and a roof hit them at different ranges,
        // each at its own one range.
        ring_span_.clear();
        double span = 0.0;
        for (std::size_t a = 0; a < thin_.size(); ++a) {
          const auto i = static_cast<std::size_t>(idx[static_cast<std::size_t>(thin_[a].second)]);
          const std::int16_t ring = points_.ring[i];
          const double r = range_of(a);
          auto it = std::find_if(ring_span_.begin(), ring_span_.end(),
                                 [&](const RingSpan& e) { return e.ring == ring; });
          if (it == ring_span_.end()) {
            ring_span_.push_back({ring, r, r});
          } else {
            it->lo = std::min(it->lo, r);
            it->hi = std::max(it->hi, r);
            span = std::max(span, it->hi - it->lo);
          }
        }
        if (span >= params_.manager.contour_arc_span) outline(0.0);
      }
      ps.x.assign(thin_x_.begin(), thin_x_.end());
      ps.y.assign(thin_y_.begin(), thin_y_.end());
    }
  };
  // Seeds for RANSAC: a function of the scan and the track only, so reruns are identical.
  auto seed_of = [&](std::int64_t salt) {
    return static_cast<std::uint64_t>(scan.utime) * 0x9E3779B97F4A7C15ull ^
           static_cast<std::uint64_t>(salt) * 0xC2B2AE3D27D4EB4Full;
  };
  // 3-D clouds only: a single-plane scanner's bearing spacing (0.5 deg or more) leaves bins of
  // the profile empty between its returns, which would read as free space beyond a face's end.
  if (multi_ring) {
    profile_.Build(pre.sensor_xy, points_.x, points_.y, points_.ring,
                   std::max(0.05, params_.manager.fit_contour_deg));
  }
  const std::size_t num_tracks = manager_->tracks().size();
  for (std::size_t j = 0; j < num_tracks; ++j) {
    const auto& idx = association_.track_points[j];
    if (idx.empty()) {
      manager_->Miss(j);
      continue;
    }
    fill(idx);
    if (point_set_.size() == 0) {  // only returns off vertical faces (roofs): nothing to fit
      manager_->Miss(j);
      continue;
    }
    TrackDebug dbg;
    manager_->Update(j, point_set_, pre.sensor_xy, seed_of(manager_->tracks()[j].id),
                     debug_ ? &dbg : nullptr, multi_ring ? &profile_ : nullptr);
    if (debug_) out->debug.push_back(std::move(dbg));
  }
  // New tracks, rectangles before small objects, each group largest first; a segment mostly
  // inside the rectangle of a track just created from this scan is part of that object (a face
  // cut off by a range jump), not a new one. A car's end face seen edge-on at 30-40 m is a piece
  // of a few returns beside its side, and may hold more returns than the side: created first,
  // it became a second track of the car (measured by centroid, 2 m from the car's centre), which
  // grew into a rectangle a few scans later and replaced the car's track (an identity switch).
  auto& objs = association_.new_objects;
  {
    std::vector<std::pair<std::pair<bool, std::size_t>, std::size_t>> order(objs.size());
    for (std::size_t k = 0; k < objs.size(); ++k) {
      Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
      Eigen::Vector2d hi = -lo;
      for (const std::int32_t i : objs[k]) {
        const Eigen::Vector2d p(points_.x[static_cast<std::size_t>(i)], points_.y[static_cast<std::size_t>(i)]);
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
      const bool small = objs[k].empty() || (hi - lo).norm() < params_.manager.small_object_extent;
      order[k] = {{small, objs[k].size()}, k};
    }
    std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) {
      if (a.first.first != b.first.first) return !a.first.first;  // rectangles first
      return a.first.second > b.first.second;
    });
    std::vector<std::vector<std::int32_t>> sorted(objs.size());
    for (std::size_t k = 0; k < order.size(); ++k) sorted[k] = std::move(objs[order[k].second]);
    objs.swap(sorted);
  }
  created_.clear();
  // World bounding box of each created rectangle grown by gate_margin (plus 1 mm for rounding):
  // a segment whose bounding box misses it has no return inside, so is not tested return by
  // return (the loop is objects x created x returns).
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> created_bounds;
  for (std::size_t k = 0; k < objs.size(); ++k) {
    const auto& idx = objs[k];
    if (idx.empty()) continue;
    bool part_of_new = false;
    Eigen::Vector2d obj_lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector2d obj_hi = -obj_lo;
    if (!created_.empty()) {
      for (const std::int32_t i : idx) {
        const Eigen::Vector2d p(points_.x[static_cast<std::size_t>(i)], points_.y[static_cast<std::size_t>(i)]);
        obj_lo = obj_lo.cwiseMin(p);
        obj_hi = obj_hi.cwiseMax(p);
      }
    }
    for (std::size_t c = 0; c < created_.size(); ++c) {
      const OrientedBox& b = created_[c];
      const auto& [box_lo, box_hi] = created_bounds[c];
      if ((obj_lo.array() > box_hi.array()).any() || (obj_hi.array() < box_lo.array()).any()) continue;
      std::size_t inside = 0;
      for (const std::int32_t i : idx) {
        inside += b.Contains({points_.x[static_cast<std::size_t>(i)], points_.y[static_cast<std::size_t>(i)]},
                             params_.association.gate_margin);
      }
      if (inside >= params_.association.merge_fraction * static_cast<double>(idx.size())) {
        part_of_new = true;
        break;
      }
    }
    if (part_of_new) continue;
    fill(idx);
    if (point_set_.size() == 0) continue;
    if (manager_->Create(point_set_, pre.sensor_xy, seed_of(-1 - static_cast<std::int64_t>(k)))) {
      const OrientedBox b = manager_->Box(manager_->tracks().size() - 1);
      created_.push_back(b);
      const double c = std::abs(std::cos(b.theta)), sn = std::abs(std::sin(b.theta));
      const double hl = 0.5 * b.length + params_.association.gate_margin;
      const double hw = 0.5 * b.width + params_.association.gate_margin;
      const Eigen::Vector2d half(c * hl + sn * hw + 1e-3, sn * hl + c * hw + 1e-3);
      created_bounds.emplace_back(b.center - half, b.center + half);
    }
  }
  manager_->EndScan(scan.utime);
  manager_->Report(scan.utime, &out->tracks);
  return true;
}

}  // namespace vtrack
