#include "tracker/core/tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "tracker/core/angle.h"
#include "tracker/core/grazing_pieces.h"

namespace vtrack {
namespace {

std::string Str(std::int64_t v) { return std::to_string(v); }

// The range profile's finest bearing bin: 7200 bins per ring.
constexpr double kMinProfileBinDeg = 0.05;  // [deg]

// The seed of the RANSAC fits of one track (salt: its id; a new object: -1 - its index): a
// function of the scan and the track only, so that reruns are identical.
std::uint64_t RansacSeed(std::int64_t scan_utime, std::int64_t salt) {
  return static_cast<std::uint64_t>(scan_utime) * 0x9E3779B97F4A7C15ull ^
         static_cast<std::uint64_t>(salt) * 0xC2B2AE3D27D4EB4Full;
}

// The longest any track may coast: beyond, a jump forward in time resets the tracker.
std::int64_t MaxCoastUs(const TrackManagerParams& m) {
  return static_cast<std::int64_t>(std::max(m.coast_max_s, m.parked_coast_max_s) * 1e6);
}

OutlineParams OutlineParamsOf(const TrackManagerParams& m) {
  return {m.fit_contour_deg, m.contour_support_height, m.contour_support_range, m.contour_arc_span};
}

GrazingJoinParams GrazingJoinParamsOf(const AssociationParams& a) {
  return {a.join_max_piece, a.join_max_gap, a.join_max_deg, a.join_max_extent};
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
      sequencer_(params.input, MaxCoastUs(params.manager), params.preprocess.max_points, &rejects_),
      preprocessor_(params.preprocess),
      segmenter_(params.segmentation),
      associator_(params.association),
      outline_(OutlineParamsOf(params.manager)),
      created_(params.association) {
  std::string error;
  if (!params_.Validate(&error)) throw std::invalid_argument(error);
  ekf_ = std::make_unique<Ekf>(params_.ism, params_.vasm, params_.ekf);
  manager_ = std::make_unique<TrackManager>(params_.manager, *ekf_, params_.fit, params_.shape);
}

void Tracker::AddPose(const EgoPose& pose, std::vector<ScanOutput>* out) {
  const ScanSequencer::Admission a = sequencer_.AddPose(pose);
  if (a.reset) manager_->Clear();
  if (a.accepted) ProcessReady(false, out);
}

void Tracker::AddScan(LadarScan&& scan, std::vector<ScanOutput>* out) {
  const ScanSequencer::Admission a = sequencer_.AddScan(std::move(scan));
  if (a.reset) manager_->Clear();
  if (a.accepted) ProcessReady(false, out);
}

void Tracker::Flush(std::vector<ScanOutput>* out) { ProcessReady(true, out); }

void Tracker::ProcessReady(bool flush, std::vector<ScanOutput>* out) {
  bool extrapolate = false;
  while (const LadarScan* scan = sequencer_.Ready(flush, &extrapolate)) {
    ScanOutput o;
    const bool processed = Process(*scan, extrapolate, &o);
    if (processed) out->push_back(std::move(o));
    sequencer_.Done(processed);
  }
}

bool Tracker::Process(const LadarScan& scan, bool extrapolate, ScanOutput* out) {
  // Compensation and ground.
  PreprocessResult pre;
  if (!Preprocess(scan, extrapolate, &pre)) return false;
  out->utime = scan.utime;
  out->seq = scan.seq;
  out->stats = pre.stats;
  // Segmentation, then the pieces of faces seen at a grazing angle joined.
  segmenter_.Run(points_, scan.num_rings <= 1, pre.sensor_xy, &segments_);
  JoinGrazingPieces(points_, pre.sensor_xy, GrazingJoinParamsOf(params_.association), &segments_);
  out->num_segments = static_cast<std::int32_t>(segments_.segments.size());
  // Association with the tracks predicted to the middle of the sweep.
  manager_->Predict(scan.utime + scan.sweep_duration_us / 2, &predicted_);
  associator_.Run(predicted_, points_, segments_, pre.sensor_xy, &association_);
  // Each track updated with its returns; new tracks from what is left; life cycle; report.
  UpdateTracks(scan, pre.sensor_xy, out);
  CreateTracks(scan, pre.sensor_xy);
  manager_->EndScan(scan.utime);
  manager_->Report(scan.utime, &out->tracks);
  return true;
}

bool Tracker::Preprocess(const LadarScan& scan, bool extrapolate, PreprocessResult* pre) {
  const PoseHistory& poses = sequencer_.poses();
  *pre = preprocessor_.Run(scan, poses, extrapolate ? params_.input.max_extrapolation_us : 0,
                           &points_);
  const std::string at = "scan " + Str(scan.seq) + " at " + Str(scan.utime);
  if (pre->status == CompensationStatus::kNoPose) {
    const bool stale = pre->failed_lookup == PoseHistory::LookupStatus::kTooFarAhead;
    rejects_.Count(stale ? "stale_pose" : "pose_missing", 1,
                   at + (stale ? ": newest pose at " + Str(poses.newest_utime()) + " is too old"
                               : ": no pose covers the sweep"));
    return false;
  }
  if (pre->status == CompensationStatus::kExtrapolated) {
    rejects_.Count("pose_extrapolated", 1, at + ": pose extrapolated past " + Str(poses.newest_utime()));
  }
  rejects_.Count("nan_point", pre->stats.nonfinite,
                 at + ": " + Str(pre->stats.nonfinite) + " NaN/Inf returns dropped");
  rejects_.Count("bad_point_time", pre->stats.bad_time,
                 at + ": " + Str(pre->stats.bad_time) + " returns with dt_us outside the sweep dropped");
  return true;
}

void Tracker::UpdateTracks(const LadarScan& scan, const Eigen::Vector2d& sensor_xy,
                           ScanOutput* out) {
  // 3-D clouds only: a single-plane scanner's bearing spacing (0.5 deg or more) leaves bins of
  // the profile empty between its returns, which would read as free space beyond a face's end.
  const bool multi_ring = scan.num_rings > 1;
  if (multi_ring) {
    profile_.Build(sensor_xy, points_.x, points_.y, points_.ring,
                   std::max(kMinProfileBinDeg, params_.manager.fit_contour_deg));
  }
  const std::size_t num_tracks = manager_->tracks().size();
  for (std::size_t j = 0; j < num_tracks; ++j) {
    const auto& idx = association_.track_points[j];
    if (idx.empty()) {
      manager_->Miss(j);
      continue;
    }
    outline_.Extract(points_, idx, scan, sensor_xy, &point_set_);
    if (point_set_.size() == 0) {  // only returns off vertical faces (roofs): nothing to fit
      manager_->Miss(j);
      continue;
    }
    TrackDebug dbg;
    manager_->Update(j, point_set_, sensor_xy, RansacSeed(scan.utime, manager_->tracks()[j].id),
                     debug_ ? &dbg : nullptr, multi_ring ? &profile_ : nullptr);
    if (debug_) out->debug.push_back(std::move(dbg));
  }
}

void Tracker::CreateTracks(const LadarScan& scan, const Eigen::Vector2d& sensor_xy) {
  auto& objs = association_.new_objects;
  OrderNewObjects(points_, params_.manager.small_object_extent, &objs);
  created_.Clear();
  for (std::size_t k = 0; k < objs.size(); ++k) {
    const auto& idx = objs[k];
    if (idx.empty() || created_.Holds(points_, idx)) continue;
    outline_.Extract(points_, idx, scan, sensor_xy, &point_set_);
    if (point_set_.size() == 0) continue;
    if (manager_->Create(point_set_, sensor_xy, RansacSeed(scan.utime, -1 - static_cast<std::int64_t>(k)))) {
      created_.Add(manager_->Box(manager_->tracks().size() - 1));
    }
  }
}

}  // namespace vtrack
