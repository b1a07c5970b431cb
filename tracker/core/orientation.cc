#include "tracker/core/orientation.h"

#include <cmath>
#include <cstdlib>
#include <optional>
#include <utility>

#include "base/angle.h"

namespace vtrack {
void TurnAxis(const Ekf& ekf, ModelKind kind, int quarter_turns, TrackHypothesis* h) {
  h->filter = ekf.Convert(h->filter, kind, quarter_turns * 0.5 * kPi);
  if (std::abs(quarter_turns) % 2 == 1) {
    h->shape.SwapLengthAndWidth();
    h->RefreshShape();
    std::swap(h->length_seen_full, h->width_seen_full);
  }
}

void AlignIsmToMotion(const Ekf& ekf, double ambiguity_deg, Track* t) {
  for (auto& h : t->hyps) {
    if (!HasIsmLayout(h.filter.kind)) continue;
    const CentreEstimate c = ekf.Centre(h.filter);
    const double theta = h.filter.x(4);
    const double off = AngleDiff(c.velocity_heading, theta);
    const int k = static_cast<int>(std::lround(off / (0.5 * kPi)));  // -2..2
    if (k == 0) continue;
    const double residual = std::abs(AngleDiff(c.velocity_heading, theta + k * 0.5 * kPi));
    if (std::abs(k) % 2 == 1 && residual > DegToRad(45.0 - 0.5 * ambiguity_deg)) {
      continue;  // too near the diagonal to tell
    }
    TurnAxis(ekf, h.filter.kind, k, &h);
  }
}

void AlignVasmToMotion(Track* t) {
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

void AlignToShape(const Ekf& ekf, const TrackManagerParams& params, Track* t) {
  // A first fit of a partly seen object may take the wrong axis (a corner whose long side is
  // still hidden), and later fits keep the heading nearest the prediction. Not while the
  // "width" is shorter than any vehicle's length: a car's end face seen whole (1.8 m) beside the
  // first metre of its side is not a side. A VASM turns too (mode vasm): a still object's
  // heading is only its axis, and one left across the object places every later fit's centre
  // half the default length from the face it sees.
  for (auto& h : t->hyps) {
    if (!h.length_est || !h.width_est) continue;
    if (*h.width_est <= std::max(params.axis_swap_ratio * *h.length_est,
                                 params.vehicle_min_length)) {
      continue;
    }
    TurnAxis(ekf, h.filter.kind, 1, &h);
  }
}

namespace {

// Turns the ISM (and CV) hypotheses of t by 90 deg and measures each afresh with the new heading: the
// centre moves with the axis (half the default length behind the face instead of half the
// width), and keeping the old position would turn the jump into a false velocity. The centre
// velocity carries over.
void TurnAcrossFace(const Ekf& ekf, const PointSet& points, const Eigen::Vector2d& sensor_xy,
                    std::uint64_t seed, TrackMeasurer* measurer, Track* t) {
  for (auto& h : t->hyps) {
    if (!HasIsmLayout(h.filter.kind)) continue;
    TurnAxis(ekf, h.filter.kind, 1, &h);
    const Hypothesis turned = h.filter;
    CentreMeasurement m;
    if (measurer->Measure(false, points, sensor_xy, seed, turned.x(4), std::nullopt, &h, &m) &&
        m.z.allFinite()) {
      Hypothesis ism = ekf.InitIsm(m);
      for (int i : {1, 3, 5}) {
        ism.x(i) = turned.x(i);
        for (int j : {1, 3, 5}) ism.P(i, j) = turned.P(i, j);
      }
      h.filter = ekf.Convert(ism, turned.kind, 0.0);  // a CV hypothesis stays one
    }
  }
}

}  // namespace

namespace {

// [m] A face is shorter than the object's estimate along it (ShapeEstimator) by more than this
// only if part of it is unseen: about three times the shape histogram's smoothing std (0.15 m,
// the noise of one dimension measurement).
constexpr double kFaceShorterThanSeenMargin = 0.5;

}  // namespace

void AlignToFullFace(const Ekf& ekf, const TrackManagerParams& params, const PointSet& points,
                     const Eigen::Vector2d& sensor_xy, std::uint64_t seed,
                     const RangeProfile& profile, TrackMeasurer* measurer, Track* t) {
  const TrackHypothesis& sel = t->hyps[static_cast<std::size_t>(t->selected)];
  if (!sel.updated_this_scan || !sel.has_fit || !HasIsmLayout(sel.filter.kind)) return;
  for (int e = 0; e < sel.fit.num_edges; ++e) {
    const FittedEdge& ed = sel.fit.edges[static_cast<std::size_t>(e)];
    const Eigen::Vector2d a = ed.start + points.origin, b = ed.end + points.origin;
    const double extent = (b - a).norm();
    if (extent >= params.vehicle_min_length || extent < 0.5 * params.vehicle_min_width) continue;
    // A corner's start is the corner itself (seen); an edge needs both ends free.
    const bool start_free = sel.fit.kind == FitKind::kCorner ||
                            profile.FreeBeyond(a, b, kEndOccluderMargin, kEndBinsBeyond);
    if (!start_free || !profile.FreeBeyond(b, a, kEndOccluderMargin, kEndBinsBeyond)) continue;
    const double face_dir = std::atan2((b - a).y(), (b - a).x());
    const double theta = sel.filter.x(4);
    const bool along = std::abs(std::sin(AngleDiff(theta, face_dir))) < std::sin(DegToRad(45.0));
    // The object was seen longer along this face before: this view of it is not whole (the far
    // part of a side that runs away from the sensor is missing, and the profile cannot tell:
    // what lies beyond it is farther, not nearer).
    const std::optional<double>& seen = along ? sel.length_est : sel.width_est;
    if (seen && *seen > extent + kFaceShorterThanSeenMargin) continue;
    if (along) TurnAcrossFace(ekf, points, sensor_xy, seed, measurer, t);
    t->axis_from_full_face = true;
    t->full_face_extent = extent;
    return;
  }
}

}  // namespace vtrack
