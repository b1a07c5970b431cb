#include "tracker/core/classification.h"

#include "tracker/core/vehicle_evidence.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace vtrack {

MoverTest::MoverTest(double confidence, double min_speed)
    : d2_quantile_(ChiSquareQuantile(confidence, 2)),
      d1_quantile_(ChiSquareQuantile(confidence, 1)),
      min_speed_(min_speed) {}

std::optional<bool> MoverTest::Evidence(const Ekf& ekf, const Track& t, bool pose_measured) const {
  const TrackHypothesis& sel = t.hyps[static_cast<std::size_t>(t.selected)];
  if (!sel.has_fit && !pose_measured) return std::nullopt;
  const CentreEstimate c = ekf.Centre(sel.filter);
  const Eigen::Matrix2d C = 0.5 * (c.velocity_cov + c.velocity_cov.transpose());
  if (!pose_measured && sel.fit.kind == FitKind::kEdge && c.velocity.allFinite()) {
    const Eigen::Vector2d n(-std::sin(sel.fit.phi), std::cos(sel.fit.phi));
    const double vn = n.dot(c.velocity), var = n.dot(C * n);
    return var > 0.0 && vn * vn / var > d1_quantile_ && std::abs(vn) >= min_speed_;
  }
  Eigen::LLT<Eigen::Matrix2d> llt(C);
  if (llt.info() == Eigen::Success && c.velocity.allFinite()) {
    const double d2 = c.velocity.dot(llt.solve(c.velocity));
    return d2 > d2_quantile_ && c.speed >= min_speed_;
  }
  return false;
}

namespace {

// The stride that takes at most kMotionCheckPoints of n returns.
std::size_t MotionCheckStride(std::size_t n) {
  return std::max<std::size_t>(1, (n + kMotionCheckPoints - 1) / kMotionCheckPoints);
}

}  // namespace

bool ReturnsMovedWith(const PointSet& now, const ReturnsSnapshot& before, const Eigen::Vector2d& d) {
  // Brute force over at most 64 x 64 pairs: a k-d tree over 64 points costs more to build than
  // this search.
  const Eigen::Vector2d off = now.origin - before.origin;  // now's frame -> before's frame
  const std::size_t stride = MotionCheckStride(now.size());
  const std::size_t m = before.x.size();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // Nearest squared distances of each of before's returns to now's (in place / displaced).
  std::array<double, kMotionCheckPoints> col_still, col_moved;
  col_still.fill(kInf);
  col_moved.fill(kInf);
  double still = 0.0, moved = 0.0;  // [m] summed nearest distances, both ways
  for (std::size_t i = 0; i < now.size(); i += stride) {
    const double px = now.x[i] + off.x(), py = now.y[i] + off.y();
    double row_still = kInf, row_moved = kInf;
    for (std::size_t k = 0; k < m; ++k) {
      const double dx = px - before.x[k], dy = py - before.y[k];
      const double s2 = dx * dx + dy * dy;
      const double ex = dx - d.x(), ey = dy - d.y();
      const double m2 = ex * ex + ey * ey;
      row_still = std::min(row_still, s2);
      row_moved = std::min(row_moved, m2);
      col_still[k] = std::min(col_still[k], s2);
      col_moved[k] = std::min(col_moved[k], m2);
    }
    still += std::sqrt(row_still);
    moved += std::sqrt(row_moved);
  }
  if (!std::isfinite(still)) return false;  // no returns now
  for (std::size_t k = 0; k < m; ++k) {
    still += std::sqrt(col_still[k]);
    moved += std::sqrt(col_moved[k]);
  }
  return moved < still;
}

void SnapshotReturns(const PointSet& points, ReturnsSnapshot* out) {
  out->origin = points.origin;
  out->utime = points.mean_utime;
  out->x.clear();
  out->y.clear();
  const std::size_t stride = MotionCheckStride(points.size());
  for (std::size_t i = 0; i < points.size(); i += stride) {
    out->x.push_back(points.x[i]);
    out->y.push_back(points.y[i]);
  }
}

ObjectClass Classify(const TrackManagerParams& params, const EvidenceParams& evidence,
                     const Track& t, bool vehicle_needs_box, std::int64_t utime,
                     double vehicle_box_score) {
  // A track a detector's box measured is a vehicle if its boxes are, on average, as confident as
  // one that may start a track (vehicle_box_score = detections.birth_score); weaker ones stay
  // tracked, scored and exported (the KITTI criterion sweeps the score itself).
  const bool confident = t.box_score >= vehicle_box_score;
  if (vehicle_needs_box) {
    // Fused: the detector is the vehicle evidence: a vehicle while the boxes alone would keep it
    // a confirmed track (confirm_updates boxes, the latest within coast_max_s).
    const double since_box_s = static_cast<double>(utime - t.last_box_utime) * 1e-6;
    const bool box_track = t.box_updates >= params.confirm_updates && since_box_s <= params.coast_max_s;
    return box_track && confident ? ObjectClass::kVehicle : ObjectClass::kOther;
  }
  if (t.box_updates > 0) return confident ? ObjectClass::kVehicle : ObjectClass::kOther;
  if ((t.evidence_3d ? evidence.classifier_3d : evidence.classifier_2d) == VehicleClassifier::kEvidence) {
    return t.evidence_vehicle ? ObjectClass::kVehicle : ObjectClass::kOther;
  }
  if (t.small_object) return ObjectClass::kOther;
  const TrackHypothesis& sel = t.hyps[static_cast<std::size_t>(t.selected)];
  const double est_l = sel.length_est.value_or(0.0), est_w = sel.width_est.value_or(0.0);
  const bool vehicle_size = est_l <= params.vehicle_max_length &&
                            est_w <= params.vehicle_max_width &&
                            std::max(est_l, est_w) >= params.vehicle_min_length &&
                            std::min(est_l, est_w) >= params.vehicle_min_width * 0.5;
  // A stationary object seen in part (a parked car from one corner).
  const bool full_face_vehicle = t.axis_from_full_face &&
                                 t.full_face_extent >= params.vehicle_min_width &&
                                 t.full_face_extent <= params.vehicle_max_width &&
                                 est_l <= params.vehicle_max_length &&
                                 std::min(est_l, est_w) >= 0.5 * params.vehicle_min_width;
  const bool mover = t.mover && std::max(est_l, est_w) >= params.vehicle_min_width;
  return vehicle_size || full_face_vehicle || mover ? ObjectClass::kVehicle : ObjectClass::kOther;
}

}  // namespace vtrack
