// The track manager's parameters (track_manager.h describes what each decides).
#pragma once

#include <string>
#include <vector>

namespace vtrack {

enum class TrackerMode { kMht, kIsm, kVasm };
const char* ToString(TrackerMode mode);
bool ParseTrackerMode(const std::string& s, TrackerMode* mode);

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

}  // namespace vtrack
