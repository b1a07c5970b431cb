// KITTI tracking sequence -> LCM log: LADAR_SCAN, EGO_POSE, GROUND_TRUTH and DETECTIONS, as a
// live system with a KITTI car would have logged them (sensor_driver/kitti/README.md). A
// sequence of the boxes layout has no point clouds: no LADAR_SCAN.
//
// Every event's log timestamp is its message's utime, and events are written in time order; at
// equal times a pose comes before the scan and the scan before its ground truth. A frame's
// detections (at the frame's time) follow its scan; without scans, they come before its ground
// truth. EGO_POSE is
// written every pose_period_us from the first scan's start to the last scan's end, plus at every
// frame time, so each frame has its exact pose.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "sensor_driver/kitti/kitti_sequence.h"

namespace vtrack::kitti {

struct ConvertOptions {
  std::string out;                           // [-] output LCM log; written as out.partial, renamed when complete
  int first_frame = 0;                       // [-] first frame to convert; >= 0
  int num_frames = -1;                       // [-] frames to convert; -1 = to the end; else >= 1
  std::int64_t pose_period_us = 10'000;      // [us] EGO_POSE period (100 Hz); in [1000, 100000]
  bool ground_truth = true;                  // [-] write GROUND_TRUTH (when the sequence has labels)
  bool detections = true;                    // [-] write DETECTIONS (when the sequence has them)
  std::string scan_channel = "LADAR_SCAN";   // [-]
  std::string pose_channel = "EGO_POSE";     // [-]
  std::string truth_channel = "GROUND_TRUTH";// [-]
  std::string detections_channel = "DETECTIONS";  // [-]

  std::string Validate() const;  // empty if valid, else names the key and value
};

struct ConvertStats {
  int frames = 0;
  std::int64_t scans = 0, poses = 0, truth_lists = 0, truth_objects = 0;
  std::int64_t detection_lists = 0, detections = 0;
  std::int64_t points = 0;
  std::int64_t bytes = 0;  // size of the log written
};

// Progress callback: (frames done, frames total, bytes written so far).
using ConvertProgress = std::function<void(int, int, std::int64_t)>;

// Converts; throws KittiError for a bad option, std::runtime_error for an I/O failure. On failure
// no file is left at options.out.
ConvertStats ConvertSequence(const Sequence& seq, const ConvertOptions& options,
                             const ConvertProgress& progress = nullptr);

}  // namespace vtrack::kitti
