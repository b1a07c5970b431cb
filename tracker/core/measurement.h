// Measuring a track on one scan: the robust edge / corner fit (fitting.h, paper Section 2.4) of
// a rectangle sized by the hypothesis' shape estimate, giving z = (x, y, theta) with its
// covariance R (Eq. 18-19); or, for a small object, the centroid of its returns.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <optional>

#include "tracker/core/fitting.h"
#include "tracker/core/motion_model.h"
#include "tracker/core/track.h"
#include "tracker/core/parameters.h"

namespace vtrack {

class TrackMeasurer {
 public:
  TrackMeasurer(const TrackManagerParams& params, const FitParams& fit);

  // Measures hypothesis h from points. small: the track is a small object (centroid; its
  // heading is not observed and is measured as predicted_theta with a flat variance). Otherwise
  // the fit, with the rectangle of Dimensions(); predicted_center (parked tracks) places a
  // partial face along itself. Sets h->fit and h->has_fit. False if nothing could be fitted.
  bool Measure(bool small, const PointSet& points, const Eigen::Vector2d& sensor_xy,
               std::uint64_t seed, std::optional<double> predicted_theta,
               std::optional<Eigen::Vector2d> predicted_center, TrackHypothesis* h,
               CentreMeasurement* m);

  // The rectangle of a hypothesis. A small object: its estimates, else small_object_extent. A
  // vehicle: its estimates, but never less than the default vehicle (a shorter estimate cannot
  // be told from a partial view: occlusion, a face seen edge on).
  void Dimensions(bool small, const TrackHypothesis& h, double* length, double* width) const;

  const FitParams& fit_params() const { return fitter_.params(); }

  // The scan's range profile for the fits that follow (FitRequest::profile; nullptr: none).
  void set_profile(const RangeProfile* profile) { profile_ = profile; }

 private:
  TrackManagerParams params_;
  SegmentFitter fitter_;
  SegmentFitter outline_fitter_;  // fitter_'s parameters with the outline_* overrides
  const RangeProfile* profile_ = nullptr;
};

}  // namespace vtrack
