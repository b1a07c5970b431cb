#include "log_tools/kitti2lcm/converter.h"

#include <filesystem>
#include <set>
#include <sstream>

#include "lcmtypes/util/log_reader.h"

namespace vtrack::kitti {
namespace fs = std::filesystem;

std::string ConvertOptions::Validate() const {
  std::ostringstream os;
  if (out.empty()) os << "out must name the output log file";
  else if (first_frame < 0) os << "first_frame must be >= 0, got " << first_frame;
  else if (num_frames == 0 || num_frames < -1) os << "num_frames must be >= 1 (or -1 = all), got " << num_frames;
  else if (pose_period_us < 1000 || pose_period_us > 100000)
    os << "pose_period_us must be in [1000, 100000] us (10-1000 Hz), got " << pose_period_us;
  else if (scan_channel.empty() || pose_channel.empty() || truth_channel.empty() ||
           detections_channel.empty())
    os << "channel names must not be empty";
  return os.str();
}

ConvertStats ConvertSequence(const Sequence& seq, const ConvertOptions& options,
                             const ConvertProgress& progress) {
  if (const std::string err = options.Validate(); !err.empty()) throw KittiError("bad option: " + err);
  if (options.first_frame >= seq.num_frames()) {
    throw KittiError("first frame " + std::to_string(options.first_frame) + " is past the end: sequence " +
                     seq.sequence() + " has " + std::to_string(seq.num_frames()) + " frames");
  }
  const int first = options.first_frame;
  const int last = options.num_frames < 0 ? seq.num_frames() - 1
                                          : std::min(seq.num_frames() - 1, first + options.num_frames - 1);
  const int total = last - first + 1;

  // Pose times: a regular grid over the converted sweeps, plus every frame's own time.
  // Without scans the poses cover the frames' times only.
  const std::int64_t t0 = seq.has_scans() ? seq.ScanUtime(first) : seq.FrameUtime(first);
  const std::int64_t t1 = seq.has_scans()
                              ? seq.ScanUtime(last) + seq.options().velodyne.sweep_duration_us
                              : seq.FrameUtime(last);
  std::set<std::int64_t> pose_times;
  for (std::int64_t t = t0; t <= t1; t += options.pose_period_us) pose_times.insert(t);
  for (int i = first; i <= last; ++i) pose_times.insert(seq.FrameUtime(i));

  const std::string partial = options.out + ".partial";
  ConvertStats stats;
  try {
    lcm_util::LogWriter log(partial);
    auto pose_it = pose_times.begin();
    auto write_poses_until = [&](std::int64_t t_inclusive) {
      for (; pose_it != pose_times.end() && *pose_it <= t_inclusive; ++pose_it) {
        log.WriteMessage(*pose_it, options.pose_channel, seq.PoseAt(*pose_it));
        ++stats.poses;
      }
    };
    for (int i = first; i <= last; ++i) {
      const VelodyneFrame frame = seq.has_scans() ? seq.ReadFrame(i) : VelodyneFrame{};
      if (seq.has_scans()) {
        const vtrack::ladar_scan_t scan = seq.Scan(i, frame);
        write_poses_until(scan.utime);
        log.WriteMessage(scan.utime, options.scan_channel, scan);
        ++stats.scans;
        stats.points += scan.npoints;
      }
      if (options.detections && seq.has_detections()) {
        const vtrack::detection_list_t boxes = seq.Detections(i);
        // With scans, right after the scan (its log time, so that the log stays in time order;
        // the message holds the frame's time, half a sweep later); without, at the frame's time.
        if (!seq.has_scans()) write_poses_until(boxes.utime);
        log.WriteMessage(seq.has_scans() ? seq.ScanUtime(i) : boxes.utime,
                         options.detections_channel, boxes);
        ++stats.detection_lists;
        stats.detections += boxes.num_detections;
      }
      if (options.ground_truth && seq.has_labels()) {
        const vtrack::object_list_t truth = seq.GroundTruth(i, frame);
        log.WriteMessage(truth.utime, options.truth_channel, truth);
        ++stats.truth_lists;
        stats.truth_objects += truth.num_objects;
      }
      ++stats.frames;
      if (progress) progress(stats.frames, total, static_cast<std::int64_t>(fs::file_size(partial)));
    }
    write_poses_until(t1);
  } catch (...) {
    std::error_code ec;
    fs::remove(partial, ec);
    throw;
  }
  std::error_code ec;
  fs::rename(partial, options.out, ec);
  if (ec) {
    fs::remove(partial, ec);
    throw std::runtime_error("cannot move " + partial + " to " + options.out + ": " + ec.message());
  }
  stats.bytes = static_cast<std::int64_t>(fs::file_size(options.out));
  return stats;
}

}  // namespace vtrack::kitti
