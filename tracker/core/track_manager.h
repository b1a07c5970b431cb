// Tracks and their hypotheses: the paper's multi-hypothesis manager (Section 2.5) and the track
// life cycle. Decisions the paper leaves open (DESIGN note 9) are fixed here and documented in
// tracker/README.md; each is a parameter of TrackManagerParams.
//
// Hypotheses. Every object starts with one hypothesis: an ISM (modes mht and ism) or a VASM
// (mode vasm). In mode mht an object judged a mover gains VASM hypotheses, up to
// max_hypotheses per object (paper: four), each with its own required fraction of points inside
// the vehicle boundary (FitRequest::min_inside_fraction) and system-noise scale (Ekf::Predict):
//   slot 0  ISM   inside_fraction = ism_inside_fraction, noise 1
//   slot 1  VASM  vasm_variants[0]          (nominal)
//   slot 2  VASM  vasm_variants[1]          (stricter inside fraction), or, while the orientation
//                                            is ambiguous, vasm_variants[0] turned by 90 deg
//   slot 3  VASM  vasm_variants[2]          (larger system noise: trusts measurements more)
// Stationary objects keep exactly one hypothesis.
//
// Mover test. On every scan that updates the object, the centre velocity v (2-vector) and its
// covariance C of the reported hypothesis give d^2 = v^T C^-1 v. The scan is evidence of motion
// if d^2 exceeds the chi-square (2 dof) quantile of mover_confidence and |v| >= mover_min_speed.
// When the fit was a single edge, only the velocity across the edge counts (1 dof): along it the
// centre follows the extent of the returns, which slides as the ego passes a parked car. Centroid
// measurements (small objects) give no evidence. mover_scans consecutive such scans declare a
// mover; a mover stays a mover (a rectangle that grows out of a small object starts over).
//
// Orientation at the mover declaration. A fit gives theta modulo 90 deg (corner) or 180 deg
// (edge); the velocity heading psi tells the length axis of a moving vehicle. With delta the
// angle between psi and the nearest of theta + k 90 deg: the VASMs take the candidate heading
// nearest psi (and the sign that points along psi, so v > 0); if psi lies within
// ambiguity_deg of the diagonal between two candidates (45 deg), the orientation is ambiguous and
// slot 2 holds the other candidate.
//
// Score (lower is better): over the last score_window scans in which the object had points, the
// mean negative log-likelihood of the hypothesis' measurements, 0.5 (NIS + ln det(2 pi S)); a scan
// in which the hypothesis got no accepted update costs 0.5 (gate_nis + ln det(2 pi S_last)), as
// if the measurement had landed on the gate. Unlike the NIS alone, this does not reward a
// hypothesis for inflating its covariance. The reported hypothesis is the best score; it changes
// only when another is better by switch_margin (hysteresis against flicker).
//
// Failure and re-seeding. A hypothesis that gets no accepted update in fail_misses consecutive
// scans in which the object had points, while the reported one was updated, has failed ("fails to
// fit for a few frames"): it is re-seeded from the reported hypothesis (Ekf::Convert into its own
// model, same heading), keeps its own inside fraction and noise scale, copies the shape, and
// starts with the reported hypothesis' score history.
//
// Axis of a stationary object. A fitted face whose both ends are seen (RangeProfile: beyond each
// end, nothing nearer) and that is shorter than vehicle_min_length is a front or rear face: the
// heading is turned by 90 deg if it runs along that face, and kept so (a parked row seen from
// behind shows full rear faces and the first metre of each side; the longer-edge rule would
// take the rear face for a side). Otherwise the length axis is the longer side: when the width
// estimate exceeds axis_swap_ratio times the length estimate and vehicle_min_length, the ISM
// heading turns by 90 deg.
//
// Life cycle. tentative -> confirmed after confirm_updates updates; a tentative track missed in
// tentative_max_misses consecutive scans is deleted. A confirmed track that gets no update is
// coasting, and is deleted after coast_max_s without an update (a parked object: not a mover,
// slower than mover_min_speed, after parked_coast_max_s: stopped traffic may hide it for longer)
// or when its position std exceeds max_position_std. A parked object missed on the previous scan
// is looked for where it was last measured, in its rectangle grown by the association's
// gate_margin only: it does not move while hidden (Predict). Of two tracks whose rectangles overlap by more than duplicate_overlap of
// the smaller one, one is deleted: a small object inside a vehicle's rectangle, else the one with
// fewer updates, else the younger. Ids are never reused within a run.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "tracker/core/association.h"
#include "tracker/core/box.h"
#include "tracker/core/ekf.h"
#include "tracker/core/fitting.h"
#include "tracker/core/shape.h"

namespace vtrack {

enum class TrackerMode { kMht, kIsm, kVasm };
const char* ToString(TrackerMode mode);
bool ParseTrackerMode(const std::string& s, TrackerMode* mode);

enum class TrackStatus : std::int8_t { kTentative = 0, kConfirmed = 1, kCoasting = 2 };  // = track_t
enum class ObjectClass : std::int8_t { kUnknown = 0, kVehicle = 1, kOther = 2 };       // = track_t

struct HypothesisVariant {
  double inside_fraction = 0.5;  // [-] required fraction of the points inside the rectangle
  double noise_scale = 1.0;      // [-] factor on the system noise Q
};

struct TrackManagerParams {
  TrackerMode mode = TrackerMode::kMht;
  int max_hypotheses = 4;                   // [-] per mover, ISM included (paper: four)
  double ism_inside_fraction = 0.5;         // [-] required inside fraction of the ISM (slot 0)
  std::vector<HypothesisVariant> vasm_variants = {{0.5, 1.0}, {0.8, 1.0}, {0.5, 4.0}};
  double mover_confidence = 0.999;          // [-] chi-square (2 dof) test on the velocity
  double mover_min_speed = 1.0;             // [m/s] and at least this speed
  int mover_scans = 6;                      // [-] consecutive scans with evidence of motion
  double ambiguity_deg = 20.0;              // [deg] psi this close to the 45 deg diagonal: ambiguous
  double axis_swap_ratio = 1.3;             // [-] stationary: width > this * length turns theta 90 deg
  int score_window = 10;                    // [-] scans in the fit score
  double switch_margin = 0.1;               // [-] score improvement needed to change the report
  int fail_misses = 3;                      // [-] consecutive misses that mark a failed hypothesis
  int confirm_updates = 3;                  // [-] updates to confirm a track
  int tentative_max_misses = 2;             // [-] consecutive misses that delete a tentative track
  double coast_max_s = 1.5;                 // [s] a confirmed track coasts at most this long
  double parked_coast_max_s = 3.0;          // [s] ... a parked one (not a mover, slower than
                                            //     mover_min_speed) at most this long
  double max_position_std = 4.0;            // [m] tracks less certain than this are deleted
  double duplicate_overlap = 0.5;           // [-] overlap (of the smaller rectangle) of duplicates
  double range_sigma = 0.03;                // [m] LADAR range noise for fitting (Eq. 18's sigma)
  double fit_contour_deg = 0.2;             // [deg] fit the nearest return per bearing bin; 0: all
  // 3-D clouds: a return enters that outline only if another return of its bin lies within
  // contour_support_range of its range and contour_support_height or more above or below it
  // (it stands on a vertical face; roofs and bonnets are grazed by single rings). 0: off.
  double contour_support_height = 0.1;      // [m]
  double contour_support_range = 0.25;      // [m]
  // ... unless no return of a segment has that support and the returns of one ring span at
  // least this much range: one ring over a nearer object sees the top of a face, while a ring
  // grazing a roof or bonnet hits it at one range (0: any unsupported segment).
  double contour_arc_span = 1.0;            // [m]
  // 3-D clouds: the fit on that outline refuses faces seen at less than outline_min_slant_deg
  // and needs outline_min_points points and outline_min_edge_inliers on an edge (the fit's own
  // min_slant_deg, min_points and min_edge_inliers apply to single-plane scans). Each outline
  // point stands on a vertical face, corroborated by other rings: a face seen nearly edge-on
  // (a parked car's side passed 2 m away: 3-6 deg at 20-40 m) gives one such point per azimuth
  // step, 1-2.5 m apart, and is all of that car in view.
  double outline_min_slant_deg = 2.0;       // [deg]
  int outline_min_points = 3;               // [-]
  int outline_min_edge_inliers = 3;         // [-]
  double default_length = 4.5;              // [m] rectangle of a new object before any estimate
  double default_width = 1.8;               // [m]
  double default_dimension_std = 1.0;       // [m] spread of that default
  double small_object_extent = 1.0;         // [m] segments smaller than this are measured by centroid
  double small_object_position_std = 0.15;  // [m] floor of the centroid measurement std
  // A track measured by centroids (first seen small, far away) becomes a rectangle once its
  // segment spans this much: a car's end face seen squarely spans its width, 1.6-1.9 m (2 m
  // before: a car coming into view end-on stayed a centroid at its face, 2.25 m from its centre).
  double small_object_grown_extent = 1.5;   // [m] >= small_object_extent
  // Classification (track_t.object_class) from the estimated size and motion.
  double vehicle_min_length = 2.5;          // [m]
  double vehicle_max_length = 20.0;         // [m]
  double vehicle_min_width = 1.2;           // [m]
  double vehicle_max_width = 2.8;           // [m] (road vehicles are at most 2.6 m wide)
  // Predicted trajectory for the planner.
  double prediction_horizon_s = 3.0;        // [s]
  double prediction_step_s = 0.1;           // [s]

  bool Validate(std::string* error) const;
};

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

struct Track {
  std::int64_t id = 0;
  TrackStatus status = TrackStatus::kTentative;
  bool mover = false;
  int motion_evidence = 0;                // [-] consecutive scans with evidence of motion
  std::int64_t created_utime = 0;         // [us]
  std::int64_t state_utime = 0;           // [us] time of the hypotheses' states
  std::int64_t last_update_utime = 0;     // [us]
  int num_updates = 0;
  int consecutive_misses = 0;             // [-] scans without any update
  bool small_object = false;              // measured by centroid (poles, bushes, pedestrians)
  bool axis_from_full_face = false;       // heading set by a fully seen short face (AlignToFullFace)
  double full_face_extent = 0.0;          // [m] that face's extent (a car's front or rear width)
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

// The nearest return per bearing bin around the sensor, over every return of a scan, per ring of
// a 3-D scanner. It tells whether a fitted face ends where the object ends (free space, or only
// farther returns, just beyond the end: a full view of that face) or where something nearer
// hides the rest of it. Per ring: a 3-D scanner sees over low objects near it (a car's bonnet
// 4 m away hides a face 40 m away from the downward rings only, not from the rings that hit the
// face); a profile over all rings read those as occluders beyond every end of the far face.
class RangeProfile {
 public:
  // bin_deg: bearing bin [deg], > 0. One profile over all returns (a single-plane scanner).
  void Build(const Eigen::Vector2d& sensor_xy, const std::vector<double>& x,
             const std::vector<double>& y, double bin_deg);
  // One profile per ring (ring[i] of return i; rings outside [0, kMaxRings) share the last).
  void Build(const Eigen::Vector2d& sensor_xy, const std::vector<double>& x,
             const std::vector<double>& y, const std::vector<std::int16_t>& ring, double bin_deg);
  // True if, in the `bins` bearing bins just beyond `end` (on the side away from `inner`, the
  // face's other end), no return lies nearer than end's range + margin, on the rings that see
  // the face at its end (a return within margin of end's range in end's bin or the one inside
  // it); on every ring if none does.
  bool FreeBeyond(const Eigen::Vector2d& end, const Eigen::Vector2d& inner, double margin,
                  int bins) const;
  bool empty() const { return nearest_.empty(); }

  static constexpr int kMaxRings = 256;

 private:
  int Bin(const Eigen::Vector2d& p) const;
  float Nearest(int ring, int bin) const {
    return nearest_[static_cast<std::size_t>(ring) * static_cast<std::size_t>(num_bins_) +
                    static_cast<std::size_t>(bin)];
  }
  Eigen::Vector2d sensor_ = Eigen::Vector2d::Zero();
  double inv_bin_ = 0.0;  // [1/rad]
  int num_bins_ = 0;
  int num_rings_ = 0;
  std::vector<float> nearest_;  // [m] per (ring, bin), ring-major; +inf where no return
};

class TrackManager {
 public:
  // Throws std::invalid_argument naming the first invalid parameter.
  TrackManager(const TrackManagerParams& params, const Ekf& ekf, const FitParams& fit,
               const ShapeParams& shape);

  // Association input: every track's reported hypothesis predicted to utime (not stored).
  void Predict(std::int64_t utime, std::vector<PredictedObject>* out) const;

  // Updates track index with its returns; debug (optional) is filled for the scan's debug.
  // profile (optional): the scan's nearest range per bearing, for the full-view test of faces.
  void Update(std::size_t index, const PointSet& points, const Eigen::Vector2d& sensor_xy,
              std::uint64_t seed, TrackDebug* debug, const RangeProfile* profile = nullptr);
  // The reported rectangle of a track at its state time.
  OrientedBox Box(std::size_t index) const;
  // Marks a track without returns on this scan.
  void Miss(std::size_t index);
  // A new track from returns that no track claimed. Returns false if they cannot be measured.
  bool Create(const PointSet& points, const Eigen::Vector2d& sensor_xy, std::uint64_t seed);
  // Life cycle after a scan at utime: confirmation, coasting, deletion, duplicates.
  void EndScan(std::int64_t utime);
  // Every track, its reported hypothesis predicted to utime.
  void Report(std::int64_t utime, std::vector<TrackReport>* out) const;

  void Clear() { tracks_.clear(); }  // ids continue: never reused within a run
  const std::vector<Track>& tracks() const { return tracks_; }
  const TrackManagerParams& params() const { return params_; }

 private:
  // Reported hypothesis of t predicted to utime (forward with Q, backward along the motion).
  Hypothesis PredictedSelected(const Track& t, std::int64_t utime) const;
  void Dimensions(const Track& t, const TrackHypothesis& h, double* length, double* width) const;
  bool Measure(const Track& t, TrackHypothesis* h, const PointSet& points,
               const Eigen::Vector2d& sensor_xy, std::uint64_t seed,
               std::optional<double> predicted_theta, bool small, CentreMeasurement* m,
               std::optional<Eigen::Vector2d> predicted_center = std::nullopt);
  void Select(Track* t) const;
  void Reseed(Track* t) const;
  void TestMotion(Track* t);
  void SpawnVasms(Track* t) const;
  void AlignToShape(Track* t) const;
  void AlignToFullFace(Track* t, const PointSet& points, const Eigen::Vector2d& sensor_xy,
                       std::uint64_t seed, const RangeProfile& profile);
  void AlignVasm(Track* t) const;
  void AlignIsm(Track* t) const;
  bool SmallObject(const PointSet& points) const;
  // Confirmed or coasting, not a mover, and slower than mover_min_speed.
  bool Parked(const Track& t) const;

  TrackManagerParams params_;
  const Ekf& ekf_;
  SegmentFitter fitter_;
  SegmentFitter outline_fitter_;  // fitter_'s parameters with the outline_* overrides
  ShapeParams shape_params_;
  double mover_d2_ = 0.0, mover_d1_ = 0.0;
  std::vector<Track> tracks_;
  std::int64_t next_id_ = 1;
};

}  // namespace vtrack
