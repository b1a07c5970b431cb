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
#include "tracker/core/params.h"

namespace vtrack {

// How scans and poses are sequenced (message time only, never the wall clock).
struct InputParams {
  static constexpr const char* kSection = "input";
  static constexpr const char* kAbout =
      "Sequencing of scans, poses and boxes, in message time only (never the wall clock)";
  std::int64_t max_pose_wait_us = 200'000;
  std::int64_t max_extrapolation_us = 300'000;
  std::int64_t time_jump_reset_us = 1'000'000;
  int max_queued_scans = 50;
  std::int64_t pose_history_us = 10'000'000;
  std::int64_t max_sweep_duration_us = 1'000'000;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("max_pose_wait_us", &max_pose_wait_us, {"us", AtLeast(0), "a scan waits this long past its last return for the pose stream ..."});
    v("max_extrapolation_us", &max_extrapolation_us, {"us", AtLeast(0), "... then the pose is extrapolated at most this far (\"pose_extrapolated\"; beyond: \"stale_pose\")"});
    v("time_jump_reset_us", &time_jump_reset_us, {"us", Above(0), "a message this much older than the newest, confirmed by the next, resets the tracker (looped log)"});
    v("max_queued_scans", &max_queued_scans, {"-", AtLeast(1), "scans waiting for poses; older ones are dropped (\"scan_overrun\")"});
    v("pose_history_us", &pose_history_us, {"us", AtLeast(1'000'000), "ego poses kept"});
    v("max_sweep_duration_us", &max_sweep_duration_us, {"us", Above(0), "longer sweeps are refused (\"bad_scan\")"});
  }
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

struct TrackerParams {
  InputParams input;
  PreprocessParams preprocess;
  SegmentationParams segmentation;
  AssociationParams association;
  FitParams fit;
  IsmParams ism;
  VasmParams vasm;
  EkfParams ekf;
  ShapeParams shape;
  TrackManagerParams manager;  // includes the mode (mht | ism | vasm)
  DetectionParams detections;  // a detector's boxes: the input mode and their measurement model

  // Calls v(&section) for every component, in the order of config/tracker.yaml.
  template <class V>
  void VisitSections(V&& v) {
    v(&input);
    v(&preprocess);
    v(&segmentation);
    v(&association);
    v(&fit);
    v(&ism);
    v(&vasm);
    v(&ekf);
    v(&shape);
    v(&manager);
    v(&detections);
  }

  // True if every component is valid; otherwise false and *error names the key and its value.
  bool Validate(std::string* error) const;
};

}  // namespace vtrack
