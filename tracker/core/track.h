// A track and what is reported of it: the data the track manager's stages share (hypotheses
// and scoring, orientation rules, life cycle, classification: track_manager.h), with no logic
// beyond small accessors.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <vector>

#include "base/box.h"
#include "tracker/core/ekf.h"
#include "tracker/core/fitting.h"
#include "tracker/core/motion_model.h"
#include "tracker/core/shape.h"

namespace vtrack {

enum class TrackStatus : std::int8_t { kTentative = 0, kConfirmed = 1, kCoasting = 2 };  // = track_t
enum class ObjectClass : std::int8_t { kUnknown = 0, kVehicle = 1, kOther = 2 };       // = track_t

// One hypothesis of a track with what the manager keeps about it.
struct TrackHypothesis {
  Hypothesis filter;                      // model kind, state, covariance (ekf.h)
  ShapeEstimator shape;                   // length and width in this hypothesis' orientation
  std::optional<double> length_est, width_est;  // shape's estimates, cached (RefreshShape)
  double inside_fraction = 0.5;           // [-]
  double noise_scale = 1.0;               // [-]
  std::deque<double> score_terms;         // per scan with points: negative log-likelihood
  double last_logdet = 0.0;               // [-] ln det(2 pi S) of the last update
  double last_nis = std::numeric_limits<double>::quiet_NaN();
  int consecutive_misses = 0;             // [-] scans with points but no accepted update
  bool updated_this_scan = false;
  bool length_seen_full = false;          // a full view of the length axis was fitted
  bool width_seen_full = false;           // a full view of the width axis was fitted
  FitResult fit;                          // last fit (debug)
  bool has_fit = false;

  double Score() const;                   // mean of score_terms; +inf if none
  void RefreshShape() {                   // after every change of shape
    length_est = shape.Length();
    width_est = shape.Width();
  }
};

// A few of one scan's returns of a track, kept for the next scan's motion check
// (ReturnsMovedWith, classification.h). World position = origin + (x, y).
struct ReturnsSnapshot {
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  // [m] world
  std::vector<float> x, y;                           // [m] relative to origin
  std::int64_t utime = 0;                            // [us] mean measurement time of the returns
  bool empty() const { return x.empty(); }
};

struct Track {
  std::int64_t id = 0;
  TrackStatus status = TrackStatus::kTentative;
  bool mover = false;
  int motion_evidence = 0;                // [-] consecutive scans with evidence of motion
  ReturnsSnapshot last_returns;           // the returns of the last scan that gave it any
  std::int64_t created_utime = 0;         // [us]
  std::int64_t state_utime = 0;           // [us] time of the hypotheses' states
  std::int64_t last_update_utime = 0;     // [us]
  int num_updates = 0;
  int consecutive_misses = 0;             // [-] scans without any update
  bool seen_this_scan = false;            // [-] this scan gave it returns (accepted or not)
  bool small_object = false;              // measured by centroid (poles, bushes, pedestrians)
  bool axis_from_full_face = false;       // heading set by a fully seen short face (AlignToFullFace)
  double full_face_extent = 0.0;          // [m] that face's extent (a car's front or rear width)
  int box_updates = 0;                    // [-] updates (and creation) by a detector's box
  std::int64_t last_box_utime = -1;       // [us] time of the latest box update; -1 = never
  double box_score = 0.0;                 // [-] recency-weighted mean score of those boxes
                                          //     (TrackManager::Report, "score")
  double box_z = 0.0, box_height = 0.0;   // [m] the same mean of their bottom (world) and height
  double vehicle_log_odds = 0.0;          // [-] accumulated vehicle evidence (vehicle_evidence.h)
  bool evidence_vehicle = false;          // [-] a vehicle by that evidence (VehicleByEvidence)
  bool evidence_seen = false;             // [-] a scan has given it evidence
  bool evidence_3d = false;               // [-] the latest scan evidence came from a 3-D cloud
  std::vector<TrackHypothesis> hyps;
  int selected = 0;                       // index into hyps of the reported hypothesis
};

// A track as reported (track_t without LCM).
struct TrackReport {
  std::int64_t id = 0;
  TrackStatus status = TrackStatus::kTentative;
  ModelKind model = ModelKind::kIsm;
  bool moving = false;
  ObjectClass object_class = ObjectClass::kUnknown;
  double x = 0, y = 0, theta = 0;         // [m, m, rad]
  double speed = 0, velocity_heading = 0, yaw_rate = 0;  // [m/s, rad, rad/s]
  double rear_axle_offset = 0;            // [m] NaN for ISM
  double length = 0, width = 0;           // [m]
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  int num_hypotheses = 0;
  double age = 0;                         // [s]
  int num_updates = 0;
  // [-] how likely the track is a real vehicle, higher is likelier (track_t.score): from a
  // detector's boxes, on the detector's scale; from scans only, in [0, 1).
  double score = 0;
  // [m] bottom of the object (world frame) and its height, from a detector's boxes (the same
  // recency-weighted mean as score); NaN for a track no box measured (the LADAR tracks in 2-D).
  double z = std::numeric_limits<double>::quiet_NaN();
  double height = std::numeric_limits<double>::quiet_NaN();
  // [-] probability that the track is a vehicle, from its accumulated scan evidence
  // (vehicle_evidence.h; track_t.vehicle_probability).
  double vehicle_probability = 0.0;
  std::vector<PredictedPose> prediction;  // t after the report time
};

struct HypothesisReport {
  int index = 0;
  ModelKind model = ModelKind::kIsm;
  bool selected = false;
  Vector6d state = Vector6d::Zero();
  Matrix6d cov = Matrix6d::Zero();
  double x = 0, y = 0, theta = 0, rear_axle_offset = 0;
  double score = 0, nis = 0;
  int consecutive_misses = 0;
  double inside_fraction = 0, noise_scale = 0;
};

// What the tracker did for one track on one scan (track_debug_entry_t without LCM).
struct TrackDebug {
  std::int64_t track_id = 0;
  FitKind fit_kind = FitKind::kNone;
  Eigen::Vector3d z = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Matrix3d R = Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN());
  OrientedBox predicted, updated;
  Eigen::Matrix3d updated_cov = Eigen::Matrix3d::Zero();
  std::uint8_t visible_faces = 0;
  std::array<double, 4> rear_axle{};      // NaN if the reported hypothesis is not a VASM
  std::vector<std::array<double, 4>> edges;  // (x0, y0, x1, y1)
  std::vector<float> point_x, point_y;
  std::vector<std::int8_t> point_edge;
  std::vector<HypothesisReport> hypotheses;
};

// The returns assigned to one track (or one new object) on one scan, in a local frame: floats
// relative to origin keep full precision far from the world origin.
struct PointSet {
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  // [m] world
  std::vector<float> x, y;                           // [m] relative to origin
  std::int64_t mean_utime = 0;                       // [us] mean measurement time of the returns
  double extent = 0.0;                               // [m] bounding-box diagonal
  std::size_t size() const { return x.size(); }
  bool outline = false;  // the outline of a 3-D cloud (TrackManagerParams::outline_*)
};

// The rectangle at pose (x, y, theta) with the given dimensions.
OrientedBox BoxOf(const Eigen::Vector3d& pose, double length, double width);

// Pose (x, y, theta) of a hypothesis' state x in model m.
Eigen::Vector3d PoseOf(const MotionModel& m, const Vector6d& x);

}  // namespace vtrack
