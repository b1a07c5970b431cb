// What one rendered frame shows, as plain structs: no LCM, no OpenCV. The renderer
// (viewer/renderer.h) draws a Scene; viewer/msg_convert.h fills one from the bus messages, and
// any other tool (tests, the evaluator's plots of one moment) can fill one by hand.
//
// Everything is in the world frame of pose_t (x, y in metres, angles in radians, counter-clockwise
// from +x). Optional values are NaN when unknown.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "base/box.h"

namespace vtrack::viewer {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Mirrors track_t.STATUS_*, MODEL_*, CLASS_* (same numbers).
enum class TrackStatus : int { kTentative = 0, kConfirmed = 1, kCoasting = 2 };
enum class MotionModel : int { kIsm = 0, kVasm = 1, kCv = 2 };
enum class TrackClass : int { kUnknown = 0, kVehicle = 1, kOther = 2 };
// Mirrors track_debug_entry_t.FIT_*.
enum class FitKind : int { kNone = 0, kEdge = 1, kCorner = 2 };

using Segment = std::pair<Eigen::Vector2d, Eigen::Vector2d>;  // [m] end points

// One tracked object as the tracker reports it (track_t): the orange rectangle of Figure 4.
struct SceneTrack {
  std::int64_t id = 0;
  TrackStatus status = TrackStatus::kConfirmed;
  MotionModel model = MotionModel::kIsm;
  bool moving = false;
  TrackClass object_class = TrackClass::kUnknown;
  OrientedBox box;                                    // [m, rad] updated state rectangle
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();      // [m^2, m rad, rad^2] of (x, y, theta)
  double speed = 0.0;                                 // [m/s] speed of the centre
  double velocity_heading = kNaN;                     // [rad]
  double yaw_rate = 0.0;                              // [rad/s]
  double rear_axle_offset = kNaN;                     // [m] VASM's L (< 0 behind); NaN for ISM
  int num_hypotheses = 1;                             // [-] live hypotheses of the object
  double vehicle_probability = kNaN;                  // [-] from its vehicle evidence (track_t)
  std::vector<Eigen::Vector2d> past;                  // [m] recent centres, oldest first (blue)
  std::vector<Eigen::Vector2d> predicted;             // [m] predicted centres, nearest first (black)
};

// One motion hypothesis of a track (hypothesis_t), drawn when "show hypotheses" is on (Fig. 6).
struct SceneHypothesis {
  int index = 0;
  MotionModel model = MotionModel::kIsm;
  bool selected = false;
  OrientedBox box;                  // [m, rad] the hypothesis' rectangle
  double rear_axle_offset = kNaN;   // [m] L (VASM), NaN for ISM
  double score = kNaN;              // [-] fit score, lower is better
};

// What the tracker did for one track on this scan (track_debug_entry_t): the green measurement,
// the dashed fitted edges, the associated points and the hypotheses.
struct SceneMeasurement {
  std::int64_t track_id = 0;
  FitKind fit_kind = FitKind::kNone;
  OrientedBox z_box;                                  // [m, rad] measurement z (Eq. 17) as a rectangle
  Eigen::Matrix3d R = Eigen::Matrix3d::Zero();        // [m^2, m rad, rad^2] Eq. 18
  std::uint8_t visible_faces = 0;                     // [-] bit i = Face i judged visible
  std::vector<Segment> edges;                         // [m] fitted edges
  std::optional<Segment> rear_axle;                   // [m] the tracker's own rear-axle segment
  std::vector<Eigen::Vector2f> points;                // [m] points associated with the track
  std::vector<std::int8_t> point_edge;                // [-] edge of each point, -1 = outlier
  std::vector<SceneHypothesis> hypotheses;
};

// One ground-truth object (object_t) and its true path around this moment.
struct SceneTruth {
  std::int64_t id = 0;
  int object_class = 0;                               // [-] object_t.CLASS_*
  OrientedBox box;                                    // [m, rad]
  double rear_axle_offset = kNaN;                     // [m]
  double speed = 0.0;                                 // [m/s]
  bool moving = false;
  bool in_labelled_region = true;
  bool is_clutter = false;                            // [-] wall, pole, bush, other: not drawn
  std::vector<Eigen::Vector2d> path;                  // [m] true centres, oldest first (red)
};

// The ego vehicle (blue) and its recent path.
struct SceneEgo {
  OrientedBox box;                                    // [m, rad] vehicle outline
  Eigen::Vector2d position = Eigen::Vector2d::Zero(); // [m] body origin (pose_t.pos)
  std::vector<Eigen::Vector2d> past;                  // [m] oldest first
};

struct Scene {
  std::int64_t utime = 0;          // [us since Unix epoch] time the frame shows
  double time_s = 0.0;             // [s] since the start of the run (printed on the frame)
  std::int64_t scan_seq = -1;      // [-] seq of the scan, -1 if unknown
  std::string mode;                // [-] tracker mode ("mht", "ism", "vasm"), "" if no tracks
  double latency_ms = kNaN;        // [ms] tracker latency for this scan
  std::vector<Eigen::Vector2f> points;  // [m] LADAR hits (grey)
  std::optional<SceneEgo> ego;
  std::vector<SceneTrack> tracks;
  std::vector<SceneMeasurement> measurements;
  std::vector<SceneTruth> truths;
  std::vector<std::string> notes;  // short status lines printed under the time stamp
};

}  // namespace vtrack::viewer
