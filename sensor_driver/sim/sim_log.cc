#include "sensor_driver/sim/sim_log.h"

namespace vtrack::sim {

SimLogStats WriteSimLog(Simulator& sim, std::int64_t start_utime, const SimLogChannels& channels,
                        lcm_util::LogWriter* writer, const std::function<void(double)>& progress) {
  SimLogStats stats;
  vtrack::ladar_scan_t scan;
  vtrack::object_list_t truth;
  vtrack::pose_t pose;
  int i = 0, k = 0;
  const int n_scans = sim.NumScans(), n_poses = sim.NumPoses();
  // Merge the two streams by publication time; a pose goes first on a tie (it was due first).
  while (i < n_scans || k < n_poses) {
    const bool pose_next =
        k < n_poses && (i >= n_scans || sim.PoseOffsetUs(k) <= sim.ScanPublishOffsetUs(i));
    if (pose_next) {
      sim.MakePose(k, start_utime, &pose);
      writer->WriteMessage(start_utime + sim.PoseOffsetUs(k), channels.pose, pose);
      stats.bytes += pose.getEncodedSize();
      ++k;
    } else {
      sim.MakeScan(i, start_utime, i, &scan, &truth);
      const std::int64_t ts = start_utime + sim.ScanPublishOffsetUs(i);
      stats.slices += SendSweep(channels.sweep, scan, [&](const std::string& ch, const auto& msg) {
        writer->WriteMessage(ts, ch, msg);
        stats.bytes += msg.getEncodedSize();
      });
      writer->WriteMessage(ts, channels.truth, truth);
      stats.bytes += truth.getEncodedSize();
      stats.points += scan.npoints;
      ++i;
      if (progress && (i % 20 == 0 || i == n_scans)) progress(static_cast<double>(i) / n_scans);
    }
  }
  stats.scans = n_scans;
  stats.poses = n_poses;
  return stats;
}

}  // namespace vtrack::sim
