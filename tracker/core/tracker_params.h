// Every parameter of the tracker, one struct per component (config/tracker.yaml mirrors this
// layout: one YAML section per struct, keys = field names).
#pragma once

#include <cstdint>
#include <string>

#include "tracker/core/association.h"
#include "tracker/core/detections.h"
#include "tracker/core/ekf.h"
#include "tracker/core/fitting.h"
#include "tracker/core/ism.h"
#include "tracker/core/preprocess.h"
#include "tracker/core/segmentation.h"
#include "tracker/core/shape.h"
#include "tracker/core/track_manager.h"
#include "tracker/core/vasm.h"

namespace vtrack {

// How scans and poses are sequenced (message time only, never the wall clock).
struct InputParams {
  // A scan is processed once the pose stream reaches its last return time (utime + sweep
  // duration), or, if it does not, once any message is this much later than that time; then the
  // pose is extrapolated (counted "pose_extrapolated").
  std::int64_t max_pose_wait_us = 200'000;       // [us]
  std::int64_t max_extrapolation_us = 300'000;   // [us] beyond: "stale_pose", scan dropped
  std::int64_t time_jump_reset_us = 1'000'000;   // [us] a message this much older than the newest
                                                 //      resets the tracker (looped log)
  int max_queued_scans = 50;                     // [-] older scans are dropped ("scan_overrun")
  std::int64_t pose_history_us = 10'000'000;     // [us] poses kept
  std::int64_t max_sweep_duration_us = 1'000'000;  // [us] longer sweeps are refused ("bad_scan")

  bool Validate(std::string* error) const;
};

struct TrackerParams {
  InputParams input;
  PreprocessParams preprocess;
  SegmentationParams segmentation;
  AssociationParams association;
  // The fitter's defaults, but inliers beyond a gap of 0.5 m (not 1 m) are dropped: the rear
  // faces of a parked row are colinear and ~0.8 m apart, and one edge would run across them.
  FitParams fit = [] {
    FitParams f;
    f.max_inlier_gap_m = 0.5;
    return f;
  }();
  IsmParams ism;
  VasmParams vasm;
  EkfParams ekf;
  ShapeParams shape;
  TrackManagerParams manager;  // includes the mode (mht | ism | vasm)
  DetectionParams detections;  // a detector's boxes: the input mode and their measurement model

  // True if every component is valid; otherwise false and *error names the key and its value.
  bool Validate(std::string* error) const;
};

}  // namespace vtrack
