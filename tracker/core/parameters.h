// Every parameter of the tracker core, one struct per component, each field declared once: its
// default is the initialiser, and the struct's Visit gives its YAML key, unit, valid range and a
// one-line reason (params.h explains the mechanism). The components' headers describe what each
// decides; docs/parameters.md is written from these lists; config/tracker.yaml mirrors them (one
// YAML section per struct, kSection).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

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

struct PreprocessParams {
  static constexpr const char* kSection = "preprocess";
  static constexpr const char* kAbout =
      "Ego-motion compensation of every return, range limits and ground removal";
  enum class Ground { kNone, kBand, kGrid };

  double min_range = 1.0;
  double max_range = 80.0;
  Ground ground = Ground::kGrid;
  int ground_min_rings = 2;
  double ground_height_body = 0.0;
  double min_height = 0.25;
  double max_height = 3.0;
  double ground_cell = 1.0;
  double ground_tolerance = 0.6;
  double ground_max_slope = 0.05;
  double ground_max_grade = 0.1;
  std::int64_t knot_us = 1000;
  std::int64_t max_points = 500000;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("min_range", &min_range, {"m", AtLeast(0), "nearer returns are dropped (the own vehicle)"});
    v("max_range", &max_range, {"m", OpenClosed(0, 1000), "farther returns are dropped"});
    v("ground", &ground, {"-", {}, "ground removal of 3-D clouds: none, a body-frame band, or a local grid"});
    v("ground_min_rings", &ground_min_rings, {"-", AtLeast(1), "ground removal only for scans with at least this many rings"});
    v("ground_height_body", &ground_height_body, {"m", Finite(), "band method: ground plane height in the body frame"});
    v("min_height", &min_height, {"m", Finite(), "keep returns at least this far above the local ground (kerbs, road paint)"});
    v("max_height", &max_height, {"m", Finite(), "and at most this far (foliage and overhangs above vehicles)"});
    v("ground_cell", &ground_cell, {"m", Closed(0.1, 10), "grid method: cell of the local ground estimate"});
    v("ground_tolerance", &ground_tolerance, {"m", AtLeast(0), "local ground within this of the scan's ground level ..."});
    v("ground_max_slope", &ground_max_slope, {"-", Closed(0, 1), "... plus this per metre from the sensor (slopes, pitch)"});
    v("ground_max_grade", &ground_max_grade, {"-", OpenClosed(0, 10), "and at most this per metre above the lowest return nearby (ground hidden behind an object)"});
    v("knot_us", &knot_us, {"us", Closed(10, 100000), "pose look-ups over the sweep, interpolated between (error (omega knot)^2/8 range)"});
    v("max_points", &max_points, {"-", AtLeast(1), "larger scans are refused (\"huge_scan\")"});
  }
  // max_range > min_range, max_height > min_height.
  std::string CrossProblem() const;
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

}  // namespace vtrack

template <>
struct vtrack::EnumNames<vtrack::PreprocessParams::Ground> {
  static constexpr std::array kNames{"none", "band", "grid"};
};

namespace vtrack {

inline const char* ToString(PreprocessParams::Ground g) { return NameOf(g); }

struct SegmentationParams {
  static constexpr const char* kSection = "segmentation";
  static constexpr const char* kAbout =
      "Segmentation of the returns into objects: range jumps on a scan line, grid components in 3-D";
  double jump_abs = 0.6;
  double jump_rel = 0.02;
  double cell_size = 0.3;
  int connectivity = 4;
  double grid_radius = 80.0;
  int min_points = 3;
  double max_extent = 25.0;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("jump_abs", &jump_abs, {"m", Above(0), "scan line: a segment breaks where consecutive returns lie farther apart than this ..."});
    v("jump_rel", &jump_rel, {"-", ClosedOpen(0, 1), "... or this fraction of the range"});
    v("cell_size", &cell_size, {"m", Closed(0.05, 5), "3-D clouds: grid cell of the connected components"});
    v("connectivity", &connectivity, {"-", Closed(4, 8), "grid neighbourhood, 4 or 8 (8 joins cars parked 0.6 m apart)"});
    v("grid_radius", &grid_radius, {"m", Above(0), "half-size of the grid around the sensor (returns beyond are dropped)"});
    v("min_points", &min_points, {"-", AtLeast(1), "smaller segments are dropped"});
    v("max_extent", &max_extent, {"m", Above(0), "segments with a larger bounding-box diagonal (walls, buildings) are dropped"});
  }
  // connectivity is 4 or 8; the grid holds at most 4000 cells across.
  std::string CrossProblem() const;
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

// Pieces of a face seen at a grazing angle (grazing_pieces.h): segments smaller than max_piece
// whose centroids lie within max_gap of each other along a line within max_deg of the ray are one
// segment, as long as it stays within max_extent.
struct GrazingJoinParams {
  static constexpr const char* kSection = "grazing";
  static constexpr const char* kAbout =
      "Pieces of one face seen at a grazing angle joined into one segment";
  double max_piece = 1.0;
  double max_gap = 2.5;
  double max_deg = 10.0;
  double max_extent = 5.0;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("max_piece", &max_piece, {"m", Closed(0, 10), "bounding-box diagonal of a piece (0: no joining)"});
    v("max_gap", &max_gap, {"m", OpenClosed(0, 20), "centroid distance of two pieces (cars of a row are 3 m or more apart)"});
    v("max_deg", &max_deg, {"deg", ClosedOpen(0, 90), "angle between the line of two pieces and the ray"});
    v("max_extent", &max_extent, {"m", Closed(0, 50), "bounding-box diagonal of the joined segment (>= max_piece)"});
  }
  // max_extent >= max_piece.
  std::string CrossProblem() const {
    if (!(max_extent >= max_piece)) return param::Problem("max_extent", max_extent, "m", ">= max_piece");
    return {};
  }
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

struct AssociationParams {
  static constexpr const char* kSection = "association";
  static constexpr const char* kAbout =
      "Segments to tracks: gates, costs, splitting and merging, grazing pieces (Eq. 15)";
  double gate_margin = 0.8;
  double gate_sigma = 3.0;
  double max_gate_margin = 4.0;
  double min_inside_fraction = 0.3;
  double outside_penalty = 2.0;
  double miss_cost = 3.0;
  double merge_fraction = 0.6;
  double ignore_max_extent = 1.0;
  int split_min_points = 3;
  double min_slant_deg = 10.0;
  // Columns behind a mover (PredictedObject::rear_sign) whose axis lies within mover_column_deg
  // of the ray: across the ray at most mover_column_width, and the mover with them at most
  // mover_max_length long.
  double mover_column_deg = 20.0;
  double mover_max_length = 12.0;
  double mover_column_width = 0.5;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("gate_margin", &gate_margin, {"m", AtLeast(0), "the predicted rectangle grown by this on every side ..."});
    v("gate_sigma", &gate_sigma, {"-", AtLeast(0), "... plus this many predicted position standard deviations ..."});
    v("max_gate_margin", &max_gate_margin, {"m", AtLeast(0), "... at most this (>= gate_margin)"});
    v("min_inside_fraction", &min_inside_fraction, {"-", OpenClosed(0, 1), "share of a segment's returns inside the gate to be a candidate"});
    v("outside_penalty", &outside_penalty, {"m", AtLeast(0), "cost per unit share of a segment's returns outside the gate, and per unit share of the gate's candidate returns it holds fewer of than the candidate holding most"});
    v("miss_cost", &miss_cost, {"m", Above(0), "cost of leaving a track unassigned"});
    v("merge_fraction", &merge_fraction, {"-", OpenClosed(0, 1), "a leftover segment joins an assigned track above this share inside"});
    v("ignore_max_extent", &ignore_max_extent, {"m", Closed(0, 10), "smaller leftovers inside a track's gate are ignored"});
    v("split_min_points", &split_min_points, {"-", AtLeast(1), "each part of a split segment has at least this many returns"});
    v("min_slant_deg", &min_slant_deg, {"deg", ClosedOpen(0, 90), "s of Eq. 15: faces seen more edge-on are not visible"});
    v("mover_column_deg", &mover_column_deg, {"deg", ClosedOpen(0, 90), "a leftover column whose axis lies this close to the ray may be a mover's side seen edge-on ..."});
    v("mover_max_length", &mover_max_length, {"m", AtLeast(0), "... if the mover with it stays at most this long ..."});
    v("mover_column_width", &mover_column_width, {"m", AtLeast(0), "... and it spans at most this across the ray"});
  }
  // max_gate_margin >= gate_margin.
  std::string CrossProblem() const;
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

// The outline a rectangle is fitted to (outline.h): per bearing bin the nearest return; in a 3-D
// cloud only a return standing on a vertical face (roofs and bonnets are grazed by single rings).
struct OutlineParams {
  static constexpr const char* kSection = "outline";
  static constexpr const char* kAbout =
      "The outline of a segment that the rectangle is fitted to: nearest returns per bearing bin";
  double bin_deg = 0.2;
  double support_height = 0.1;
  double support_range = 0.25;
  double arc_span = 1.0;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("bin_deg", &bin_deg, {"deg", Closed(0, 10), "bearing bin: the nearest return of each is fitted (0: every return); also the range profile's bin"});
    v("support_height", &support_height, {"m", Closed(0, 2), "3-D: a return needs another of its bin this far above or below it ... (0: off)"});
    v("support_range", &support_range, {"m", OpenClosed(0, 2), "... within this of its range (it stands on a vertical face)"});
    v("arc_span", &arc_span, {"m", AtLeast(0), "3-D: a segment without support is still fitted when one ring spans this much range (a face's top seen over something nearer; 0: any)"});
  }
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

struct FitParams {
  static constexpr const char* kSection = "fit";
  static constexpr const char* kAbout =
      "Robust edge and corner fitting (Section 3, Eqs. 15-18), RANSAC then Gauss-Newton";
  double min_slant_deg = 10.0;
  double inlier_sigmas = 3.0;
  double min_inlier_distance_m = 0.03;
  double surface_std_m = 0.02;
  int max_edge_iterations = 100;
  int max_corner_iterations = 200;
  int min_iterations = 10;
  double ransac_confidence = 0.99;
  int max_scoring_points = 96;
  double min_sample_separation_m = 0.2;
  int min_points = 5;
  int min_edge_inliers = 4;
  double min_second_edge_fraction = 0.1;
  double min_inlier_fraction = 0.3;
  int gauss_newton_iterations = 1;
  double max_inlier_gap_m = 0.5;
  double max_gap_spacings = 5.0;
  double inside_margin_m = 0.2;
  double partial_view_sigmas = 2.0;
  double variance_factor_sigmas = 3.0;
  double side_face_min_excess_m = 0.4;
  double side_face_min_incidence_deg = 60.0;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("min_slant_deg", &min_slant_deg, {"deg", ClosedOpen(0, 45), "s of Eq. 15: least angle between a fitted face and the ray"});
    v("inlier_sigmas", &inlier_sigmas, {"-", Above(0), "a point is an inlier within this many sigma_perp of an edge"});
    v("min_inlier_distance_m", &min_inlier_distance_m, {"m", AtLeast(0), "floor of that inlier threshold"});
    v("surface_std_m", &surface_std_m, {"m", AtLeast(0), "face-normal noise not explained by range noise (curved bodies)"});
    v("max_edge_iterations", &max_edge_iterations, {"-", AtLeast(1), "cap of RANSAC iterations on 2-point edge hypotheses"});
    v("max_corner_iterations", &max_corner_iterations, {"-", AtLeast(0), "cap of RANSAC iterations on 3-point corner hypotheses (0: no corners)"});
    v("min_iterations", &min_iterations, {"-", AtLeast(0), "RANSAC iterations before adaptive stopping"});
    v("ransac_confidence", &ransac_confidence, {"-", Open(0, 1), "probability of drawing one all-inlier sample"});
    v("max_scoring_points", &max_scoring_points, {"-", AtLeast(8), "hypotheses are scored on a seeded subset of at most this many points"});
    v("min_sample_separation_m", &min_sample_separation_m, {"m", AtLeast(0), "least distance between the sample points of an edge"});
    v("min_points", &min_points, {"-", AtLeast(3), "segments with fewer points are not fitted"});
    v("min_edge_inliers", &min_edge_inliers, {"-", AtLeast(3), "least inliers of each fitted edge"});
    v("min_second_edge_fraction", &min_second_edge_fraction, {"-", Closed(0, 0.5), "each edge of a corner holds at least this share of its inliers"});
    v("min_inlier_fraction", &min_inlier_fraction, {"-", Closed(0, 1), "least share of the segment's points that are inliers"});
    v("gauss_newton_iterations", &gauss_newton_iterations, {"-", Closed(0, 20), "weighted Gauss-Newton steps on Eq. 16 (paper: one)"});
    v("max_inlier_gap_m", &max_inlier_gap_m, {"m", Above(0), "inliers beyond a larger gap along an edge are dropped (parked rows: rear faces ~0.8 m apart)"});
    v("max_gap_spacings", &max_gap_spacings, {"-", AtLeast(1), "... unless the gap is within this many median point spacings (missing returns) and, on 3-D scans, not seen through"});
    v("inside_margin_m", &inside_margin_m, {"m", AtLeast(0), "the rectangle grown by this for the inside fraction"});
    v("partial_view_sigmas", &partial_view_sigmas, {"-", AtLeast(0), "an extent shorter than the shape by more sigmas is a partial view"});
    v("variance_factor_sigmas", &variance_factor_sigmas, {"-", Finite(), "significance for scaling R by chi^2/dof (<= 0: never)"});
    v("side_face_min_excess_m", &side_face_min_excess_m, {"m", AtLeast(0), "new object: a single face longer than its width + this is a side ..."});
    v("side_face_min_incidence_deg", &side_face_min_incidence_deg, {"deg", OpenClosed(0, 90), "... or one seen at a larger incidence (90: off)"});
  }
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

struct IsmParams {
  static constexpr const char* kSection = "ism";
  static constexpr const char* kAbout =
      "Independent steering model (Section 2.1)";
  double alpha = 2.0;
  double beta = 0.3;
  double initial_velocity_std = 10.0;
  double initial_yaw_rate_std = 0.5;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("alpha", &alpha, {"m^2/s^3", Above(0), "spectral density of the white acceleration in x and in y (Eq. 2)"});
    v("beta", &beta, {"rad^2/s^3", Above(0), "spectral density of the white angular acceleration (Eq. 4)"});
    v("initial_velocity_std", &initial_velocity_std, {"m/s", Above(0), "std of x_dot and y_dot from a single measurement (not observed yet)"});
    v("initial_yaw_rate_std", &initial_yaw_rate_std, {"rad/s", Above(0), "std of theta_dot from a single measurement"});
  }
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

struct VasmParams {
  static constexpr const char* kSection = "vasm";
  static constexpr const char* kAbout =
      "Variable-axis Ackerman steering model (Section 2.2)";
  double alpha = 2.0;
  double gamma = 0.3;
  double epsilon_L = 0.01;
  // Prior of L where a conversion cannot tell it (from an ISM state, or after turning theta),
  // for a vehicle that drives forwards: a car's rear axle is about 1.2 m behind the centre. If
  // the centre moves against theta (v < 0), theta most likely points to the vehicle's back, and
  // the prior mean is -initial_L (axis ahead of the centre along theta); a reversing vehicle then
  // starts with L of the wrong sign and has to learn it (paper Section 2.2: estimating L adapts
  // the model to either orientation). A symmetric prior (mean 0, std 1.5 m) was tried: on the
  // turn of motion_consistency_test, 2% of VASMs drifted to L of the wrong sign on the straight
  // before the turn and were lost in it; with this prior none of 500 were.
  double initial_L = -1.2;
  double initial_L_std = 1.0;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("alpha", &alpha, {"m^2/s^3", Above(0), "spectral density of the along-arc acceleration on v"});
    v("gamma", &gamma, {"rad^2/s^3", Above(0), "spectral density of the angular acceleration"});
    v("epsilon_L", &epsilon_L, {"m^2/s", AtLeast(0), "random-walk density of L: Q_L = epsilon_L dt"});
    v("initial_L", &initial_L, {"m", Closed(-20, 20), "prior of L: a car's rear axle ~1.2 m behind its centre"});
    v("initial_L_std", &initial_L_std, {"m", Above(0), "std of that prior"});
  }
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

struct CvParams {
  static constexpr const char* kSection = "cv";
  static constexpr const char* kAbout =
      "Constant-velocity reference model (AB3DMOT's): constant centre velocity, heading a random walk";
  // A CV hypothesis starts as an ISM one (ism.initial_velocity_std) without its yaw rate.
  // Fitted by scripts/fit-cv-noise to the labelled cars and vans of the KITTI training
  // sequences in the boxes layout (world-frame trajectories at a lag of 1 s).
  double alpha = 0.54;
  double q_theta = 0.0051;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("alpha", &alpha, {"m^2/s^3", Above(0), "white acceleration density in x and in y, fitted to KITTI car trajectories (scripts/fit-cv-noise)"});
    v("q_theta", &q_theta, {"rad^2/s", Above(0), "heading random-walk density (no yaw-rate state), fitted likewise"});
  }
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

struct EkfParams {
  static constexpr const char* kSection = "ekf";
  static constexpr const char* kAbout =
      "The extended Kalman filter shared by both models";
  double gate_probability = 0.999;

  template <class V>
  void Visit(V& v) {
    v("gate_probability", &gate_probability, {"-", param::Open(0, 1), "a consistent measurement passes the NIS gate (chi-square, 3 dof: 0.999 -> 16.27)"});
  }
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

struct ShapeParams {
  static constexpr const char* kSection = "shape";
  static constexpr const char* kAbout =
      "Adaptive shape: decaying histograms of length and width (Section 4)";
  double half_life = 3.0;
  double bin_width = 0.05;
  double max_dimension = 20.0;
  double excluded_fraction = 0.05;
  double smoothing_std = 0.15;
  double min_peak_fraction = 0.25;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("half_life", &half_life, {"s", Above(0), "a sample's weight halves every half_life"});
    v("bin_width", &bin_width, {"m", OpenClosed(0, 10), "histogram bin width"});
    v("max_dimension", &max_dimension, {"m", OpenClosed(0, 1e4), "histogram range (0, max]; larger samples are outliers, never a peak"});
    v("excluded_fraction", &excluded_fraction, {"-", ClosedOpen(0, 1), "top share of the weight excluded as outliers"});
    v("smoothing_std", &smoothing_std, {"m", AtLeast(0), "std of the Gaussian kernel smoothing the histogram"});
    v("min_peak_fraction", &min_peak_fraction, {"-", OpenClosed(0, 1), "least height of a peak relative to the highest"});
  }
  // max_dimension spans 2 to 1e5 bins; smoothing_std at most 100 bins.
  std::string CrossProblem() const;
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

enum class TrackerMode { kMht, kIsm, kVasm, kCv };

}  // namespace vtrack

template <>
struct vtrack::EnumNames<vtrack::TrackerMode> {
  static constexpr std::array kNames{"mht", "ism", "vasm", "cv"};
};

namespace vtrack {

inline const char* ToString(TrackerMode mode) { return NameOf(mode); }

struct HypothesisVariant {
  double inside_fraction = 0.5;
  double noise_scale = 1.0;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("inside_fraction", &inside_fraction, {"-", Closed(0, 1), "required share of the returns inside the rectangle"});
    v("noise_scale", &noise_scale, {"-", OpenClosed(0, 100), "factor on the system noise Q"});
  }
};

struct TrackManagerParams {
  static constexpr const char* kSection = "manager";
  static constexpr const char* kAbout =
      "Hypotheses, outline, life cycle, classification and prediction of each track";
  TrackerMode mode = TrackerMode::kMht;
  int max_hypotheses = 4;
  double ism_inside_fraction = 0.5;
  std::vector<HypothesisVariant> vasm_variants = {{0.5, 1.0}, {0.8, 1.0}, {0.5, 4.0}};
  double mover_confidence = 0.999;
  double mover_min_speed = 1.0;
  int mover_scans = 6;
  double ambiguity_deg = 20.0;
  double axis_swap_ratio = 1.3;
  int score_window = 10;
  double switch_margin = 0.1;
  int fail_misses = 3;
  int confirm_updates = 3;
  int tentative_max_misses = 2;
  double coast_max_s = 1.5;
  double parked_coast_max_s = 3.0;
  double max_position_std = 4.0;
  double duplicate_overlap = 0.5;
  double range_sigma = 0.03;
  // 3-D clouds: the fit on that outline refuses faces seen at less than outline_min_slant_deg
  // and needs outline_min_points points and outline_min_edge_inliers on an edge (the fit's own
  // min_slant_deg, min_points and min_edge_inliers apply to single-plane scans). Each outline
  // point stands on a vertical face, corroborated by other rings: a face seen nearly edge-on
  // (a parked car's side passed 2 m away: 3-6 deg at 20-40 m) gives one such point per azimuth
  // step, 1-2.5 m apart, and is all of that car in view.
  double outline_min_slant_deg = 2.0;
  int outline_min_points = 3;
  int outline_min_edge_inliers = 3;
  double default_length = 4.5;
  double default_width = 1.8;
  double default_dimension_std = 1.0;
  double small_object_extent = 1.0;
  double small_object_position_std = 0.15;
  // A track measured by centroids (first seen small, far away) becomes a rectangle once its
  // segment spans this much: a car's end face seen squarely spans its width, 1.6-1.9 m (2 m
  // before: a car coming into view end-on stayed a centroid at its face, 2.25 m from its centre).
  double small_object_grown_extent = 1.5;
  double vehicle_min_length = 2.5;
  double vehicle_max_length = 20.0;
  double vehicle_min_width = 1.2;
  double vehicle_max_width = 2.8;
  double prediction_horizon_s = 3.0;
  double prediction_step_s = 0.1;
  // The planner acts on vehicles; a trajectory per clutter track cost about 6% of a KITTI
  // sweep's instructions for output nobody reads.
  bool predict_all_tracks = false;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("mode", &mode, {"-", {}, "mht: ISM and VASM hypotheses per mover; ism or vasm: one model only; cv: the constant-velocity reference (no yaw rate)"});
    v("max_hypotheses", &max_hypotheses, {"-", Closed(1, 4), "hypotheses per mover, ISM included (paper: four)"});
    v("ism_inside_fraction", &ism_inside_fraction, {"-", Closed(0, 1), "required inside share of the ISM hypothesis (slot 0)"});
    v("vasm_variants", &vasm_variants, {"-", {}, "the VASM hypotheses: inside share and noise factor each (max_hypotheses - 1 used)"});
    v("mover_confidence", &mover_confidence, {"-", Open(0, 1), "chi-square (2 dof) test of a non-zero velocity"});
    v("mover_min_speed", &mover_min_speed, {"m/s", AtLeast(0), "and at least this speed"});
    v("mover_scans", &mover_scans, {"-", AtLeast(1), "consecutive scans with evidence of motion make a mover"});
    v("ambiguity_deg", &ambiguity_deg, {"deg", Closed(0, 45), "psi this close to the 45 deg diagonal: the corner is ambiguous"});
    v("axis_swap_ratio", &axis_swap_ratio, {"-", AtLeast(1), "stationary: width > this x length turns theta by 90 deg"});
    v("score_window", &score_window, {"-", AtLeast(1), "scans in a hypothesis' fit score"});
    v("switch_margin", &switch_margin, {"-", AtLeast(0), "score improvement needed to change the reported hypothesis"});
    v("fail_misses", &fail_misses, {"-", AtLeast(1), "consecutive misses that fail a hypothesis"});
    v("confirm_updates", &confirm_updates, {"-", AtLeast(1), "updates that confirm a track"});
    v("tentative_max_misses", &tentative_max_misses, {"-", AtLeast(1), "consecutive misses that delete a tentative track"});
    v("coast_max_s", &coast_max_s, {"s", Above(0), "a confirmed track lives at most this long without an accepted update"});
    v("parked_coast_max_s", &parked_coast_max_s, {"s", Above(0), "... a parked one (no mover, slower than mover_min_speed) at most this long"});
    v("max_position_std", &max_position_std, {"m", Above(0), "tracks less certain than this are deleted"});
    v("duplicate_overlap", &duplicate_overlap, {"-", OpenClosed(0, 1), "overlap (of the smaller rectangle) that makes two tracks duplicates"});
    v("range_sigma", &range_sigma, {"m", Above(0), "LADAR range noise for fitting (Eq. 18's sigma); on 3-D scans also the uncertainty at or below which a fitted length or width counts as one whole sample of the shape's histogram (docs/design.md, note 8)"});
    v("outline_min_slant_deg", &outline_min_slant_deg, {"deg", ClosedOpen(0, 45), "3-D outline fit: least angle of a face to the ray"});
    v("outline_min_points", &outline_min_points, {"-", AtLeast(3), "3-D outline fit: least points"});
    v("outline_min_edge_inliers", &outline_min_edge_inliers, {"-", AtLeast(3), "3-D outline fit: least inliers of an edge (<= outline_min_points)"});
    v("default_length", &default_length, {"m", OpenClosed(0, 30), "rectangle of a new object before any estimate (a car)"});
    v("default_width", &default_width, {"m", OpenClosed(0, 10), "its width"});
    v("default_dimension_std", &default_dimension_std, {"m", AtLeast(0), "spread of that default"});
    v("small_object_extent", &small_object_extent, {"m", AtLeast(0), "smaller segments are measured by their centroid"});
    v("small_object_position_std", &small_object_position_std, {"m", Above(0), "floor of the centroid measurement std"});
    v("small_object_grown_extent", &small_object_grown_extent, {"m", AtLeast(0), "a centroid track becomes a rectangle once its segment spans this (a car's end face: 1.6-1.9 m)"});
    v("vehicle_min_length", &vehicle_min_length, {"m", AtLeast(0), "class vehicle: estimated length at least this ..."});
    v("vehicle_max_length", &vehicle_max_length, {"m", AtLeast(0), "... at most this"});
    v("vehicle_min_width", &vehicle_min_width, {"m", AtLeast(0), "... width at least this ..."});
    v("vehicle_max_width", &vehicle_max_width, {"m", AtLeast(0), "... at most this (road vehicles are at most 2.6 m wide)"});
    v("prediction_horizon_s", &prediction_horizon_s, {"s", Closed(0, 30), "predicted trajectory for the planner: horizon"});
    v("prediction_step_s", &prediction_step_s, {"s", OpenClosed(0, 1), "its step"});
    v("predict_all_tracks", &predict_all_tracks, {"-", {}, "predicted trajectory for every track; false: vehicles only (the planner's), the rest report none"});
  }
  // Enough vasm_variants; outline_min_edge_inliers <= outline_min_points; grown extent >= small
  // extent; vehicle size windows not empty.
  std::string CrossProblem() const;
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

// What the tracker measures tracks with: the LADAR's scans (fitted outlines), a detector's
// boxes, or both (fused: boxes update and start tracks between scans; scans drive the life
// cycle and the reports).
enum class InputMode { kScans, kBoxes, kFused };

}  // namespace vtrack

template <>
struct vtrack::EnumNames<vtrack::InputMode> {
  static constexpr std::array kNames{"scans", "boxes", "fused"};
};

namespace vtrack {

inline const char* ToString(InputMode mode) { return NameOf(mode); }

struct DetectionParams {
  static constexpr const char* kSection = "detections";
  static constexpr const char* kAbout =
      "A detector's boxes: input mode and their measurement model";
  InputMode mode = InputMode::kScans;
  // Every box of PointRCNN (its scores on the KITTI training sequences are >= -0.85): the weak
  // ones are mostly far cars (median score 0.5 at 60-70 m), which they keep tracked, and the
  // track score ranks them low. On the ten training sequences of the boxes layout, -1 instead of
  // 2 raises sAMOTA (3-D IoU 0.25, mode mht) from 84.1 to 86.7 and the devkit's MOTA from 77.7 to
  // 80.4; vtrack-eval's MOTA (centre gate 2 m, within 40 m) falls from 0.840 to 0.816 (more false
  // positives near the threshold, which sAMOTA's sweep removes).
  double min_score = -1.0;
  double birth_score = 2.0;
  double position_std = 0.25;
  double heading_std_deg = 6.0;
  double gate_m = 2.0;
  double gate_sigma = 3.0;
  double max_gate_m = 5.0;
  bool fused_vehicle_needs_box = true;
  double score_memory = 10.0;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("mode", &mode, {"-", {}, "what measures tracks: scans (fitted outlines), boxes (a detector's), or both (fused)"});
    v("min_score", &min_score, {"-", Finite(), "boxes below this score, on the detector's own scale, are not used"});
    v("birth_score", &birth_score, {"-", Finite(), "a box starts a track only from this score on, and a track is a vehicle from this mean box score on (weaker ones are tracked, scored and exported as other)"});
    v("position_std", &position_std, {"m", OpenClosed(0, 10), "1-sigma of a box centre along each axis"});
    v("heading_std_deg", &heading_std_deg, {"deg", OpenClosed(0, 90), "1-sigma of a box heading (modulo 180 deg)"});
    v("gate_m", &gate_m, {"m", Above(0), "a box farther than this (+ gate_sigma predicted position stds) from a track is not its candidate"});
    v("gate_sigma", &gate_sigma, {"-", AtLeast(0), "predicted position stds added to gate_m"});
    v("max_gate_m", &max_gate_m, {"m", OpenClosed(0, 50), "upper bound of the whole gate (>= gate_m), and the cost of a track going without a box in the association"});
    v("fused_vehicle_needs_box", &fused_vehicle_needs_box, {"-", {}, "fused: a track is a vehicle only while its boxes would confirm it (manager.confirm_updates boxes, the latest within manager.coast_max_s); scan-only tracks are other: the size rules alone class walls and hedges as cars"});
    v("score_memory", &score_memory, {"-", Closed(1, 1000), "a track's score: mean of its boxes' scores, each update weighted 1/min(n, this) (recent boxes count more; 10: about 1 s at 10 Hz)"});
  }
  // gate_m <= max_gate_m.
  std::string CrossProblem() const;
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

// The vehicle evidence of a track (vehicle_evidence.h): per scan a model of what the scan
// measured of the track (boosted trees or a logistic model), accumulated over its life as
// log-odds. The trees, terms and biases are fitted by scripts/fit-vehicle-evidence from tracks
// labelled against ground truth; the defaults here are its output, which
// scripts/check-parameters carries into config/tracker.yaml.
enum class EvidenceFeature : std::int8_t {
  kLogPoints,      // [-] ln(returns of the track on the scan)
  kLogRange,       // [-] ln(range of their centroid from the sensor / 1 m)
  kHeightMax,      // [m] highest return above the local ground (3-D)
  kHeightMedian,   // [m] median height above the local ground (3-D)
  kHeightMin,      // [m] lowest (3-D): free space under a car body is low, under a crown high
  kColumnTop,      // [m] median over the returns of the highest return in their ground cell,
                   //     above preprocess.max_height too (a car's roof against a crown or a
                   //     building; 3-D, grid ground), at most 10 m
  kTopBeam,        // [-] ln(1 + returns from the scan's highest beam): the object reaches above
                   //     what that beam sees at its range (a tree or a wall close by looks no
                   //     taller than the beam; a car stays under it; 3-D)
  kLength,         // [m] the shape estimate of the reported hypothesis; missing (NaN) if none
  kWidth,          // [m] likewise: a single edge seen so far measures no width
  kSegmentExtent,  // [m] bounding-box diagonal of the largest segment holding the returns (walls)
  kHiddenEnds,     // [-] ends of the returns (extreme bearings) not free: something nearer just
                   //     beyond, or the object going on (0 a car seen whole, 2 a wall in a gap)
  kSpeed,          // [m/s] of the reported hypothesis' centre
  kMover,          // [-] 1 if judged a mover
  kSmall,          // [-] 1 if measured by its centroid (small object)
  kLengthUnseen,   // [-] 1 if the hypothesis has no length estimate yet
  kWidthUnseen,    // [-] 1 if it has no width estimate yet (one face seen)
  kInlierShare,    // [-] share of the fitted returns within the inlier threshold of the fitted
                   //     faces: a body panel is smooth at the range noise, foliage scatters its
                   //     returns through its depth; missing (NaN) if the scan gave no fit
  kRoughness,      // [m] median distance of a return from the chord through its two neighbours
                   //     along its ring (SurfaceRoughness): the range noise on a body panel or
                   //     a wall, the depth a ray travels into foliage on a hedge or a crown;
                   //     missing (NaN) with too few such triplets
  kCount
};

}  // namespace vtrack

template <>
struct vtrack::EnumNames<vtrack::EvidenceFeature> {
  static constexpr std::array kNames{"log_points", "log_range", "height_max", "height_median",
                                     "height_min", "column_top", "top_beam", "length", "width",
                                     "segment_extent", "hidden_ends", "speed", "mover", "small",
                                     "length_unseen", "width_unseen", "inlier_share",
                                     "roughness"};
};

namespace vtrack {

// One term of the per-scan logit: weight * ((feature - center) / scale)^power; 0 while the
// feature is missing (not finite), as if it were at its training mean.
struct EvidenceTerm {
  EvidenceFeature feature = EvidenceFeature::kLogPoints;
  int power = 1;
  double center = 0.0;
  double scale = 1.0;
  double weight = 0.0;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("feature", &feature, {"-", {}, "which measured feature"});
    v("power", &power, {"-", Closed(1, 2), "1: linear, 2: quadratic (a window: e.g. a car's height)"});
    v("center", &center, {"feature's unit", Finite(), "subtracted before the power (the training mean)"});
    v("scale", &scale, {"feature's unit", Above(0), "divides after centring (the training std)"});
    v("weight", &weight, {"-", Finite(), "fitted coefficient of the logistic model"});
  }
};

// One node of a tree of a boosted ensemble (EvidenceParams::trees_3d, trees_2d). A tree's nodes
// are contiguous in the list, its root first; a split sends the scan left if its feature is at
// most threshold or missing (the fit gave missing features a value below every threshold), a
// leaf adds its value to the scan's logit.
struct EvidenceNode {
  int tree = 0;
  EvidenceFeature feature = EvidenceFeature::kLogPoints;
  double threshold = 0.0;
  int left = -1;
  int right = -1;
  double value = 0.0;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("tree", &tree, {"-", AtLeast(0), "the tree the node belongs to (its nodes are contiguous, the root first)"});
    v("feature", &feature, {"-", {}, "split: the feature compared"});
    v("threshold", &threshold, {"feature's unit", Finite(), "split: at most this (or missing) goes left"});
    v("left", &left, {"-", AtLeast(-1), "split: index of the left child in the list; -1: a leaf"});
    v("right", &right, {"-", AtLeast(-1), "split: index of the right child; -1: a leaf"});
    v("value", &value, {"-", Finite(), "leaf: added to the logit (learning rate included)"});
  }
};

// The per-scan model of the vehicle evidence: a logistic model on standardised features and
// their squares, or a boosted ensemble of shallow trees (interactions: a single long face with
// free ends against a short piece of wall); fitted, the better held-out log-likelihood chosen.
enum class EvidenceModel : std::int8_t { kLogistic, kTrees };

enum class VehicleClassifier : std::int8_t { kRules, kEvidence };
// How a track's scans add up (vehicle_evidence.h): a discounted sum of their log-likelihood
// ratios, or an exponential average of their log posterior odds.
enum class EvidenceAccumulation : std::int8_t { kSum, kAverage };

}  // namespace vtrack

template <>
struct vtrack::EnumNames<vtrack::EvidenceModel> {
  static constexpr std::array kNames{"logistic", "trees"};
};

template <>
struct vtrack::EnumNames<vtrack::EvidenceAccumulation> {
  static constexpr std::array kNames{"sum", "average"};
};

#include "tracker/core/vehicle_evidence_fit.h"  // the fitted defaults below (generated)

template <>
struct vtrack::EnumNames<vtrack::VehicleClassifier> {
  static constexpr std::array kNames{"rules", "evidence"};
};

namespace vtrack {

struct EvidenceParams {
  static constexpr const char* kSection = "evidence";
  static constexpr const char* kAbout =
      "Vehicle evidence of each track: a fitted per-scan model (boosted trees or logistic) accumulated as log-odds";
  VehicleClassifier classifier_3d = VehicleClassifier::kEvidence;
  VehicleClassifier classifier_2d = VehicleClassifier::kEvidence;
  double prior = evidence_fit::kPrior;
  double prior_2d = evidence_fit::kPrior2D;
  EvidenceAccumulation accumulation = evidence_fit::kAccumulation;
  double scan_weight = evidence_fit::kScanWeight;
  double max_log_odds = 6.0;
  double vehicle_probability = 0.5;
  double keep_probability = evidence_fit::kKeepProbability;
  EvidenceModel model_3d = evidence_fit::kModel3D;
  double bias_3d = evidence_fit::kBias3D;
  std::vector<EvidenceTerm> terms_3d = evidence_fit::kTerms3D;
  std::vector<EvidenceNode> trees_3d = evidence_fit::kTrees3D;
  EvidenceModel model_2d = evidence_fit::kModel2D;
  double bias_2d = evidence_fit::kBias2D;
  std::vector<EvidenceTerm> terms_2d = evidence_fit::kTerms2D;
  std::vector<EvidenceNode> trees_2d = evidence_fit::kTrees2D;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("classifier_3d", &classifier_3d, {"-", {}, "tracks from 3-D clouds: evidence (the accumulated vehicle probability decides) or rules (size and motion windows, classification.h); evidence: KITTI 0000 mht MOTA 0.68 against -0.63, urban_intersection 0.90 against 0.66 (seed 1)"});
    v("classifier_2d", &classifier_2d, {"-", {}, "tracks from single-plane scans: evidence (the fitted single-plane model: footprint, outline, hidden ends, inlier share, motion; no heights) or rules; evidence: mht MOTA paper_fig4_turn 0.99 against 0.19, fig5 0.67 against 0.60, reversing_and_skid_steer 0.55 against 0.19, fig6 0.61 against 0.54 (seed 1)"});
    v("prior", &prior, {"-", Open(0, 1), "share of vehicle scans in the 3-D fitting set: the 3-D model's logits are posteriors at this prior, and a track first measured in 3-D starts at it (so does one with no evidence yet); fitted"});
    v("prior_2d", &prior_2d, {"-", Open(0, 1), "the same for the single-plane model and tracks first measured by single-plane scans; fitted"});
    v("accumulation", &accumulation, {"-", {}, "sum: L += scan_weight (l - logit(prior)); average: L += scan_weight (l - L), an exponential average of the scans' log posterior odds (scans of one object are far from independent); fitted (the better log-likelihood)"});
    v("scan_weight", &scan_weight, {"-", OpenClosed(0, 1), "the weight of each scan in the accumulation; fitted"});
    v("max_log_odds", &max_log_odds, {"-", Above(0), "the accumulated log-odds are clamped to +-this, so that a track can change its mind"});
    v("vehicle_probability", &vehicle_probability, {"-", Open(0, 1), "a track becomes a vehicle when its accumulated probability reaches this (0.5: a report is more likely right than wrong, what MOTA counts; on KITTI 0000 0.4 and 0.6 both score lower in every mode, docs/design.md section 4.10a)"});
    v("keep_probability", &keep_probability, {"-", OpenClosed(0, 1), "a vehicle stays one while its accumulated probability is at least this (<= vehicle_probability; a run of weak scans then does not flip it, each flip cost a fragment); fitted: the fewest held-out wrong decisions"});
    v("model_3d", &model_3d, {"-", {}, "3-D scans: logistic (bias_3d + terms_3d) or trees (bias_3d + trees_3d); fitted: the better held-out log-likelihood"});
    v("bias_3d", &bias_3d, {"-", Finite(), "3-D scans: intercept of the per-scan logit"});
    v("terms_3d", &terms_3d, {"-", {}, "3-D scans: the logistic model's terms (fitted)"});
    v("trees_3d", &trees_3d, {"-", {}, "3-D scans: the boosted trees' nodes (fitted)"});
    v("model_2d", &model_2d, {"-", {}, "single-plane scans: logistic or trees, as model_3d"});
    v("bias_2d", &bias_2d, {"-", Finite(), "single-plane scans: intercept of the per-scan logit"});
    v("terms_2d", &terms_2d, {"-", {}, "single-plane scans: the logistic model's terms (fitted)"});
    v("trees_2d", &trees_2d, {"-", {}, "single-plane scans: the boosted trees' nodes (fitted)"});
  }
  // keep_probability <= vehicle_probability; the chosen family's list is not empty; each tree's
  // children lie after their parent, in the list and in the same tree.
  std::string CrossProblem() const;
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

struct ComputeParams {
  static constexpr const char* kSection = "compute";
  static constexpr const char* kAbout =
      "Threads of the per-scan pipeline: TRACKS do not depend on them, only the latency does";
  int threads = 2;
  bool pin_threads = true;

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("pin_threads", &pin_threads, {"-", {}, "pins the pool's threads in a process that allows it (Tracker::AllowThreadPinning: the live vtrack-tracker), where it may use exactly as many CPUs as threads (a 2-CPU machine, or CPUs chosen with taskset): each thread on its own, the tracker's thread on the first; unpinned, a worker woken after the ~90 ms between sweeps is placed beside the tracker's thread and the two run in turn (KITTI 0000 at 10 Hz, 2 CPUs, wall ms: median 9.3-9.9 pinned against 12.7-13.1 unpinned, p99 13.1-14.1 against 17.5-18.1; over LCM the p99 varies from run to run by more than that: docs/speed.md). With more CPUs nothing is pinned; vtrack-tracker --input never pins"});
    v("threads", &threads, {"-", Closed(1, 64), "threads that share a scan's loops: the returns' placement and ground cells, the range profile beside the segmentation, the tracks' candidate pairs, their updates and the new objects' measurement (each part independent of the others); 1: all on the calling thread. 2 on a 2-core computer: KITTI 0000 bench, see docs/results.md and docs/speed.md"});
  }
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

struct TrackerParams {
  InputParams input;
  PreprocessParams preprocess;
  SegmentationParams segmentation;
  GrazingJoinParams grazing;
  AssociationParams association;
  OutlineParams outline;
  FitParams fit;
  IsmParams ism;
  VasmParams vasm;
  CvParams cv;
  EkfParams ekf;
  ShapeParams shape;
  TrackManagerParams manager;  // includes the mode (mht | ism | vasm | cv)
  DetectionParams detections;  // a detector's boxes: the input mode and their measurement model
  EvidenceParams evidence;     // vehicle evidence of each track
  ComputeParams compute;       // threads

  // Calls v(&section) for every component, in the order of config/tracker.yaml.
  template <class V>
  void VisitSections(V&& v) {
    v(&input);
    v(&preprocess);
    v(&segmentation);
    v(&grazing);
    v(&association);
    v(&outline);
    v(&fit);
    v(&ism);
    v(&vasm);
    v(&cv);
    v(&ekf);
    v(&shape);
    v(&manager);
    v(&detections);
    v(&evidence);
    v(&compute);
  }

  // True if every component is valid; otherwise false and *error names the key and its value.
  bool Validate(std::string* error) const;
};

}  // namespace vtrack
