#include "tracker/core/track_manager.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "base/angle.h"
#include "tracker/core/classification.h"
#include "tracker/core/hypotheses.h"
#include "tracker/core/life_cycle.h"
#include "tracker/core/orientation.h"

namespace vtrack {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
// Floor of an observed extent fed to the shape estimate: a single return, or returns in a line,
// still occupy about a LADAR footprint.
constexpr double kMinObservedExtent = 0.1;  // [m]

// The model of an object's first hypothesis: VASM in mode vasm, CV in mode cv, else ISM.
ModelKind FirstModel(TrackerMode mode) {
  return mode == TrackerMode::kVasm ? ModelKind::kVasm
         : mode == TrackerMode::kCv ? ModelKind::kCv
                                    : ModelKind::kIsm;
}

}  // namespace

std::string TrackManagerParams::CrossProblem() const {
  using param::Problem;
  if (static_cast<int>(vasm_variants.size()) < max_hypotheses - 1)
    return Problem("vasm_variants", vasm_variants.size(), "entries", "at least max_hypotheses - 1");
  if (outline_min_edge_inliers > outline_min_points)
    return Problem("outline_min_edge_inliers", outline_min_edge_inliers, "-", "<= outline_min_points");
  if (!(small_object_grown_extent >= small_object_extent))
    return Problem("small_object_grown_extent", small_object_grown_extent, "m", ">= small_object_extent");
  if (!(vehicle_max_length >= vehicle_min_length))
    return Problem("vehicle_max_length", vehicle_max_length, "m", ">= vehicle_min_length");
  if (!(vehicle_max_width >= vehicle_min_width))
    return Problem("vehicle_max_width", vehicle_max_width, "m", ">= vehicle_min_width");
  return {};
}

TrackManager::TrackManager(const TrackManagerParams& params, const Ekf& ekf,
                           const FitParams& fit, const ShapeParams& shape)
    : params_(params),
      ekf_(ekf),
      measurer_(params, fit),
      shape_params_(shape),
      mover_test_(params.mover_confidence, params.mover_min_speed) {
  std::string error;
  if (!params_.Validate(&error)) throw std::invalid_argument(error);
  if (!shape_params_.Validate(&error)) throw std::invalid_argument(error);
  first_hypothesis_.shape = ShapeEstimator(shape_params_);
  first_hypothesis_.inside_fraction =
      params_.mode == TrackerMode::kVasm && !params_.vasm_variants.empty()
          ? params_.vasm_variants[0].inside_fraction
          : params_.ism_inside_fraction;
}

bool TrackManager::Parked(const Track& t) const {
  return vtrack::Parked(ekf_, params_.mover_min_speed, t);
}

OrientedBox TrackManager::RectangleOf(const Track& t, const Hypothesis& h) const {
  double length, width;
  measurer_.Dimensions(t.small_object, t.hyps[static_cast<std::size_t>(t.selected)], &length,
                       &width);
  return BoxOf(PoseOf(ekf_.model(h.kind), h.x), length, width);
}

void TrackManager::Predict(std::int64_t utime, std::vector<PredictedObject>* out) const {
  out->clear();
  for (const Track& t : tracks_) {
    const Hypothesis h = PredictReported(ekf_, t, utime);
    const auto idx = ekf_.model(h.kind).PoseIndices();
    const TrackHypothesis& sel = t.hyps[static_cast<std::size_t>(t.selected)];
    PredictedObject p;
    p.box = RectangleOf(t, h);
    p.established = t.status != TrackStatus::kTentative;
    const double a = h.P(idx[0], idx[0]), b = h.P(idx[0], idx[1]), c = h.P(idx[1], idx[1]);
    p.position_std = std::sqrt(std::max(0.0, 0.5 * (a + c) + std::hypot(0.5 * (a - c), b)));
    if (t.consecutive_misses > 0 && Parked(t)) {
      // A parked object stays where it is while it is hidden: its rectangle where it was last
      // measured, grown by gate_margin only. Predicted with its residual velocity and the gate
      // grown with the motion noise over the missed scans, a lot car hidden for 0.5 s by a
      // passing vehicle took in the face of the car parked 0.8 m beside it and slid onto it.
      p.box = RectangleOf(t, sel.filter);
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

void TrackManager::Update(std::size_t index, const PointSet& points,
                          const Eigen::Vector2d& sensor_xy, std::uint64_t seed,
                          TrackDebug* debug, const RangeProfile* profile,
                          TrackMeasurer* measurer) {
  if (measurer == nullptr) measurer = &measurer_;
  measurer->set_profile(profile);
  Track& t = tracks_[index];
  t.seen_this_scan = true;
  const std::int64_t tm = std::max(points.mean_utime, t.state_utime);
  const double dt = static_cast<double>(tm - t.state_utime) * 1e-6;
  if (debug) debug->predicted = RectangleOf(t, PredictReported(ekf_, t, tm));
  for (auto& h : t.hyps) {
    if (dt > 0.0) ekf_.Predict(dt, h.noise_scale, &h.filter);
  }
  t.state_utime = tm;
  if (t.small_object && points.extent >= params_.small_object_grown_extent) {
    GrowIntoRectangle(points, sensor_xy, seed, measurer, &t);
  }
  const bool any = UpdateHypotheses(points, sensor_xy, seed, tm, profile != nullptr, measurer, &t);
  AfterUpdate(any, tm, /*pose_measured=*/false, &points, &t);
  SnapshotReturns(points, &t.last_returns);
  if (any && !t.mover && !t.small_object && profile && !profile->empty()) {
    AlignToFullFace(ekf_, params_, points, sensor_xy, seed, *profile, measurer, &t);
  }
  if (any && !t.mover && !t.small_object && !t.axis_from_full_face) AlignToShape(ekf_, params_, &t);
  if (debug) FillDebug(t, points, sensor_xy, debug);
}

void TrackManager::GrowIntoRectangle(const PointSet& points, const Eigen::Vector2d& sensor_xy,
                                     std::uint64_t seed, TrackMeasurer* measurer, Track* t) {
  // A far object first seen as a few returns has grown into a rectangle: its orientation was
  // never measured (centroid updates), so it is taken afresh from this fit, keeping the centre
  // velocity; the shape starts over. Its hypotheses reduce to the first one. Fitted as a
  // vehicle's rectangle (the default dimensions), not the small object's: which face a single
  // edge is (side or end) is judged against the default width.
  TrackHypothesis& h0 = t->hyps[0];
  TrackHypothesis fresh = FirstHypothesis();
  fresh.inside_fraction = h0.inside_fraction;
  fresh.noise_scale = h0.noise_scale;
  CentreMeasurement m;
  const bool fitted =
      measurer->Measure(false, points, sensor_xy, seed, std::nullopt, std::nullopt, &fresh, &m) &&
      m.z.allFinite();
  if (!fitted) return;  // a small object until a fit succeeds
  t->small_object = false;
  const Hypothesis old_ism = ekf_.Convert(t->hyps[static_cast<std::size_t>(t->selected)].filter,
                                          ModelKind::kIsm, 0.0);
  Hypothesis ism = ekf_.InitIsm(m);
  for (int i : {1, 3}) {  // centre velocity and its covariance carry over
    ism.x(i) = old_ism.x(i);
    for (int j : {1, 3}) ism.P(i, j) = old_ism.P(i, j);
  }
  fresh.filter = ekf_.Convert(ism, FirstModel(params_.mode), 0.0);
  fresh.last_logdet = h0.last_logdet;
  fresh.score_terms = h0.score_terms;
  fresh.has_fit = false;
  t->hyps.clear();
  t->hyps.push_back(std::move(fresh));
  t->selected = 0;
  // Centroids of a few returns slide along a surface as the view changes: motion judged from
  // them is not evidence; the test starts over on the rectangle.
  t->mover = false;
  t->motion_evidence = 0;
}

bool TrackManager::UpdateHypotheses(const PointSet& points, const Eigen::Vector2d& sensor_xy,
                                    std::uint64_t seed, std::int64_t utime, bool three_d,
                                    TrackMeasurer* measurer, Track* t) {
  // A parked car's partial face is placed along itself where predicted (FitRequest::
  // predicted_center). Not a mover's: the same view of a mover does not repeat scan after scan,
  // and placing its face where predicted loses it (KITTI 0000, every mode).
  const bool parked = Parked(*t);
  const double time_s = static_cast<double>(utime) * 1e-6;
  bool any = false;
  for (TrackHypothesis& h : t->hyps) {
    any = UpdateHypothesis(*t, parked, points, sensor_xy, seed, time_s, three_d, measurer, &h) ||
          any;
  }
  return any;
}

bool TrackManager::UpdateHypothesis(const Track& t, bool parked, const PointSet& points,
                                    const Eigen::Vector2d& sensor_xy, std::uint64_t seed,
                                    double time_s, bool three_d, TrackMeasurer* measurer,
                                    TrackHypothesis* h) {
  h->updated_this_scan = false;
  const Eigen::Vector3d pose = PoseOf(ekf_.model(h->filter.kind), h->filter.x);
  CentreMeasurement m;
  // Same request for every hypothesis but the heading and the shape: the seed is shared so
  // hypotheses that agree get the same fit.
  const bool measured =
      measurer->Measure(t.small_object, points, sensor_xy, seed, pose(2),
                        parked ? std::optional<Eigen::Vector2d>(pose.head<2>()) : std::nullopt,
                        h, &m);
  if (ApplyMeasurement(measured ? &m : nullptr, h) ||
      (measured && RestartLostStill(t, points, m, h))) {
    ObserveShape(t.small_object, points, time_s, three_d, h);
  }
  return h->updated_this_scan;
}

bool TrackManager::RestartLostStill(const Track& t, const PointSet& points,
                                    const CentreMeasurement& m, TrackHypothesis* h) const {
  if (t.mover || t.hyps.size() != 1 || h->consecutive_misses < params_.fail_misses ||
      t.last_returns.empty() || !m.z.allFinite()) {
    return false;
  }
  const Hypothesis ism = ekf_.Convert(h->filter, ModelKind::kIsm, 0.0);
  const double dt = static_cast<double>(points.mean_utime - t.last_returns.utime) * 1e-6;
  if (ReturnsMovedWith(points, t.last_returns, Eigen::Vector2d(ism.x(1), ism.x(3)) * dt)) {
    return false;
  }
  h->filter = ekf_.Convert(ekf_.InitIsm(m), h->filter.kind, 0.0);
  h->consecutive_misses = 0;
  h->updated_this_scan = true;
  h->last_nis = std::numeric_limits<double>::quiet_NaN();  // restarted, not an accepted update
  return true;
}

bool TrackManager::ApplyMeasurement(const CentreMeasurement* m, TrackHypothesis* h) {
  // The score term of a scan without an accepted update: as if the measurement had landed on
  // the gate (track_manager.h, "Score").
  double term = 0.5 * (ekf_.gate_nis() + h->last_logdet);
  if (m) {
    const auto idx = ekf_.model(h->filter.kind).PoseIndices();
    Eigen::Matrix3d S;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) S(r, c) = h->filter.P(idx[r], idx[c]);
    S += m->R;
    const double det = (2.0 * kPi * S).determinant();
    const double logdet = det > 0.0 ? std::log(det) : h->last_logdet;
    const UpdateResult res = ekf_.Update(*m, &h->filter);
    if (res.accepted) {
      term = 0.5 * (res.nis + logdet);
      h->last_logdet = logdet;
      h->last_nis = res.nis;
      h->consecutive_misses = 0;
      h->updated_this_scan = true;
    } else {
      term = 0.5 * (ekf_.gate_nis() + logdet);
    }
  }
  if (!h->updated_this_scan) ++h->consecutive_misses;
  AddScoreTerm(term, params_.score_window, h);
  return h->updated_this_scan;
}

void TrackManager::ObserveShape(bool small, const PointSet& points, double time_s,
                                bool three_d, TrackHypothesis* h) const {
  if (small) {
    // Extent of the returns along and across the estimated heading.
    const double th = h->filter.x(ekf_.model(h->filter.kind).PoseIndices()[2]);
    const Eigen::Vector2d ax(std::cos(th), std::sin(th)), nx(-ax.y(), ax.x());
    double a0 = kInf, a1 = -kInf, n0 = kInf, n1 = -kInf;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector2d p(points.x[i], points.y[i]);
      a0 = std::min(a0, p.dot(ax));
      a1 = std::max(a1, p.dot(ax));
      n0 = std::min(n0, p.dot(nx));
      n1 = std::max(n1, p.dot(nx));
    }
    h->shape.AddLength(time_s, std::max(kMinObservedExtent, a1 - a0));
    h->shape.AddWidth(time_s, std::max(kMinObservedExtent, n1 - n0));
  } else if (h->has_fit) {
    ObserveFitDimensions(time_s, three_d, h);
    h->length_seen_full = h->length_seen_full || h->fit.length_full_view;
    h->width_seen_full = h->width_seen_full || h->fit.width_full_view;
  }
  h->RefreshShape();
}

void TrackManager::TestMotion(Track* t, bool pose_measured, const PointSet* points) const {
  std::optional<bool> evidence = mover_test_.Evidence(ekf_, *t, pose_measured);
  if (!evidence) return;  // no evidence either way: the count is kept
  if (*evidence && points != nullptr && !t->last_returns.empty()) {
    const TrackHypothesis& sel = t->hyps[static_cast<std::size_t>(t->selected)];
    Eigen::Vector2d v = ekf_.Centre(sel.filter).velocity;
    if (sel.fit.kind == FitKind::kEdge) {
      // As in the mover test, only the velocity across a single fitted face counts.
      const Eigen::Vector2d n(-std::sin(sel.fit.phi), std::cos(sel.fit.phi));
      v = n * n.dot(v);
    }
    const double dt = static_cast<double>(points->mean_utime - t->last_returns.utime) * 1e-6;
    evidence = ReturnsMovedWith(*points, t->last_returns, v * dt);
  }
  t->motion_evidence = *evidence ? t->motion_evidence + 1 : 0;
  if (!t->mover && t->motion_evidence >= params_.mover_scans) {
    t->mover = true;
    AlignIsmToMotion(ekf_, params_.ambiguity_deg, t);
    AlignVasmToMotion(t);
  } else if (t->mover && *evidence) {
    AlignIsmToMotion(ekf_, params_.ambiguity_deg, t);
  }
  // Small objects (pedestrians, poles) have no rectangle for a VASM to steer.
  if (t->mover && params_.mode == TrackerMode::kMht && t->hyps.size() == 1 && !t->small_object) {
    SpawnVasms(ekf_, params_, t);
  }
}

void TrackManager::UpdateWithBox(std::size_t index, const BoxMeasurement& b,
                                 const DetectionParams& dp) {
  Track& t = tracks_[index];
  const std::int64_t tm = std::max(b.utime, t.state_utime);
  const double dt = static_cast<double>(tm - t.state_utime) * 1e-6;
  for (auto& h : t.hyps) {
    if (dt > 0.0) ekf_.Predict(dt, h.noise_scale, &h.filter);
  }
  t.state_utime = tm;
  const double time_s = static_cast<double>(tm) * 1e-6;
  bool any = false;
  for (TrackHypothesis& h : t.hyps) {
    h.updated_this_scan = false;
    h.has_fit = false;
    const double theta = PoseOf(ekf_.model(h.filter.kind), h.filter.x)(2);
    const CentreMeasurement m = BoxToMeasurement(b, theta, dp);
    if (ApplyMeasurement(&m, &h)) {
      ObserveBoxShape(b, time_s, &h);
      any = true;
    }
  }
  if (any) {
    // Recency-weighted mean of the boxes' scores: the plain mean over the first score_memory
    // boxes, then an exponential average with weight 1 / score_memory.
    ++t.box_updates;
    const double w = 1.0 / std::min(static_cast<double>(t.box_updates), dp.score_memory);
    t.box_score += w * (b.score - t.box_score);
    t.box_z += w * (b.z - t.box_z);
    t.box_height += w * (b.height - t.box_height);
    t.last_box_utime = b.utime;
    t.small_object = false;  // the box is a full view of a vehicle's rectangle
  }
  AfterUpdate(any, tm, /*pose_measured=*/true, /*points=*/nullptr, &t);
}

void TrackManager::AfterUpdate(bool any, std::int64_t utime, bool pose_measured,
                               const PointSet* points, Track* t) {
  if (any) {
    ++t->num_updates;
    t->consecutive_misses = 0;
    t->last_update_utime = utime;
  } else {
    ++t->consecutive_misses;
  }
  SelectHypothesis(params_.switch_margin, t);
  ReseedFailedHypotheses(ekf_, params_.fail_misses, t);
  if (any) TestMotion(t, pose_measured, points);
}

void TrackManager::ObserveBoxShape(const BoxMeasurement& b, double time_s,
                                   TrackHypothesis* h) const {
  // The box's length lies along the hypothesis' axis (its heading is taken modulo 180 deg, not
  // 90): a detector's box is a full view of both.
  h->shape.AddLength(time_s, b.box.length);
  h->shape.AddWidth(time_s, b.box.width);
  h->length_seen_full = true;
  h->width_seen_full = true;
  h->RefreshShape();
}

bool TrackManager::CreateFromBox(const BoxMeasurement& b, const DetectionParams& dp) {
  TrackHypothesis h = FirstHypothesis();
  const CentreMeasurement m = BoxToMeasurement(b, b.box.theta, dp);
  if (!m.z.allFinite() || !(b.box.length > 0.0) || !(b.box.width > 0.0)) return false;
  StartFilter(m, &h);
  ObserveBoxShape(b, static_cast<double>(b.utime) * 1e-6, &h);
  Track t;
  t.box_updates = 1;
  t.last_box_utime = b.utime;
  t.box_score = b.score;
  t.box_z = b.z;
  t.box_height = b.height;
  AddTrack(std::move(t), std::move(h), b.utime);
  return true;
}

TrackHypothesis TrackManager::FirstHypothesis() const { return first_hypothesis_; }

void TrackManager::StartFilter(const CentreMeasurement& m, TrackHypothesis* h) const {
  h->filter = ekf_.Convert(ekf_.InitIsm(m), FirstModel(params_.mode), 0.0);
  h->last_logdet = std::log(std::max(1e-300, (2.0 * kPi * m.R).determinant()));
  // The first scan's score term: the NIS of a measurement at its expected value (3, the
  // measurement's dimension) with the measurement's own covariance.
  h->score_terms.push_back(0.5 * (3.0 + h->last_logdet));
}

void TrackManager::AddTrack(Track t, TrackHypothesis h, std::int64_t utime) {
  t.id = next_id_++;
  t.created_utime = utime;
  t.state_utime = utime;
  t.last_update_utime = utime;
  t.num_updates = 1;
  t.vehicle_log_odds = PriorLogOdds(evidence_, /*three_d=*/true);
  t.hyps.push_back(std::move(h));
  tracks_.push_back(std::move(t));
}

OrientedBox TrackManager::Box(std::size_t index) const {
  const Track& t = tracks_[index];
  return RectangleOf(t, t.hyps[static_cast<std::size_t>(t.selected)].filter);
}

void TrackManager::Miss(std::size_t index) { ++tracks_[index].consecutive_misses; }

double TrackManager::ObserveEvidence(std::size_t index, const ReturnEvidence& r,
                                     EvidenceFeatures* features) {
  Track& t = tracks_[index];
  const TrackHypothesis& sel = t.hyps[static_cast<std::size_t>(t.selected)];
  const EvidenceFeatures f = FeaturesOf(r, t, ekf_.Centre(sel.filter).speed);
  const double logit = ScanLogit(evidence_, r.three_d, f, evidence_roots_);
  // The first evidence: the track starts at the prior of the model that measured it.
  if (!t.evidence_seen) t.vehicle_log_odds = PriorLogOdds(evidence_, r.three_d);
  t.evidence_seen = true;
  t.vehicle_log_odds = AccumulateLogOdds(evidence_, r.three_d, t.vehicle_log_odds, logit);
  t.evidence_vehicle = VehicleByEvidence(evidence_, t.evidence_vehicle, t.vehicle_log_odds);
  t.evidence_3d = r.three_d;
  if (features != nullptr) *features = f;
  return logit;
}

bool TrackManager::Create(const PointSet& points, const Eigen::Vector2d& sensor_xy,
                          std::uint64_t seed, const RangeProfile* profile) {
  NewTrack t;
  if (!PrepareCreate(points, sensor_xy, seed, profile, &measurer_, &t)) return false;
  AddCreated(std::move(t));
  return true;
}

bool TrackManager::PrepareCreate(const PointSet& points, const Eigen::Vector2d& sensor_xy,
                                 std::uint64_t seed, const RangeProfile* profile,
                                 TrackMeasurer* measurer, NewTrack* out) const {
  measurer->set_profile(profile);
  Track& t = out->track;
  t = Track{};
  t.small_object = points.extent < params_.small_object_extent;
  TrackHypothesis& h = out->hypothesis;
  h = FirstHypothesis();
  CentreMeasurement m;
  if (!measurer->Measure(t.small_object, points, sensor_xy, seed, std::nullopt, std::nullopt,
                         &h, &m)) {
    return false;
  }
  if (!m.z.allFinite() || !m.R.allFinite()) return false;
  StartFilter(m, &h);
  ObserveFirstShape(t.small_object, points, profile != nullptr, &h);
  SnapshotReturns(points, &t.last_returns);
  out->utime = points.mean_utime;
  return true;
}

void TrackManager::AddCreated(NewTrack&& t) {
  AddTrack(std::move(t.track), std::move(t.hypothesis), t.utime);
}

void TrackManager::ObserveFitDimensions(double time_s, bool three_d, TrackHypothesis* h) const {
  const FitResult& f = h->fit;
  auto weight = [&](double std_m) {
    return three_d ? DimensionSampleWeight(std_m, params_.range_sigma) : 1.0;
  };
  if (std::isfinite(f.observed_length_m)) {
    h->shape.AddLength(time_s, f.observed_length_m, weight(f.observed_length_std_m));
  }
  if (std::isfinite(f.observed_width_m)) {
    h->shape.AddWidth(time_s, f.observed_width_m, weight(f.observed_width_std_m));
  }
}

void TrackManager::ObserveFirstShape(bool small, const PointSet& points, bool three_d,
                                     TrackHypothesis* h) const {
  const double time_s = static_cast<double>(points.mean_utime) * 1e-6;
  if (small) {
    // Axis-aligned extents (theta = 0 for a centroid measurement).
    float x0 = points.x[0], x1 = x0, y0 = points.y[0], y1 = y0;
    for (std::size_t i = 1; i < points.size(); ++i) {
      x0 = std::min(x0, points.x[i]);
      x1 = std::max(x1, points.x[i]);
      y0 = std::min(y0, points.y[i]);
      y1 = std::max(y1, points.y[i]);
    }
    h->shape.AddLength(time_s, std::max(kMinObservedExtent, static_cast<double>(x1 - x0)));
    h->shape.AddWidth(time_s, std::max(kMinObservedExtent, static_cast<double>(y1 - y0)));
  } else if (h->has_fit) {
    ObserveFitDimensions(time_s, three_d, h);
    h->length_seen_full = h->fit.length_full_view;
    h->width_seen_full = h->fit.width_full_view;
  }
  h->RefreshShape();
}

void TrackManager::EndScan(std::int64_t utime) {
  std::vector<char> remove(tracks_.size(), 0);
  for (std::size_t i = 0; i < tracks_.size(); ++i) {
    Track& t = tracks_[i];
    if (!AdvanceStatus(ekf_, params_, utime, PredictReported(ekf_, t, utime), &t)) remove[i] = 1;
    t.seen_this_scan = false;
  }
  std::vector<PredictedObject> boxes;
  Predict(utime, &boxes);
  MarkDuplicates(params_, tracks_, boxes, &remove);
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
    const Hypothesis h = PredictReported(ekf_, t, utime);
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
    measurer_.Dimensions(t.small_object, sel, &r.length, &r.width);
    r.cov = c.pose_cov;
    r.num_hypotheses = static_cast<int>(t.hyps.size());
    r.age = static_cast<double>(utime - t.created_utime) * 1e-6;
    r.num_updates = t.num_updates;
    r.score = TrackScore(t);
    if (t.box_updates > 0) {
      r.z = t.box_z;
      r.height = t.box_height;
    }
    r.vehicle_probability = VehicleProbability(t.vehicle_log_odds);
    r.object_class = Classify(params_, evidence_, t, vehicle_needs_box_, utime, vehicle_box_score_);
    if (r.object_class == ObjectClass::kVehicle && t.small_object) {
      // A vehicle seen by a few returns (its evidence says so) is still a vehicle's size.
      measurer_.Dimensions(false, sel, &r.length, &r.width);
    }
    if ((r.object_class != ObjectClass::kVehicle || t.box_updates > 0) && sel.length_est &&
        sel.width_est) {
      // Clutter: its own size, not the vehicle default. A track a detector's box measured: its
      // size from the boxes, each a full view (a car shorter than default_length is not
      // lengthened to it).
      r.length = *sel.length_est;
      r.width = *sel.width_est;
    }
    if (params_.predict_all_tracks || r.object_class == ObjectClass::kVehicle) {
      r.prediction = ekf_.PredictTrajectory(h, params_.prediction_horizon_s,
                                            params_.prediction_step_s, sel.noise_scale);
    }
    out->push_back(std::move(r));
  }
}

double TrackManager::TrackScore(const Track& t) const {
  if (t.box_updates > 0) return t.box_score;
  // Scans only: n / (n + confirm_updates) for n updates, 0.5 at confirmation, rising towards 1
  // as the returns keep fitting the track.
  const double n = static_cast<double>(t.num_updates);
  return n / (n + static_cast<double>(params_.confirm_updates));
}

void TrackManager::FillDebug(const Track& t, const PointSet& points,
                             const Eigen::Vector2d& sensor_xy, TrackDebug* debug) const {
  const TrackHypothesis& h = t.hyps[static_cast<std::size_t>(t.selected)];
  debug->track_id = t.id;
  debug->visible_faces = VisibleFaces(debug->predicted, sensor_xy,
                                      DegToRad(measurer_.fit_params().min_slant_deg));
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
  measurer_.Dimensions(t.small_object, h, &length, &width);
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
    debug->hypotheses.push_back(ReportHypothesis(t, k));
  }
}

HypothesisReport TrackManager::ReportHypothesis(const Track& t, std::size_t k) const {
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
  return r;
}

}  // namespace vtrack
