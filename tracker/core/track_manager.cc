#include "tracker/core/track_manager.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "tracker/core/angle.h"
#include "tracker/core/fast_atan2.h"

namespace vtrack {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

bool Check(bool ok, const char* field, double value, const char* unit, const char* requirement,
           std::string* error) {
  return internal::CheckParam(ok, "manager", field, value, unit, requirement, error);
}

OrientedBox BoxOf(const Eigen::Vector3d& pose, double length, double width) {
  OrientedBox b;
  b.center = pose.head<2>();
  b.theta = pose(2);
  b.length = length;
  b.width = width;
  return b;
}

// Pose (x, y, theta) of a hypothesis from its state.
Eigen::Vector3d PoseOf(const MotionModel& m, const Vector6d& x) {
  const auto idx = m.PoseIndices();
  return {x(idx[0]), x(idx[1]), x(idx[2])};
}

// Fraction of a 5 x 3 lattice over the smaller rectangle that lies inside the other.
double Overlap(const OrientedBox& a, const OrientedBox& b) {
  const OrientedBox& s = a.length * a.width <= b.length * b.width ? a : b;
  const OrientedBox& o = &s == &a ? b : a;
  int inside = 0;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector2d q((i - 2) * 0.2 * s.length, (j - 1) * 0.33 * s.width);
      inside += o.Contains(s.ToWorld(q));
    }
  }
  return inside / 15.0;
}

}  // namespace

void RangeProfile::Build(const Eigen::Vector2d& sensor_xy, const std::vector<double>& x,
                         const std::vector<double>& y, double bin_deg) {
  Build(sensor_xy, x, y, {}, bin_deg);
}

void RangeProfile::Build(const Eigen::Vector2d& sensor_xy, const std::vector<double>& x,
                         const std::vector<double>& y, const std::vector<std::int16_t>& ring,
                         double bin_deg) {
  sensor_ = sensor_xy;
  num_bins_ = std::max(1, static_cast<int>(std::ceil(360.0 / bin_deg)));
  inv_bin_ = num_bins_ / (2.0 * kPi);
  const bool rings = ring.size() == x.size();
  auto ring_of = [&](std::size_t i) {
    return rings ? std::clamp<int>(ring[i], 0, kMaxRings - 1) : 0;
  };
  num_rings_ = 1;
  for (std::size_t i = 0; rings && i < x.size(); ++i) num_rings_ = std::max(num_rings_, ring_of(i) + 1);
  nearest_.assign(static_cast<std::size_t>(num_rings_) * static_cast<std::size_t>(num_bins_),
                  std::numeric_limits<float>::infinity());
  // The bin Bin() gives, with Atan2Approx wherever its error bound (with ample slack for the
  // rounding of the sum and product) cannot change the floor; else Bin() itself. Same bins.
  const int n = num_bins_;
  const double slack = 10.0 * kAtan2ApproxMaxError * inv_bin_ + 1e-9;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const Eigen::Vector2d p(x[i], y[i]);
    const Eigen::Vector2d d = p - sensor_;
    const double v = (Atan2Approx(d.y(), d.x()) + kPi) * inv_bin_;
    const double lo = std::floor(v - slack);
    int b;
    if (lo == std::floor(v + slack)) {
      b = static_cast<int>(lo);  // in [-1, n]: the wrap of Bin() without its two divisions
      if (b < 0) b += n;
      else if (b >= n) b -= n;
    } else {
      b = Bin(p);
    }
    float& r = nearest_[static_cast<std::size_t>(ring_of(i)) * static_cast<std::size_t>(n) +
                        static_cast<std::size_t>(b)];
    r = std::min(r, static_cast<float>(d.norm()));
  }
}

int RangeProfile::Bin(const Eigen::Vector2d& p) const {
  const Eigen::Vector2d d = p - sensor_;
  const int n = num_bins_;
  const int b = static_cast<int>(std::floor((std::atan2(d.y(), d.x()) + kPi) * inv_bin_));
  return ((b % n) + n) % n;
}

bool RangeProfile::FreeBeyond(const Eigen::Vector2d& end, const Eigen::Vector2d& inner,
                              double margin, int bins) const {
  if (nearest_.empty()) return false;
  const Eigen::Vector2d de = end - sensor_, di = inner - sensor_;
  // Beyond = the rotation sense from inner to end.
  const int step = de.x() * di.y() - de.y() * di.x() < 0.0 ? 1 : -1;
  const int n = num_bins_;
  const double r = de.norm();
  const int b0 = Bin(end);
  const int b_in = (((b0 - step) % n) + n) % n;
  // The rings that see the face at its end; every ring if none does.
  bool any_on_face = false;
  for (int ring = 0; ring < num_rings_ && !any_on_face; ++ring) {
    any_on_face = std::abs(Nearest(ring, b0) - r) <= margin || std::abs(Nearest(ring, b_in) - r) <= margin;
  }
  for (int ring = 0; ring < num_rings_; ++ring) {
    if (any_on_face && std::abs(Nearest(ring, b0) - r) > margin &&
        std::abs(Nearest(ring, b_in) - r) > margin) {
      continue;
    }
    for (int k = 1; k <= bins; ++k) {
      const int b = (((b0 + step * k) % n) + n) % n;
      if (Nearest(ring, b) < r + margin) return false;
    }
  }
  return true;
}

const char* ToString(TrackerMode mode) {
  switch (mode) {
    case TrackerMode::kMht: return "mht";
    case TrackerMode::kIsm: return "ism";
    case TrackerMode::kVasm: return "vasm";
  }
  return "?";
}

bool ParseTrackerMode(const std::string& s, TrackerMode* mode) {
  if (s == "mht") *mode = TrackerMode::kMht;
  else if (s == "ism") *mode = TrackerMode::kIsm;
  else if (s == "vasm") *mode = TrackerMode::kVasm;
  else return false;
  return true;
}

bool TrackManagerParams::Validate(std::string* error) const {
  const auto& p = *this;
  if (!Check(p.max_hypotheses >= 1 && p.max_hypotheses <= 4, "max_hypotheses", p.max_hypotheses,
             "", "in [1, 4]", error) ||
      !Check(static_cast<int>(p.vasm_variants.size()) >= p.max_hypotheses - 1, "vasm_variants",
             static_cast<double>(p.vasm_variants.size()), "entries", "at least max_hypotheses - 1",
             error) ||
      !Check(p.ism_inside_fraction >= 0 && p.ism_inside_fraction <= 1, "ism_inside_fraction",
             p.ism_inside_fraction, "", "in [0, 1]", error) ||
      !Check(p.mover_confidence > 0 && p.mover_confidence < 1, "mover_confidence",
             p.mover_confidence, "", "in (0, 1)", error) ||
      !Check(p.mover_min_speed >= 0, "mover_min_speed", p.mover_min_speed, "m/s", ">= 0", error) ||
      !Check(p.mover_scans >= 1, "mover_scans", p.mover_scans, "", ">= 1", error) ||
      !Check(p.ambiguity_deg >= 0 && p.ambiguity_deg <= 45, "ambiguity_deg", p.ambiguity_deg,
             "deg", "in [0, 45]", error) ||
      !Check(p.axis_swap_ratio >= 1, "axis_swap_ratio", p.axis_swap_ratio, "", ">= 1", error) ||
      !Check(p.score_window >= 1, "score_window", p.score_window, "", ">= 1", error) ||
      !Check(p.switch_margin >= 0, "switch_margin", p.switch_margin, "", ">= 0", error) ||
      !Check(p.fail_misses >= 1, "fail_misses", p.fail_misses, "", ">= 1", error) ||
      !Check(p.confirm_updates >= 1, "confirm_updates", p.confirm_updates, "", ">= 1", error) ||
      !Check(p.tentative_max_misses >= 1, "tentative_max_misses", p.tentative_max_misses, "",
             ">= 1", error) ||
      !Check(p.coast_max_s > 0, "coast_max_s", p.coast_max_s, "s", "> 0", error) ||
      !Check(p.parked_coast_max_s > 0, "parked_coast_max_s", p.parked_coast_max_s, "s", "> 0",
             error) ||
      !Check(p.max_position_std > 0, "max_position_std", p.max_position_std, "m", "> 0", error) ||
      !Check(p.duplicate_overlap > 0 && p.duplicate_overlap <= 1, "duplicate_overlap",
             p.duplicate_overlap, "", "in (0, 1]", error) ||
      !Check(p.range_sigma > 0 && std::isfinite(p.range_sigma), "range_sigma", p.range_sigma, "m",
             "> 0", error) ||
      !Check(p.fit_contour_deg >= 0 && p.fit_contour_deg <= 10, "fit_contour_deg",
             p.fit_contour_deg, "deg", "in [0, 10]", error) ||
      !Check(p.contour_support_height >= 0 && p.contour_support_height <= 2,
             "contour_support_height", p.contour_support_height, "m", "in [0, 2]", error) ||
      !Check(p.contour_support_range > 0 && p.contour_support_range <= 2, "contour_support_range",
             p.contour_support_range, "m", "in (0, 2]", error) ||
      !Check(p.contour_arc_span >= 0, "contour_arc_span", p.contour_arc_span, "m", ">= 0",
             error) ||
      !Check(p.outline_min_slant_deg >= 0 && p.outline_min_slant_deg < 45,
             "outline_min_slant_deg", p.outline_min_slant_deg, "deg", "in [0, 45)", error) ||
      !Check(p.outline_min_points >= 3, "outline_min_points", p.outline_min_points, "", ">= 3",
             error) ||
      !Check(p.outline_min_edge_inliers >= 3 && p.outline_min_edge_inliers <= p.outline_min_points,
             "outline_min_edge_inliers", p.outline_min_edge_inliers, "",
             "in [3, outline_min_points]", error) ||
      !Check(p.default_length > 0 && p.default_length <= 30, "default_length", p.default_length,
             "m", "in (0, 30]", error) ||
      !Check(p.default_width > 0 && p.default_width <= 10, "default_width", p.default_width, "m",
             "in (0, 10]", error) ||
      !Check(p.default_dimension_std >= 0, "default_dimension_std", p.default_dimension_std, "m",
             ">= 0", error) ||
      !Check(p.small_object_extent >= 0, "small_object_extent", p.small_object_extent, "m", ">= 0",
             error) ||
      !Check(p.small_object_grown_extent >= p.small_object_extent, "small_object_grown_extent",
             p.small_object_grown_extent, "m", ">= small_object_extent", error) ||
      !Check(p.small_object_position_std > 0, "small_object_position_std",
             p.small_object_position_std, "m", "> 0", error) ||
      !Check(p.vehicle_max_length >= p.vehicle_min_length, "vehicle_max_length",
             p.vehicle_max_length, "m", ">= vehicle_min_length", error) ||
      !Check(p.vehicle_max_width >= p.vehicle_min_width, "vehicle_max_width", p.vehicle_max_width,
             "m", ">= vehicle_min_width", error) ||
      !Check(p.prediction_horizon_s >= 0 && p.prediction_horizon_s <= 30, "prediction_horizon_s",
             p.prediction_horizon_s, "s", "in [0, 30]", error) ||
      !Check(p.prediction_step_s > 0 && p.prediction_step_s <= 1, "prediction_step_s",
             p.prediction_step_s, "s", "in (0, 1]", error)) {
    return false;
  }
  for (std::size_t i = 0; i < p.vasm_variants.size(); ++i) {
    const auto& v = p.vasm_variants[i];
    if (!Check(v.inside_fraction >= 0 && v.inside_fraction <= 1, "vasm_variants.inside_fraction",
               v.inside_fraction, "", "in [0, 1]", error) ||
        !Check(v.noise_scale > 0 && v.noise_scale <= 100, "vasm_variants.noise_scale",
               v.noise_scale, "", "in (0, 100]", error)) {
      return false;
    }
  }
  return true;
}

double TrackHypothesis::Score() const {
  if (score_terms.empty()) return kInf;
  return std::accumulate(score_terms.begin(), score_terms.end(), 0.0) /
         static_cast<double>(score_terms.size());
}

TrackManager::TrackManager(const TrackManagerParams& params, const Ekf& ekf,
                           const FitParams& fit, const ShapeParams& shape)
    : params_(params),
      ekf_(ekf),
      fitter_(fit),
      outline_fitter_([&] {
        FitParams f = fit;
        f.min_slant_deg = params.outline_min_slant_deg;
        f.min_points = params.outline_min_points;
        f.min_edge_inliers = params.outline_min_edge_inliers;
        return f;
      }()),
      shape_params_(shape) {
  std::string error;
  if (!params_.Validate(&error)) throw std::invalid_argument(error);
  if (!shape_params_.Validate(&error)) throw std::invalid_argument(error);
  mover_d2_ = ChiSquareQuantile(params_.mover_confidence, 2);
  mover_d1_ = ChiSquareQuantile(params_.mover_confidence, 1);
}

Hypothesis TrackManager::PredictedSelected(const Track& t, std::int64_t utime) const {
  const TrackHypothesis& h = t.hyps[static_cast<std::size_t>(t.selected)];
  Hypothesis out = h.filter;
  const double dt = static_cast<double>(utime - t.state_utime) * 1e-6;
  if (dt > 0.0) {
    ekf_.Predict(dt, h.noise_scale, &out);
  } else if (dt < 0.0) {
    // Back along the same motion; the noise of |dt| is added (conservative, not subtracted).
    const MotionModel& m = ekf_.model(out.kind);
    Matrix6d Phi;
    const Vector6d x = m.Propagate(out.x, dt, &Phi);
    out.P = Phi * out.P * Phi.transpose() + h.noise_scale * m.ProcessNoise(out.x, -dt);
    out.P = 0.5 * (out.P + out.P.transpose()).eval();
    out.x = x;
  }
  return out;
}

void TrackManager::Dimensions(const Track& t, const TrackHypothesis& h, double* length,
                              double* width) const {
  const auto& l = h.length_est; const auto& w = h.width_est;
  if (t.small_object) {
    *length = l ? *l : params_.small_object_extent;
    *width = w ? *w : params_.small_object_extent;
    return;
  }
  // A shorter estimate than the default vehicle cannot be told from a partial view (occlusion,
  // a face seen edge on): the default is the lower bound of the rectangle that places the centre.
  *length = std::max(l ? *l : 0.0, params_.default_length);
  *width = std::max(w ? *w : 0.0, params_.default_width);
}

void TrackManager::Predict(std::int64_t utime, std::vector<PredictedObject>* out) const {
  out->clear();
  for (const Track& t : tracks_) {
    const Hypothesis h = PredictedSelected(t, utime);
    const MotionModel& m = ekf_.model(h.kind);
    const auto idx = m.PoseIndices();
    double length, width;
    Dimensions(t, t.hyps[static_cast<std::size_t>(t.selected)], &length, &width);
    PredictedObject p;
    p.box = BoxOf(PoseOf(m, h.x), length, width);
    const TrackHypothesis& sel = t.hyps[static_cast<std::size_t>(t.selected)];
    p.established = t.status != TrackStatus::kTentative;
    const double a = h.P(idx[0], idx[0]), b = h.P(idx[0], idx[1]), c = h.P(idx[1], idx[1]);
    p.position_std = std::sqrt(std::max(0.0, 0.5 * (a + c) + std::hypot(0.5 * (a - c), b)));
    if (t.consecutive_misses > 0 && Parked(t)) {
      // A parked object stays where it is while it is hidden: its rectangle where it was last
      // measured, grown by gate_margin only. Predicted with its residual velocity and the gate
      // grown with the motion noise over the missed scans, a lot car hidden for 0.5 s by a
      // passing vehicle took in the face of the car parked 0.8 m beside it and slid onto it.
      p.box = BoxOf(PoseOf(ekf_.model(sel.filter.kind), sel.filter.x), length, width);
      p.position_std = 0.0;
    }
    p.seen_length = sel.length_est.value_or(0.0);
    p.seen_width = sel.width_est.value_or(0.0);
    if (t.mover) {
      // Its rear is known only while it moves (a mover stopped at a light keeps the flag).
      const CentreEstimate c = ekf_.Centre(h);
      const Eigen::Vector2d axis(std::cos(p.box.theta), std::sin(p.box.theta));
      if (c.speed >= params_.mover_min_speed) p.rear_sign = c.velocity.dot(axis) >= 0.0 ? -1 : 1;
    }
    out->push_back(p);
  }
}

bool TrackManager::Parked(const Track& t) const {
  if (t.status == TrackStatus::kTentative || t.mover) return false;
  return ekf_.Centre(t.hyps[static_cast<std::size_t>(t.selected)].filter).speed <
         params_.mover_min_speed;
}

bool TrackManager::SmallObject(const PointSet& points) const {
  return points.extent < params_.small_object_extent;
}

bool TrackManager::Measure(const Track& t, TrackHypothesis* h, const PointSet& points,
                           const Eigen::Vector2d& sensor_xy, std::uint64_t seed,
                           std::optional<double> predicted_theta, bool small,
                           CentreMeasurement* m, std::optional<Eigen::Vector2d> predicted_center) {
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
  Dimensions(t, *h, &req.length_m, &req.width_m);
  // Known once the estimates, not the default lower bound, size the rectangle.
  req.shape_known = l && w && *l >= params_.default_length && *w >= params_.default_width;
  req.length_std_m = req.shape_known ? 0.1 : params_.default_dimension_std;
  req.width_std_m = req.shape_known ? 0.1 : params_.default_dimension_std;
  req.predicted_theta = predicted_theta;
  if (predicted_center) req.predicted_center = *predicted_center - points.origin;
  req.range_sigma_m = params_.range_sigma;
  req.min_inside_fraction = h->inside_fraction;
  req.seed = seed;
  (points.outline ? outline_fitter_ : fitter_).Fit(req, &h->fit);
  if (h->fit.kind == FitKind::kNone) return false;
  h->has_fit = true;
  m->z << h->fit.z.head<2>() + points.origin, h->fit.z(2);
  m->R = h->fit.R;
  return true;
}

void TrackManager::Update(std::size_t index, const PointSet& points,
                          const Eigen::Vector2d& sensor_xy, std::uint64_t seed,
                          TrackDebug* debug, const RangeProfile* profile) {
  Track& t = tracks_[index];
  const std::int64_t tm = std::max(points.mean_utime, t.state_utime);
  const double dt = static_cast<double>(tm - t.state_utime) * 1e-6;
  if (debug) {
    const Hypothesis ph = PredictedSelected(t, tm);
    double length, width;
    Dimensions(t, t.hyps[static_cast<std::size_t>(t.selected)], &length, &width);
    debug->predicted = BoxOf(PoseOf(ekf_.model(ph.kind), ph.x), length, width);
  }
  for (auto& h : t.hyps) {
    if (dt > 0.0) ekf_.Predict(dt, h.noise_scale, &h.filter);
  }
  t.state_utime = tm;
  const double time_s = static_cast<double>(tm) * 1e-6;
  if (t.small_object && points.extent >= params_.small_object_grown_extent) {
    // A far object first seen as a few returns has grown into a rectangle: its orientation was
    // never measured (centroid updates), so it is taken afresh from this fit, keeping the
    // centre velocity; the shape starts over. Its hypotheses reduce to the first one.
    TrackHypothesis& h0 = t.hyps[0];
    TrackHypothesis fresh;
    fresh.shape = ShapeEstimator(shape_params_);
    fresh.inside_fraction = h0.inside_fraction;
    fresh.noise_scale = h0.noise_scale;
    CentreMeasurement m;
    // Fitted as a vehicle's rectangle (the default dimensions), not the small object's: which
    // face a single edge is (side or end) is judged against the default width.
    t.small_object = false;
    const bool fitted = Measure(t, &fresh, points, sensor_xy, seed, std::nullopt, false, &m) &&
                        m.z.allFinite();
    t.small_object = !fitted;
    if (fitted) {
      const Hypothesis old_ism = ekf_.Convert(t.hyps[static_cast<std::size_t>(t.selected)].filter,
                                              ModelKind::kIsm, 0.0);
      Hypothesis ism = ekf_.InitIsm(m);
      for (int i : {1, 3}) {  // centre velocity and its covariance carry over
        ism.x(i) = old_ism.x(i);
        for (int j : {1, 3}) ism.P(i, j) = old_ism.P(i, j);
      }
      fresh.filter = params_.mode == TrackerMode::kVasm
                         ? ekf_.Convert(ism, ModelKind::kVasm, 0.0)
                         : ism;
      fresh.last_logdet = h0.last_logdet;
      fresh.score_terms = h0.score_terms;
      fresh.has_fit = false;
      t.hyps.clear();
      t.hyps.push_back(std::move(fresh));
      t.selected = 0;
      // Centroids of a few returns slide along a surface as the view changes: motion judged
      // from them is not evidence; the test starts over on the rectangle.
      t.mover = false;
      t.motion_evidence = 0;
    }
  }

  bool any = false;
  // A parked car's partial face is placed along itself where predicted (FitRequest::
  // predicted_center). Not a mover's: measured against KITTI 0000 with movers too, HOTA fell in
  // every mode (mht 0.442 -> 0.400); the same view of a mover does not repeat scan after scan.
  const bool parked = Parked(t);
  for (std::size_t k = 0; k < t.hyps.size(); ++k) {
    TrackHypothesis& h = t.hyps[k];
    h.updated_this_scan = false;
    const MotionModel& model = ekf_.model(h.filter.kind);
    const Eigen::Vector3d pose = PoseOf(model, h.filter.x);
    CentreMeasurement m;
    double term = 0.5 * (ekf_.gate_nis() + h.last_logdet);
    // Same request for every hypothesis but the heading and the shape: the seed is shared so
    // hypotheses that agree get the same fit.
    if (Measure(t, &h, points, sensor_xy, seed, pose(2), t.small_object, &m,
                parked ? std::optional<Eigen::Vector2d>(pose.head<2>()) : std::nullopt)) {
      const auto idx = model.PoseIndices();
      Eigen::Matrix3d S;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) S(r, c) = h.filter.P(idx[r], idx[c]);
      S += m.R;
      const double det = (2.0 * kPi * S).determinant();
      const double logdet = det > 0.0 ? std::log(det) : h.last_logdet;
      const UpdateResult res = ekf_.Update(m, &h.filter);
      if (res.accepted) {
        term = 0.5 * (res.nis + logdet);
        h.last_logdet = logdet;
        h.last_nis = res.nis;
        h.consecutive_misses = 0;
        h.updated_this_scan = true;
        any = true;
        if (t.small_object) {
          // Extent of the returns along and across the estimated heading.
          const double th = h.filter.x(model.PoseIndices()[2]);
          const Eigen::Vector2d ax(std::cos(th), std::sin(th)), nx(-ax.y(), ax.x());
          double a0 = kInf, a1 = -kInf, n0 = kInf, n1 = -kInf;
          for (std::size_t i = 0; i < points.size(); ++i) {
            const Eigen::Vector2d p(points.x[i], points.y[i]);
            a0 = std::min(a0, p.dot(ax));
            a1 = std::max(a1, p.dot(ax));
            n0 = std::min(n0, p.dot(nx));
            n1 = std::max(n1, p.dot(nx));
          }
          h.shape.AddLength(time_s, std::max(0.1, a1 - a0));
          h.shape.AddWidth(time_s, std::max(0.1, n1 - n0));
        } else if (h.has_fit) {
          if (std::isfinite(h.fit.observed_length_m)) h.shape.AddLength(time_s, h.fit.observed_length_m);
          if (std::isfinite(h.fit.observed_width_m)) h.shape.AddWidth(time_s, h.fit.observed_width_m);
          h.length_seen_full = h.length_seen_full || h.fit.length_full_view;
          h.width_seen_full = h.width_seen_full || h.fit.width_full_view;
        }
        h.RefreshShape();
      } else {
        term = 0.5 * (ekf_.gate_nis() + logdet);
      }
    }
    if (!h.updated_this_scan) ++h.consecutive_misses;
    h.score_terms.push_back(term);
    while (static_cast<int>(h.score_terms.size()) > params_.score_window) h.score_terms.pop_front();
  }
  if (any) {
    ++t.num_updates;
    t.consecutive_misses = 0;
    t.last_update_utime = tm;
  } else {
    ++t.consecutive_misses;
  }
  Select(&t);
  Reseed(&t);
  if (any) TestMotion(&t);
  if (any && !t.mover && !t.small_object && profile && !profile->empty()) {
    AlignToFullFace(&t, points, sensor_xy, seed, *profile);
  }
  if (any && !t.mover && !t.small_object && !t.axis_from_full_face) AlignToShape(&t);

  if (debug) {
    const TrackHypothesis& h = t.hyps[static_cast<std::size_t>(t.selected)];
    debug->track_id = t.id;
    debug->visible_faces = VisibleFaces(debug->predicted, sensor_xy, DegToRad(fitter_.params().min_slant_deg));
    debug->point_x.resize(points.size());
    debug->point_y.resize(points.size());
    debug->point_edge.assign(points.size(), FitResult::kOutlier);
    for (std::size_t i = 0; i < points.size(); ++i) {
      debug->point_x[i] = static_cast<float>(points.origin.x() + points.x[i]);
      debug->point_y[i] = static_cast<float>(points.origin.y() + points.y[i]);
    }
    if (h.has_fit) {
      debug->fit_kind = h.fit.kind;
      debug->z << h.fit.z.head<2>() + points.origin, h.fit.z(2);
      debug->R = h.fit.R;
      for (int e = 0; e < h.fit.num_edges; ++e) {
        const auto& ed = h.fit.edges[static_cast<std::size_t>(e)];
        debug->edges.push_back({ed.start.x() + points.origin.x(), ed.start.y() + points.origin.y(),
                                ed.end.x() + points.origin.x(), ed.end.y() + points.origin.y()});
      }
      if (h.fit.point_edge.size() == points.size()) debug->point_edge = h.fit.point_edge;
    }
    const CentreEstimate ce = ekf_.Centre(h.filter);
    double length, width;
    Dimensions(t, h, &length, &width);
    debug->updated = BoxOf(ce.pose, length, width);
    debug->updated_cov = ce.pose_cov;
    debug->rear_axle.fill(kNaN);
    if (h.filter.kind == ModelKind::kVasm) {
      // The rotation axis: the line across the vehicle at L from the centre along theta.
      const Eigen::Vector2d axis = debug->updated.center + ce.rear_axle_offset * debug->updated.Axis();
      const Eigen::Vector2d half = 0.5 * width * debug->updated.Normal();
      debug->rear_axle = {axis.x() - half.x(), axis.y() - half.y(), axis.x() + half.x(),
                          axis.y() + half.y()};
    }
    debug->hypotheses.clear();
    for (std::size_t k = 0; k < t.hyps.size(); ++k) {
      const TrackHypothesis& hk = t.hyps[k];
      const Eigen::Vector3d pose = PoseOf(ekf_.model(hk.filter.kind), hk.filter.x);
      HypothesisReport r;
      r.index = static_cast<int>(k);
      r.model = hk.filter.kind;
      r.selected = static_cast<int>(k) == t.selected;
      r.state = hk.filter.x;
      r.cov = hk.filter.P;
      r.x = pose(0);
      r.y = pose(1);
      r.theta = pose(2);
      r.rear_axle_offset = hk.filter.kind == ModelKind::kVasm ? hk.filter.x(2) : kNaN;
      r.score = hk.Score();
      r.nis = hk.updated_this_scan ? hk.last_nis : kNaN;
      r.consecutive_misses = hk.consecutive_misses;
      r.inside_fraction = hk.inside_fraction;
      r.noise_scale = hk.noise_scale;
      debug->hypotheses.push_back(r);
    }
  }
}

OrientedBox TrackManager::Box(std::size_t index) const {
  const Track& t = tracks_[index];
  const TrackHypothesis& h = t.hyps[static_cast<std::size_t>(t.selected)];
  double length, width;
  Dimensions(t, h, &length, &width);
  return BoxOf(PoseOf(ekf_.model(h.filter.kind), h.filter.x), length, width);
}

void TrackManager::Miss(std::size_t index) { ++tracks_[index].consecutive_misses; }

bool TrackManager::Create(const PointSet& points, const Eigen::Vector2d& sensor_xy,
                          std::uint64_t seed) {
  Track t;
  t.small_object = SmallObject(points);
  TrackHypothesis h;
  h.shape = ShapeEstimator(shape_params_);
  h.inside_fraction = params_.mode == TrackerMode::kVasm && !params_.vasm_variants.empty()
                          ? params_.vasm_variants[0].inside_fraction
                          : params_.ism_inside_fraction;
  CentreMeasurement m;
  if (!Measure(t, &h, points, sensor_xy, seed, std::nullopt, t.small_object, &m)) return false;
  if (!m.z.allFinite() || !m.R.allFinite()) return false;
  h.filter = ekf_.InitIsm(m);
  if (params_.mode == TrackerMode::kVasm) h.filter = ekf_.Convert(h.filter, ModelKind::kVasm, 0.0);
  const double time_s = static_cast<double>(points.mean_utime) * 1e-6;
  if (t.small_object) {
    // Axis-aligned extents (theta = 0 for a centroid measurement).
    float x0 = points.x[0], x1 = x0, y0 = points.y[0], y1 = y0;
    for (std::size_t i = 1; i < points.size(); ++i) {
      x0 = std::min(x0, points.x[i]);
      x1 = std::max(x1, points.x[i]);
      y0 = std::min(y0, points.y[i]);
      y1 = std::max(y1, points.y[i]);
    }
    h.shape.AddLength(time_s, std::max(0.1, static_cast<double>(x1 - x0)));
    h.shape.AddWidth(time_s, std::max(0.1, static_cast<double>(y1 - y0)));
  } else if (h.has_fit) {
    if (std::isfinite(h.fit.observed_length_m)) h.shape.AddLength(time_s, h.fit.observed_length_m);
    if (std::isfinite(h.fit.observed_width_m)) h.shape.AddWidth(time_s, h.fit.observed_width_m);
    h.length_seen_full = h.fit.length_full_view;
    h.width_seen_full = h.fit.width_full_view;
  }
  h.RefreshShape();
  h.last_logdet = std::log(std::max(1e-300, (2.0 * kPi * m.R).determinant()));
  h.score_terms.push_back(0.5 * (3.0 + h.last_logdet));
  t.id = next_id_++;
  t.created_utime = points.mean_utime;
  t.state_utime = points.mean_utime;
  t.last_update_utime = points.mean_utime;
  t.num_updates = 1;
  t.hyps.push_back(std::move(h));
  tracks_.push_back(std::move(t));
  return true;
}

void TrackManager::Select(Track* t) const {
  int best = t->selected;
  double best_score = t->hyps[static_cast<std::size_t>(best)].Score();
  for (std::size_t k = 0; k < t->hyps.size(); ++k) {
    const double s = t->hyps[k].Score();
    if (s < best_score - params_.switch_margin || !std::isfinite(best_score)) {
      best = static_cast<int>(k);
      best_score = s;
    }
  }
  t->selected = best;
}

void TrackManager::Reseed(Track* t) const {
  const TrackHypothesis& sel = t->hyps[static_cast<std::size_t>(t->selected)];
  if (!sel.updated_this_scan) return;
  for (std::size_t k = 0; k < t->hyps.size(); ++k) {
    if (static_cast<int>(k) == t->selected) continue;
    TrackHypothesis& h = t->hyps[k];
    if (h.consecutive_misses < params_.fail_misses) continue;
    h.filter = ekf_.Convert(sel.filter, h.filter.kind, 0.0);
    h.shape = sel.shape;
    h.RefreshShape();
    h.length_seen_full = sel.length_seen_full;
    h.width_seen_full = sel.width_seen_full;
    h.score_terms = sel.score_terms;
    h.last_logdet = sel.last_logdet;
    h.consecutive_misses = 0;
  }
}

void TrackManager::TestMotion(Track* t) {
  const TrackHypothesis& sel = t->hyps[static_cast<std::size_t>(t->selected)];
  const CentreEstimate c = ekf_.Centre(sel.filter);
  const Eigen::Matrix2d C = 0.5 * (c.velocity_cov + c.velocity_cov.transpose());
  Eigen::LLT<Eigen::Matrix2d> llt(C);
  bool evidence = false;
  if (sel.has_fit && sel.fit.kind == FitKind::kEdge && c.velocity.allFinite()) {
    // A single edge fixes the position across the face only: along it the centre follows the
    // extent of the returns, which slides as the view changes. Only the velocity across the
    // face is evidence of motion (1-dof test).
    const Eigen::Vector2d n(-std::sin(sel.fit.phi), std::cos(sel.fit.phi));
    const double vn = n.dot(c.velocity), var = n.dot(C * n);
    evidence = var > 0.0 && vn * vn / var > mover_d1_ && std::abs(vn) >= params_.mover_min_speed;
  } else if (sel.has_fit && llt.info() == Eigen::Success && c.velocity.allFinite()) {
    const double d2 = c.velocity.dot(llt.solve(c.velocity));
    evidence = d2 > mover_d2_ && c.speed >= params_.mover_min_speed;
  }
  // Without a fit (centroid of a few returns, or the fit failed) there is no evidence either way:
  // a centroid slides with the view just the same.
  if (!sel.has_fit) return;  // no evidence either way: the count is kept
  t->motion_evidence = evidence ? t->motion_evidence + 1 : 0;
  if (!t->mover && t->motion_evidence >= params_.mover_scans) {
    t->mover = true;
    AlignIsm(t);
    AlignVasm(t);
  } else if (t->mover && evidence) {
    AlignIsm(t);
  }
  // Small objects (pedestrians, poles) have no rectangle for a VASM to steer.
  if (t->mover && params_.mode == TrackerMode::kMht && t->hyps.size() == 1 && !t->small_object) {
    SpawnVasms(t);
  }
}

void TrackManager::AlignIsm(Track* t) const {
  // A moving vehicle drives along its length axis: turn ISM hypotheses whose heading is more
  // than 45 deg + ambiguity_deg / 2 off the velocity heading by the multiple of 90 deg that
  // brings them nearest (and flip those pointing backwards).
  for (auto& h : t->hyps) {
    if (h.filter.kind != ModelKind::kIsm) continue;
    const CentreEstimate c = ekf_.Centre(h.filter);
    const double theta = h.filter.x(4);
    const double off = AngleDiff(c.velocity_heading, theta);
    const int k = static_cast<int>(std::lround(off / (0.5 * kPi)));  // -2..2
    if (k == 0) continue;
    const double residual = std::abs(AngleDiff(c.velocity_heading, theta + k * 0.5 * kPi));
    if (std::abs(k) % 2 == 1 &&
        residual > DegToRad(45.0 - 0.5 * params_.ambiguity_deg)) {
      continue;  // too near the diagonal to tell
    }
    h.filter = ekf_.Convert(h.filter, ModelKind::kIsm, k * 0.5 * kPi);
    if (std::abs(k) % 2 == 1) {
      h.shape.SwapLengthAndWidth();
      h.RefreshShape();
      std::swap(h.length_seen_full, h.width_seen_full);
    }
  }
}

void TrackManager::AlignVasm(Track* t) const {
  // Mode vasm: a VASM started from one fit may point backwards (theta + pi, v < 0, L > 0
  // describe the same motion). At the mover declaration it is turned to point along its motion,
  // (theta, v, L) -> (theta + pi, -v, -L), P -> D P D^T with D = diag(1, 1, -1, -1, 1, 1).
  for (auto& h : t->hyps) {
    if (h.filter.kind != ModelKind::kVasm || h.filter.x(3) >= 0.0) continue;
    Matrix6d D = Matrix6d::Identity();
    D(2, 2) = D(3, 3) = -1.0;
    h.filter.x = D * h.filter.x;
    h.filter.x(4) = WrapToPi(h.filter.x(4) + kPi);
    h.filter.P = D * h.filter.P * D.transpose();
  }
}

void TrackManager::AlignToShape(Track* t) const {
  // The length axis of a vehicle is its longer side. A first fit of a partly seen object may
  // take the wrong axis (a corner whose long side is still hidden), and later fits keep the
  // heading nearest the prediction; once the estimated "width" clearly exceeds the "length",
  // the heading turns by 90 deg and the dimensions swap. Not while the "width" is shorter than
  // any vehicle's length: a car's end face seen whole (1.8 m) beside the first metre of its side
  // is not a side.
  for (auto& h : t->hyps) {
    if (h.filter.kind != ModelKind::kIsm || !h.length_est || !h.width_est) continue;
    if (*h.width_est <= std::max(params_.axis_swap_ratio * *h.length_est,
                                 params_.vehicle_min_length)) {
      continue;
    }
    h.filter = ekf_.Convert(h.filter, ModelKind::kIsm, 0.5 * kPi);
    h.shape.SwapLengthAndWidth();
    h.RefreshShape();
    std::swap(h.length_seen_full, h.width_seen_full);
  }
}

void TrackManager::AlignToFullFace(Track* t, const PointSet& points,
                                   const Eigen::Vector2d& sensor_xy, std::uint64_t seed,
                                   const RangeProfile& profile) {
  const TrackHypothesis& sel = t->hyps[static_cast<std::size_t>(t->selected)];
  if (!sel.updated_this_scan || !sel.has_fit || sel.filter.kind != ModelKind::kIsm) return;
  constexpr double kMargin = 0.5;  // [m] a return this much nearer than a face's end hides it
  constexpr int kBins = 3;         // [-] bearing bins (0.2 deg) looked at beyond each end
  for (int e = 0; e < sel.fit.num_edges; ++e) {
    const FittedEdge& ed = sel.fit.edges[static_cast<std::size_t>(e)];
    const Eigen::Vector2d a = ed.start + points.origin, b = ed.end + points.origin;
    const double extent = (b - a).norm();
    if (extent >= params_.vehicle_min_length || extent < 0.5 * params_.vehicle_min_width) continue;
    // A corner's start is the corner itself (seen); an edge needs both ends free.
    const bool start_free = sel.fit.kind == FitKind::kCorner ||
                            profile.FreeBeyond(a, b, kMargin, kBins);
    if (!start_free || !profile.FreeBeyond(b, a, kMargin, kBins)) continue;
    // A fully seen face shorter than a vehicle: the front or rear. The heading is across it.
    const double face_dir = std::atan2((b - a).y(), (b - a).x());
    const double theta = sel.filter.x(4);
    const bool along = std::abs(std::sin(AngleDiff(theta, face_dir))) < std::sin(DegToRad(45.0));
    if (along) {
      for (auto& h : t->hyps) {
        if (h.filter.kind != ModelKind::kIsm) continue;
        const Hypothesis old = ekf_.Convert(h.filter, ModelKind::kIsm, 0.5 * kPi);
        h.shape.SwapLengthAndWidth();
        h.RefreshShape();
        std::swap(h.length_seen_full, h.width_seen_full);
        // The centre moves with the axis (half the default length behind the face instead of
        // half the width): it is measured afresh with the new heading; keeping the old position
        // would turn the jump into a false velocity. The centre velocity carries over.
        CentreMeasurement m;
        if (Measure(*t, &h, points, sensor_xy, seed, old.x(4), false, &m) && m.z.allFinite()) {
          Hypothesis ism = ekf_.InitIsm(m);
          for (int i : {1, 3, 5}) {
            ism.x(i) = old.x(i);
            for (int j : {1, 3, 5}) ism.P(i, j) = old.P(i, j);
          }
          h.filter = ism;
        } else {
          h.filter = old;
        }
      }
    }
    t->axis_from_full_face = true;
    t->full_face_extent = extent;
    return;
  }
}

void TrackManager::SpawnVasms(Track* t) const {
  const TrackHypothesis base = t->hyps[0];
  const CentreEstimate c = ekf_.Centre(base.filter);
  const double theta = PoseOf(ekf_.model(base.filter.kind), base.filter.x)(2);
  const double off = AngleDiff(c.velocity_heading, theta);
  const int k_main = static_cast<int>(std::lround(off / (0.5 * kPi)));
  const double resid = AngleDiff(c.velocity_heading, theta + k_main * 0.5 * kPi);  // [-45, 45] deg
  const bool ambiguous = std::abs(resid) > DegToRad(45.0 - params_.ambiguity_deg);
  const int k_alt = k_main + (resid > 0 ? 1 : -1);
  const int num_vasm = params_.max_hypotheses - 1;
  for (int s = 0; s < num_vasm; ++s) {
    HypothesisVariant v = params_.vasm_variants[static_cast<std::size_t>(s)];
    int k = k_main;
    if (ambiguous && s == 1) {
      v = params_.vasm_variants[0];
      k = k_alt;
    }
    TrackHypothesis h = base;
    h.filter = ekf_.Convert(base.filter, ModelKind::kVasm, k * 0.5 * kPi);
    if (std::abs(k) % 2 == 1) {
      h.shape.SwapLengthAndWidth();
      h.RefreshShape();
      std::swap(h.length_seen_full, h.width_seen_full);
    }
    h.inside_fraction = v.inside_fraction;
    h.noise_scale = v.noise_scale;
    h.consecutive_misses = 0;
    h.has_fit = false;
    t->hyps.push_back(std::move(h));
  }
}

void TrackManager::EndScan(std::int64_t utime) {
  std::vector<char> remove(tracks_.size(), 0);
  for (std::size_t i = 0; i < tracks_.size(); ++i) {
    Track& t = tracks_[i];
    const bool updated = t.consecutive_misses == 0;
    if (t.status == TrackStatus::kTentative) {
      if (t.consecutive_misses >= params_.tentative_max_misses) remove[i] = 1;
      else if (t.num_updates >= params_.confirm_updates) t.status = TrackStatus::kConfirmed;
    } else {
      t.status = updated ? TrackStatus::kConfirmed : TrackStatus::kCoasting;
      // A parked object may stay hidden behind stopped traffic for longer than a moving one
      // may go unseen (max_position_std still applies to both).
      const double coast_max = Parked(t) ? params_.parked_coast_max_s : params_.coast_max_s;
      if (static_cast<double>(utime - t.last_update_utime) * 1e-6 > coast_max) remove[i] = 1;
    }
    const Hypothesis h = PredictedSelected(t, utime);
    const auto idx = ekf_.model(h.kind).PoseIndices();
    const double a = h.P(idx[0], idx[0]), b = h.P(idx[0], idx[1]), c = h.P(idx[1], idx[1]);
    const double lambda = 0.5 * (a + c) + std::hypot(0.5 * (a - c), b);
    if (!(std::sqrt(std::max(0.0, lambda)) <= params_.max_position_std) || !h.x.allFinite()) remove[i] = 1;
  }
  // Duplicates: the younger of two overlapping tracks goes (ids grow with creation).
  std::vector<PredictedObject> boxes;
  Predict(utime, &boxes);
  for (std::size_t i = 0; i < tracks_.size(); ++i) {
    if (remove[i]) continue;
    for (std::size_t j = i + 1; j < tracks_.size(); ++j) {
      if (remove[j]) continue;
      if ((boxes[i].box.center - boxes[j].box.center).norm() >
          0.5 * (boxes[i].box.length + boxes[j].box.length)) {
        continue;
      }
      if (Overlap(boxes[i].box, boxes[j].box) >= params_.duplicate_overlap) {
        // Keep the vehicle over a small object inside it, then the better established track,
        // then the older one.
        const Track& a = tracks_[i];
        const Track& b = tracks_[j];
        bool drop_a;
        if (a.small_object != b.small_object) drop_a = a.small_object;
        else if (a.num_updates != b.num_updates) drop_a = a.num_updates < b.num_updates;
        else drop_a = a.id > b.id;
        remove[drop_a ? i : j] = 1;
      }
    }
  }
  std::size_t w = 0;
  for (std::size_t i = 0; i < tracks_.size(); ++i) {
    if (remove[i]) continue;
    if (w != i) tracks_[w] = std::move(tracks_[i]);
    ++w;
  }
  tracks_.resize(w);
}

void TrackManager::Report(std::int64_t utime, std::vector<TrackReport>* out) const {
  out->clear();
  out->reserve(tracks_.size());
  for (const Track& t : tracks_) {
    const TrackHypothesis& sel = t.hyps[static_cast<std::size_t>(t.selected)];
    const Hypothesis h = PredictedSelected(t, utime);
    const CentreEstimate c = ekf_.Centre(h);
    TrackReport r;
    r.id = t.id;
    r.status = t.status;
    r.model = h.kind;
    r.moving = t.mover;
    r.x = c.pose(0);
    r.y = c.pose(1);
    r.theta = WrapToPi(c.pose(2));
    r.speed = c.speed;
    r.velocity_heading = c.velocity_heading;
    r.yaw_rate = c.yaw_rate;
    r.rear_axle_offset = h.kind == ModelKind::kVasm ? c.rear_axle_offset : kNaN;
    Dimensions(t, sel, &r.length, &r.width);
    r.cov = c.pose_cov;
    r.num_hypotheses = static_cast<int>(t.hyps.size());
    r.age = static_cast<double>(utime - t.created_utime) * 1e-6;
    r.num_updates = t.num_updates;
    // Class from the estimated size (not the default lower bound) and motion: a mover of any
    // plausible size is a vehicle, seen in part or not.
    const auto& le = sel.length_est; const auto& we = sel.width_est;
    const double est_l = le ? *le : 0.0, est_w = we ? *we : 0.0;
    const bool vehicle_size = est_l <= params_.vehicle_max_length &&
                              est_w <= params_.vehicle_max_width &&
                              std::max(est_l, est_w) >= params_.vehicle_min_length &&
                              std::min(est_l, est_w) >= params_.vehicle_min_width * 0.5;
    // A stationary object seen in part (a parked car from one corner) is a vehicle if a face
    // of a car's front or rear width was seen whole (both ends free, AlignToFullFace) and the
    // rest fits a vehicle.
    const bool full_face_vehicle = t.axis_from_full_face &&
                                   t.full_face_extent >= params_.vehicle_min_width &&
                                   t.full_face_extent <= params_.vehicle_max_width &&
                                   est_l <= params_.vehicle_max_length &&
                                   std::min(est_l, est_w) >= 0.5 * params_.vehicle_min_width;
    const bool vehicle = !t.small_object &&
                         (vehicle_size || full_face_vehicle ||
                          (t.mover && std::max(est_l, est_w) >= params_.vehicle_min_width));
    r.object_class = vehicle ? ObjectClass::kVehicle : ObjectClass::kOther;
    if (!vehicle && le && we) {  // clutter: its own size, not the vehicle default
      r.length = est_l;
      r.width = est_w;
    }
    r.prediction = ekf_.PredictTrajectory(h, params_.prediction_horizon_s,
                                          params_.prediction_step_s, sel.noise_scale);
    out->push_back(std::move(r));
  }
}

}  // namespace vtrack
