#include "log_tools/eval/kitti_export.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "log_tools/eval/report.h"
#include "base/angle.h"

namespace vtrack::eval {

std::string KittiExportParams::Validate() const {
  std::ostringstream os;
  if (const std::string err = camera.Validate(); !err.empty()) {
    os << err;
  } else if (coast_frames < 0) {
    os << "coast_frames must be >= 0, got " << coast_frames;
  } else if (!std::isfinite(time_offset_s)) {
    os << "time_offset_s must be finite, got " << time_offset_s;
  }
  return os.str();
}

KittiExportStats ExportKittiTracking(const LogData& data, const std::string& mode,
                                     const KittiExportParams& params, const std::string& path) {
  if (const std::string err = params.Validate(); !err.empty()) {
    throw std::runtime_error("invalid KITTI export parameter: " + err);
  }
  const auto lists = data.tracks.find(mode);
  if (lists == data.tracks.end()) {
    throw std::runtime_error("no tracks of mode '" + mode + "' to export");
  }
  if (data.poses.empty()) {
    throw std::runtime_error("the KITTI export needs the ego pose (pose_t), and the logs hold none");
  }
  KittiExportStats stats;
  stats.time_offset_s = params.time_offset_s >= 0.0
                            ? params.time_offset_s
                            : 0.5e-6 * static_cast<double>(data.sweep_duration_us.value_or(0));
  const Eigen::Isometry3d body_from_sensor =
      data.body_from_sensor.value_or(Eigen::Isometry3d::Identity());
  const auto offset_us = static_cast<std::int64_t>(std::llround(stats.time_offset_s * 1e6));

  struct Line {
    std::int64_t frame, id;
    std::string text;
  };
  std::vector<Line> lines;
  // Per track id: the frame and the update count of the last list that measured it (a tentative
  // track keeps its status over a miss, so a new measurement shows as a larger num_updates).
  struct Seen {
    std::int64_t frame = 0;
    std::int32_t updates = 0;
  };
  std::unordered_map<std::int64_t, Seen> measured;
  std::int64_t index = 0;
  for (const auto& [utime, list] : lists->second) {
    ++stats.frames;
    const std::int64_t frame = KittiFrame(list, index++);
    const auto ego = data.poses.At(utime + offset_us, 500'000);
    if (!ego) ++stats.frames_without_pose;  // its tracks still count as measured below
    const Eigen::Isometry3d sensor_from_world =
        ego ? Eigen::Isometry3d((*ego * body_from_sensor).inverse()) : Eigen::Isometry3d::Identity();
    for (const auto& tr : list.tracks) {
      // Vehicles, and every track a detector's box measured (height finite) whatever its class:
      // the tracker calls a box track a vehicle only from a confident score, while the KITTI
      // criterion sweeps the score threshold itself (sAMOTA), so the weak ones go out ranked by it.
      const bool box_measured = std::isfinite(tr.height);
      const auto seen = measured.find(tr.id);
      const bool coasting = tr.status == vtrack::track_t::STATUS_COASTING;
      const bool measured_now = !coasting && (seen == measured.end() || tr.num_updates > seen->second.updates);
      if (measured_now) measured[tr.id] = {frame, tr.num_updates};
      bool write = false;
      if (tr.status == vtrack::track_t::STATUS_CONFIRMED) {
        write = true;
      } else if (tr.status == vtrack::track_t::STATUS_TENTATIVE) {
        write = params.tentative_boxes && box_measured && measured_now;
      } else if (coasting) {
        write = params.score_coasting ||
                (seen != measured.end() && frame - seen->second.frame <= params.coast_frames);
      }
      if (!ego || !write || (tr.object_class != vtrack::track_t::CLASS_VEHICLE && !box_measured)) {
        continue;
      }
      const double dt = stats.time_offset_s;
      const double speed = std::isfinite(tr.speed) ? tr.speed : 0.0;
      const double vh = std::isfinite(tr.velocity_heading) ? tr.velocity_heading : tr.theta;
      const double yaw_rate = std::isfinite(tr.yaw_rate) ? tr.yaw_rate : 0.0;
      const double x = tr.x + speed * std::cos(vh) * dt, y = tr.y + speed * std::sin(vh) * dt;
      const double theta = tr.theta + yaw_rate * dt;
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(theta) || !(tr.length > 0.0) ||
          !(tr.width > 0.0)) {
        continue;
      }
      const SensorBox box = TrackBoxInSensor(tr, x, y, theta, sensor_from_world, params.camera);
      const std::optional<ImageBox> image = ProjectToImage(box, tr.length, tr.width, params.camera);
      if (!image) {
        ++stats.outside_image;
        continue;
      }
      const Eigen::Vector3d c_s = box.bottom, h_s = box.heading;
      const double box_height = box.height;
      const double u0 = image->u0, v0 = image->v0, u1 = image->u1, v1 = image->v1;
      const Eigen::Vector3d bottom_r = params.camera.rect_from_sensor * c_s;
      const Eigen::Vector3d d_r = params.camera.rect_from_sensor.linear() * h_s;
      const double rotation_y = std::atan2(-d_r.z(), d_r.x());
      const double alpha = WrapToPi(rotation_y - std::atan2(bottom_r.x(), bottom_r.z()));
      char buf[512];
      std::snprintf(buf, sizeof(buf),
                    "%lld %lld Car -1 -1 %.6f %.2f %.2f %.2f %.2f %.6f %.6f %.6f %.6f %.6f %.6f "
                    "%.6f %.6f\n",
                    static_cast<long long>(frame), static_cast<long long>(tr.id), alpha, u0, v0,
                    u1, v1, box_height, tr.width, tr.length, bottom_r.x(), bottom_r.y(),
                    bottom_r.z(), rotation_y, static_cast<double>(tr.score));
      lines.push_back({frame, tr.id, buf});
    }
  }
  std::stable_sort(lines.begin(), lines.end(), [](const Line& a, const Line& b) {
    return a.frame != b.frame ? a.frame < b.frame : a.id < b.id;
  });
  std::string text;
  for (const auto& l : lines) text += l.text;
  WriteTextFile(path, text);
  stats.lines = static_cast<std::int64_t>(lines.size());
  return stats;
}

}  // namespace vtrack::eval
