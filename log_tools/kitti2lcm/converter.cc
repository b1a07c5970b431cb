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

namespace {

// Where the log goes. Through a symbolic link (a chain of them), to the file it names: the link
// stays. A file that is not a regular one (/dev/null, a pipe) is written directly: a temporary
// file moved over it would replace it. A regular file, or none yet, is written next to it as
// OUT.partial and moved over it when complete, so that a failed conversion leaves no half log.
struct OutputTarget {
  fs::path path;
  bool direct = false;
};

OutputTarget ResolveOutput(const std::string& out) {
  OutputTarget t{fs::path(out), false};
  std::error_code ec;
  for (int hops = 0; fs::is_symlink(fs::symlink_status(t.path, ec)); ++hops) {
    if (hops == 40) throw KittiError(out + ": too many levels of symbolic links");
    const fs::path next = fs::read_symlink(t.path, ec);
    if (ec) throw KittiError(out + ": cannot read the symbolic link: " + ec.message());
    t.path = next.is_absolute() ? next : t.path.parent_path() / next;
  }
  const fs::file_status st = fs::status(t.path, ec);
  if (fs::is_directory(st)) {
    throw KittiError(out + ": is a directory (--out names the log file to write)");
  }
  t.direct = fs::exists(st) && !fs::is_regular_file(st);
  return t;
}

}  // namespace

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

  const OutputTarget target = ResolveOutput(options.out);
  const std::string partial = target.direct ? target.path.string() : target.path.string() + ".partial";
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
      stats.bytes = log.bytes_written();
      if (progress) progress(stats.frames, total, stats.bytes);
    }
    write_poses_until(t1);
    stats.bytes = log.bytes_written();
  } catch (...) {
    std::error_code ec;
    if (!target.direct) fs::remove(partial, ec);
    throw;
  }
  if (target.direct) return stats;
  std::error_code ec;
  fs::rename(partial, target.path, ec);
  if (ec) {
    const std::string why = ec.message();
    fs::remove(partial, ec);
    throw KittiError("cannot move " + partial + " to " + target.path.string() + ": " + why);
  }
  return stats;
}

}  // namespace vtrack::kitti
