// A detector's boxes as measurements (the box input of the tracker): each box, placed in the
// world with the ego pose at its frame's time, measures a track's centre and heading directly,
// z = (x, y, theta), through the same ISM / VASM filters and hypotheses as a fitted outline
// (paper Section 2.5). The detector's heading may be off by 180 deg (front and rear look alike
// in a box): each hypothesis takes the box's heading or its opposite, whichever is nearer its
// own. Boxes are associated with the tracks one to one by centre distance (Hungarian method),
// within a gate of gate_m plus gate_sigma predicted position standard deviations.
#pragma once

#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <vector>

#include "tracker/core/association.h"
#include "base/box.h"
#include "tracker/core/motion_model.h"
#include "tracker/core/params.h"

namespace vtrack {

// One box as the detector gives it (detection_t without LCM): body frame at the list's utime.
struct Detection {
  double x = 0, y = 0, z = 0;    // [m] bottom centre, body frame
  double yaw = 0;                // [rad] heading of the length axis, body frame
  double length = 0, width = 0, height = 0;  // [m]
  double score = 0;              // [-] the detector's confidence, on its own scale
  std::int8_t object_class = 0;  // [-] object_t.CLASS_*
};

struct DetectionList {
  std::int64_t utime = 0;        // [us] time the boxes describe
  std::int64_t seq = 0;          // [-]
  std::vector<Detection> boxes;
};

// What the tracker measures tracks with: the LADAR's scans (fitted outlines), a detector's
// boxes, or both (fused: boxes update and start tracks between scans; scans drive the life
// cycle and the reports).
enum class InputMode { kScans, kBoxes, kFused };

}  // namespace vtrack

template <>
struct vtrack::param::EnumNames<vtrack::InputMode> {
  static constexpr std::array kNames{"scans", "boxes", "fused"};
};

namespace vtrack {

inline const char* ToString(InputMode mode) { return param::NameOf(mode); }

struct DetectionParams {
  static constexpr const char* kSection = "detections";
  static constexpr const char* kAbout =
      "A detector's boxes: input mode and their measurement model";
  InputMode mode = InputMode::kScans;
  double min_score = 2.0;
  double birth_score = 2.0;
  double position_std = 0.25;
  double heading_std_deg = 6.0;
  double gate_m = 2.0;
  double gate_sigma = 3.0;
  double max_gate_m = 5.0;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("mode", &mode, {"-", {}, "what measures tracks: scans (fitted outlines), boxes (a detector's), or both (fused)"});
    v("min_score", &min_score, {"-", Finite(), "boxes below this score, on the detector's own scale, are not used"});
    v("birth_score", &birth_score, {"-", Finite(), "a box starts a track only from this score on"});
    v("position_std", &position_std, {"m", OpenClosed(0, 10), "1-sigma of a box centre along each axis"});
    v("heading_std_deg", &heading_std_deg, {"deg", OpenClosed(0, 90), "1-sigma of a box heading (modulo 180 deg)"});
    v("gate_m", &gate_m, {"m", Above(0), "a box farther than this (+ gate_sigma predicted position stds) from a track is not its candidate"});
    v("gate_sigma", &gate_sigma, {"-", AtLeast(0), "predicted position stds added to gate_m"});
    v("max_gate_m", &max_gate_m, {"m", OpenClosed(0, 50), "upper bound of the whole gate (>= gate_m)"});
  }
  // gate_m <= max_gate_m.
  std::string CrossProblem() const;
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

// A box in the world frame, ready to measure a track.
struct BoxMeasurement {
  OrientedBox box;               // centre, heading (as the detector gave it), length, width
  double z = 0, height = 0;      // [m] bottom of the box (world) and its height
  double score = 0;              // [-]
  std::int64_t utime = 0;        // [us]
};

// The boxes of a list with score >= min_score, placed with world_from_body at the list's utime.
std::vector<BoxMeasurement> BoxesInWorld(const DetectionList& list,
                                         const Eigen::Isometry3d& world_from_body,
                                         const DetectionParams& params);

// The measurement a box gives a hypothesis whose heading is theta: its centre, and its heading
// or the opposite, whichever is nearer theta; R from position_std and heading_std_deg.
CentreMeasurement BoxToMeasurement(const BoxMeasurement& b, double theta,
                                   const DetectionParams& params);

// Box k of the returned vector's track_box[j] is assigned to track j (-1: none); new_boxes are
// the boxes no track took.
struct BoxAssociation {
  std::vector<int> track_box;
  std::vector<int> new_boxes;
};
BoxAssociation AssociateBoxes(const std::vector<PredictedObject>& tracks,
                              const std::vector<BoxMeasurement>& boxes,
                              const DetectionParams& params);

}  // namespace vtrack
