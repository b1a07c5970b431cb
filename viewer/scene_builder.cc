#include "viewer/scene_builder.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "base/pose.h"
#include "viewer/msg_convert.h"

namespace vtrack::viewer {
namespace {

std::string FormatSeconds(double s) {
  std::ostringstream os;
  os.precision(2);
  os << std::fixed << s;
  return os.str();
}

}  // namespace

std::string SceneParams::FirstProblem() const {
  if (std::string err = param::FirstProblem(preprocess); !err.empty()) return err;
  std::ostringstream os;
  if (max_pose_extrapolation_us < 0 || max_pose_extrapolation_us > 10'000'000) {
    os << "scene.max_pose_extrapolation_us = " << max_pose_extrapolation_us
       << ": must be in [0, 10 s]";
  } else if (!(ego_length > 0.0) || ego_length > 100.0) {
    os << "scene.ego_length = " << ego_length << ": must be in (0, 100] m";
  } else if (!(ego_width > 0.0) || ego_width > 100.0) {
    os << "scene.ego_width = " << ego_width << ": must be in (0, 100] m";
  } else if (!std::isfinite(ego_center_ahead) || std::abs(ego_center_ahead) > 100.0) {
    os << "scene.ego_center_ahead = " << ego_center_ahead << ": must be in [-100, 100] m";
  }
  return os.str();
}

SceneBuilder::SceneBuilder(const SceneParams& params)
    : params_(params), preprocessor_(params.preprocess) {
  if (const std::string err = params_.FirstProblem(); !err.empty()) throw std::invalid_argument(err);
}

Scene SceneBuilder::Build(const FrameInputs& in) {
  Scene s;
  s.utime = in.utime;
  s.time_s = 1e-6 * static_cast<double>(in.utime - in.time_origin_utime);

  // Ego vehicle at the frame time.
  if (const auto world_from_body = in.poses.At(in.utime, params_.max_pose_extrapolation_us)) {
    SceneEgo ego;
    ego.position = world_from_body->translation().head<2>();
    const double yaw = YawOf(*world_from_body);
    ego.box.theta = yaw;
    ego.box.length = params_.ego_length;
    ego.box.width = params_.ego_width;
    ego.box.center = ego.position + params_.ego_center_ahead * ego.box.Axis();
    ego.past = in.ego_trail;
    s.ego = std::move(ego);
  } else if (!in.poses.empty()) {
    s.notes.push_back("no ego pose at this time");
  }

  // LADAR hits in the world frame.
  for (const auto& msg : in.scans) {
    if (msg->npoints > params_.preprocess.max_points) {
      s.notes.push_back("scan " + std::to_string(msg->seq) + ": " + std::to_string(msg->npoints) +
                        " points, over the limit of " +
                        std::to_string(params_.preprocess.max_points) + "; not drawn");
      continue;
    }
    std::string why;
    const auto scan = ScanFromMsg(*msg, &why);
    if (!scan) {
      s.notes.push_back("scan " + std::to_string(msg->seq) + ": " + why);
      continue;
    }
    const PoseHistory* poses = &in.poses;
    PoseHistory body_frame;
    if (in.poses.empty()) {
      // No ego pose at all (e.g. a fixed sensor): the body frame is the world frame.
      body_frame.Add(scan->utime - 1, Eigen::Isometry3d::Identity());
      body_frame.Add(scan->utime + std::max(0, scan->sweep_duration_us) + 1,
                     Eigen::Isometry3d::Identity());
      poses = &body_frame;
      s.notes.push_back("no ego pose: points in the vehicle frame");
    }
    const PreprocessResult r =
        preprocessor_.Run(*scan, *poses, params_.max_pose_extrapolation_us, &world_);
    if (r.status == CompensationStatus::kNoPose) {
      s.notes.push_back("scan " + std::to_string(msg->seq) + ": no ego pose for its sweep");
      continue;
    }
    s.points.reserve(s.points.size() + world_.size());
    for (std::size_t i = 0; i < world_.size(); ++i) {
      s.points.emplace_back(static_cast<float>(world_.x[i]), static_cast<float>(world_.y[i]));
    }
    if (msg->utime == in.utime) s.scan_seq = msg->seq;
  }

  // Tracks with their recent paths.
  if (in.tracks) {
    s.mode = in.tracks->mode;
    s.latency_ms = 1e-3 * static_cast<double>(in.tracks->latency_us);
    if (s.scan_seq < 0) s.scan_seq = in.tracks->scan_seq;
    s.tracks.reserve(in.tracks->tracks.size());
    for (const auto& msg : in.tracks->tracks) {
      SceneTrack t = TrackFromMsg(msg);
      if (const auto it = in.track_trails.find(t.id); it != in.track_trails.end()) {
        t.past = it->second;
      }
      s.tracks.push_back(std::move(t));
    }
    if (in.tracks->utime != in.utime) {
      s.notes.push_back("tracks from " +
                        FormatSeconds(1e-6 * static_cast<double>(in.utime - in.tracks->utime)) +
                        " s earlier");
    }
  }

  if (in.debug) {
    for (const auto& entry : in.debug->entries) {
      const auto it = std::find_if(s.tracks.begin(), s.tracks.end(),
                                   [&](const SceneTrack& t) { return t.id == entry.track_id; });
      s.measurements.push_back(
          MeasurementFromMsg(entry, it == s.tracks.end() ? nullptr : &*it));
    }
  }

  if (in.truth) {
    for (const auto& o : in.truth->objects) {
      SceneTruth g = TruthFromMsg(o);
      if (const auto it = in.truth_paths.find(g.id); it != in.truth_paths.end()) {
        g.path = it->second;
      }
      s.truths.push_back(std::move(g));
    }
  }
  return s;
}

}  // namespace vtrack::viewer
