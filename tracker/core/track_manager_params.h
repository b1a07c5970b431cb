// The track manager's parameters (track_manager.h describes what each decides).
#pragma once

#include <string>
#include <vector>

#include "tracker/core/params.h"

namespace vtrack {

enum class TrackerMode { kMht, kIsm, kVasm };

}  // namespace vtrack

template <>
struct vtrack::param::EnumNames<vtrack::TrackerMode> {
  static constexpr std::array kNames{"mht", "ism", "vasm"};
};

namespace vtrack {

inline const char* ToString(TrackerMode mode) { return param::NameOf(mode); }

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
  double fit_contour_deg = 0.2;
  // 3-D clouds: a return enters that outline only if another return of its bin lies within
  // contour_support_range of its range and contour_support_height or more above or below it
  // (it stands on a vertical face; roofs and bonnets are grazed by single rings). 0: off.
  double contour_support_height = 0.1;
  double contour_support_range = 0.25;
  // ... unless no return of a segment has that support and the returns of one ring span at
  // least this much range: one ring over a nearer object sees the top of a face, while a ring
  // grazing a roof or bonnet hits it at one range (0: any unsupported segment).
  double contour_arc_span = 1.0;
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

  template <class V>
  void Visit(V& v) {
    using namespace param;
    v("mode", &mode, {"-", {}, "mht: ISM and VASM hypotheses per mover; ism or vasm: one model only"});
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
    v("coast_max_s", &coast_max_s, {"s", Above(0), "a confirmed track coasts at most this long"});
    v("parked_coast_max_s", &parked_coast_max_s, {"s", Above(0), "... a parked one (no mover, slower than mover_min_speed) at most this long"});
    v("max_position_std", &max_position_std, {"m", Above(0), "tracks less certain than this are deleted"});
    v("duplicate_overlap", &duplicate_overlap, {"-", OpenClosed(0, 1), "overlap (of the smaller rectangle) that makes two tracks duplicates"});
    v("range_sigma", &range_sigma, {"m", Above(0), "LADAR range noise for fitting (Eq. 18's sigma)"});
    v("fit_contour_deg", &fit_contour_deg, {"deg", Closed(0, 10), "fit the nearest return per bearing bin of this width (0: all returns)"});
    v("contour_support_height", &contour_support_height, {"m", Closed(0, 2), "3-D outline: a return needs another of its bin this far above or below ... (0: off)"});
    v("contour_support_range", &contour_support_range, {"m", OpenClosed(0, 2), "... within this of its range (it stands on a vertical face)"});
    v("contour_arc_span", &contour_arc_span, {"m", AtLeast(0), "unsupported segments still fitted when one ring spans this much range"});
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
  }
  // Enough vasm_variants; outline_min_edge_inliers <= outline_min_points; grown extent >= small
  // extent; vehicle size windows not empty.
  std::string CrossProblem() const;
  bool Validate(std::string* error) const { return param::Validate(*this, error); }
};

}  // namespace vtrack
