#include "tracker/core/measurement.h"

#include <algorithm>

namespace vtrack {
namespace {

// The shape's spread once the estimates (not the default lower bound) size the rectangle.
constexpr double kKnownDimensionStd = 0.1;  // [m]

// The fitter's parameters with the 3-D outline's overrides (TrackManagerParams::outline_*).
FitParams OutlineFitParams(const TrackManagerParams& params, const FitParams& fit) {
  FitParams f = fit;
  f.min_slant_deg = params.outline_min_slant_deg;
  f.min_points = params.outline_min_points;
  f.min_edge_inliers = params.outline_min_edge_inliers;
  return f;
}

}  // namespace

TrackMeasurer::TrackMeasurer(const TrackManagerParams& params, const FitParams& fit)
    : params_(params), fitter_(fit), outline_fitter_(OutlineFitParams(params, fit)) {}

void TrackMeasurer::Dimensions(bool small, const TrackHypothesis& h, double* length,
                               double* width) const {
  const auto& l = h.length_est; const auto& w = h.width_est;
  if (small) {
    *length = l ? *l : params_.small_object_extent;
    *width = w ? *w : params_.small_object_extent;
    return;
  }
  *length = std::max(l ? *l : 0.0, params_.default_length);
  *width = std::max(w ? *w : 0.0, params_.default_width);
}

bool TrackMeasurer::Measure(bool small, const PointSet& points, const Eigen::Vector2d& sensor_xy,
                            std::uint64_t seed, std::optional<double> predicted_theta,
                            std::optional<Eigen::Vector2d> predicted_center, TrackHypothesis* h,
                            CentreMeasurement* m) {
  h->has_fit = false;
  if (small) {
    // Centroid measurement of a small object (pole, bush, pedestrian): no rectangle to fit.
    // Its orientation is not observed: theta is measured as predicted with a flat variance.
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    for (std::size_t i = 0; i < points.size(); ++i) c += Eigen::Vector2d(points.x[i], points.y[i]);
    c /= static_cast<double>(points.size());
    const double s = std::max(params_.small_object_position_std, 0.25 * points.extent);
    m->z << points.origin + c, predicted_theta.value_or(0.0);
    m->R = Eigen::Vector3d(s * s, s * s, 1.0).asDiagonal();
    return true;
  }
  FitRequest req;
  req.x = points.x;
  req.y = points.y;
  req.sensor_xy = sensor_xy - points.origin;
  const auto& l = h->length_est; const auto& w = h->width_est;
  Dimensions(small, *h, &req.length_m, &req.width_m);
  req.shape_known = l && w && *l >= params_.default_length && *w >= params_.default_width;
  req.length_std_m = req.shape_known ? kKnownDimensionStd : params_.default_dimension_std;
  req.width_std_m = req.shape_known ? kKnownDimensionStd : params_.default_dimension_std;
  req.predicted_theta = predicted_theta;
  if (predicted_center) req.predicted_center = *predicted_center - points.origin;
  req.range_sigma_m = params_.range_sigma;
  req.min_inside_fraction = h->inside_fraction;
  req.seed = seed;
  req.profile = profile_;
  req.profile_offset = points.origin;
  (points.outline ? outline_fitter_ : fitter_).Fit(req, &h->fit);
  if (h->fit.kind == FitKind::kNone) return false;
  h->has_fit = true;
  m->z << h->fit.z.head<2>() + points.origin, h->fit.z(2);
  m->R = h->fit.R;
  return true;
}

}  // namespace vtrack
