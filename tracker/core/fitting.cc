#include "tracker/core/fitting.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>

#include "base/angle.h"
#include "tracker/core/range_profile.h"
#include "tracker/core/return_kernels.h"

namespace vtrack {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Gauss-Newton stops when a step moves the corner and phi by less than this [m, rad].
constexpr double kConvergedStep = 1e-5;
using internal::kMinPerpVar;

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}
Eigen::Vector2d Perp(const Eigen::Vector2d& v) { return {-v.y(), v.x()}; }  // +90 deg
Eigen::Vector2d Dir(double a) { return {std::cos(a), std::sin(a)}; }
double AngleOf(const Eigen::Vector2d& v) { return std::atan2(v.y(), v.x()); }

// The angle a or a + pi that lies in (-pi/2, pi/2].
double InRightHalfPlane(double a) {
  const double w = WrapToPi(a);
  if (w > 0.5 * kPi) return w - kPi;
  if (w <= -0.5 * kPi) return w + kPi;
  return w;
}

// Face (box.h numbering) whose outward normal points along normal_angle for heading theta.
Face FaceFromNormal(double normal_angle, double theta) {
  const long k = std::lround(AngleDiff(normal_angle, theta) / (0.5 * kPi));
  return static_cast<Face>(((k % 4) + 4) % 4);
}
bool IsSideFace(Face f) { return f == Face::kLeft || f == Face::kRight; }

// RANSAC iterations needed to draw one all-inlier sample with probability `confidence` when a
// sample is all-inlier with probability p.
int IterationsFor(double p, double confidence) {
  if (p >= 1.0 - 1e-12) return 0;
  if (p <= 1e-12) return std::numeric_limits<int>::max();
  const double n = std::log(1.0 - confidence) / std::log(1.0 - p);
  return n >= 1e9 ? std::numeric_limits<int>::max() : static_cast<int>(std::ceil(n));
}

// One or two edges from the point c: a straight edge through c along u0 (both ways), or a corner
// at c with edges leaving along u0 = Dir(phi) and u1 = Perp(u0). Coordinates are local (relative
// to the segment's first point, so that float world coordinates far from 0 lose nothing).
struct Model {
  int num_edges = 0;
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  double phi = 0.0;
  // Covariance of (c_x, c_y, phi) from the last Gauss-Newton step (zero for a RANSAC sample):
  // a point's residual against a fitted model varies by its own noise plus the model's, so the
  // inlier test uses var_i + J_i cov J_i^T (the predictive variance; 1 + leverage). Without it a
  // point dropped by the sample's line is never readmitted when the converged line, no longer
  // pulled by it, passes just beyond the threshold.
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  Eigen::Vector2d U0() const { return Dir(phi); }
  Eigen::Vector2d U1() const { return Perp(Dir(phi)); }
};

// Inlier extent of one edge along its direction, measured from the model point c.
struct Extent {
  int n = 0;
  double s_min = 0.0, s_max = 0.0;  // [m] outermost kept inliers
};

// Where the face really ends beyond an outermost return: mean offset outwards [m] and its
// variance [m^2].
struct EndOffset {
  double mean = 0.0;
  double var = 0.0;
};

// The data and noise model of one fit (the noise model's fields and two-lane threshold:
// internal::PerpNoise).
struct Context : internal::PerpNoise {
  // Per point, precomputed once per fit: local position and unit ray from the sensor.
  const double* px = nullptr;
  const double* py = nullptr;
  const double* rx = nullptr;
  const double* ry = nullptr;
  int n = 0;
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  // world position of the local frame
  Eigen::Vector2d sensor = Eigen::Vector2d::Zero();  // local
  const RangeProfile* profile = nullptr;             // see FitRequest
  Eigen::Vector2d profile_origin = Eigen::Vector2d::Zero();  // world position of local 0

  Eigen::Vector2d P(int i) const { return {px[i], py[i]}; }
  Eigen::Vector2d RayAt(int i) const { return {rx[i], ry[i]}; }
  Eigen::Vector2d Ray(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d d = p - sensor;
    const double len = d.norm();
    return len > 0.0 ? Eigen::Vector2d(d / len) : Eigen::Vector2d(1.0, 0.0);
  }
  // Variance of a point's distance from a face whose unit normal makes cosine cos_a with the ray.
  double PerpVar(double cos_a) const {
    return std::max(sigma2 * cos_a * cos_a + surface2, kMinPerpVar);
  }
  double Threshold2(double var) const { return std::max(k2 * var, min_t2); }
};

// NoDivisionAbove: the classification and RANSAC's costs use a normalised squared residual
// x / t (t > 0) only where it is below 1 (an inlier); 1 or more all count alike. x >= t gives
// x / t >= 1 exactly (rounding is monotonic and 1 is a double), so there 1 stands in for the
// quotient without a division: every comparison and sum comes out the same. (A NaN residual
// fails x < t as it failed x / t < 1.)

// Normalised squared residual of a point (local p, unit ray) against edge k of the model, or
// +inf if the point is not eligible for that edge (behind a corner by more than the threshold);
// 1 where it would be 1 or more (NoDivisionAbove). *r receives the signed distance and *var its
// variance.
// u0, u1: the model's m.U0(), m.U1() (passed in: computed once per model, not per point).
double EdgeError(const Context& ctx, const Model& m, const Eigen::Vector2d& u0,
                 const Eigen::Vector2d& u1, int k, const Eigen::Vector2d& p,
                 const Eigen::Vector2d& ray, double* r, double* var) {
  const Eigen::Vector2d v = p - m.c;
  const Eigen::Vector2d& normal = (k == 0) ? u1 : u0;
  const Eigen::Vector2d& along = (k == 0) ? u0 : u1;
  *r = normal.dot(v);
  *var = ctx.PerpVar(normal.dot(ray));
  // d(normal)/d(phi): d(u1)/d(phi) = -u0, d(u0)/d(phi) = u1 (as in GaussNewtonStep).
  const Eigen::Vector3d J(-normal.x(), -normal.y(), (k == 0 ? -along : along).dot(v));
  const double t2 = ctx.Threshold2(*var + J.dot(m.cov * J));
  if (m.num_edges == 2) {
    const double a = along.dot(v);
    if (a < 0.0 && a * a >= t2) return std::numeric_limits<double>::infinity();
  }
  const double r2 = (*r) * (*r);
  return r2 < t2 ? r2 / t2 : 1.0;
}

// Internal labels: an inlier within the threshold of both corner edges (near the corner) is
// labelled kAmbiguous + its nearer edge. It counts for that edge's support and extent but is left
// out of Gauss-Newton and R: which face it lies on is a guess, and a wrong guess pulls the corner.
constexpr std::int8_t kAmbiguous = 2;
int EdgeOf(std::int8_t label) { return label < 0 ? -1 : label % kAmbiguous; }

// Labels every point with its nearer eligible edge (or outlier). Returns inlier counts.
// Per-point mask of a single-edge fit (values).
constexpr std::int8_t kMaskAmbiguous = 1;  // near a perpendicular face's corner
constexpr std::int8_t kMaskExcluded = 2;   // beyond the vehicle's known length: not the vehicle

// Labels with mask (if given) applied. Returns a checksum of the labels (equal labellings give
// equal sums).
std::uint64_t Classify(const Context& ctx, const Model& m, const std::int8_t* mask,
                       std::int8_t* labels, int counts[2]) {
  counts[0] = counts[1] = 0;
  std::uint64_t checksum = 0;
  double r, var;
  const Eigen::Vector2d u0 = m.U0(), u1 = m.U1();
  for (int i = 0; i < ctx.n; ++i) {
    if (mask && mask[i] == kMaskExcluded) {
      labels[i] = FitResult::kOutlier;
      checksum = checksum * 0x100000001b3ull + 1;
      continue;
    }
    const Eigen::Vector2d p = ctx.P(i);
    const Eigen::Vector2d ray = ctx.RayAt(i);
    double best = 1.0;
    int within = 0;
    std::int8_t label = FitResult::kOutlier;
    for (int k = 0; k < m.num_edges; ++k) {
      const double e = EdgeError(ctx, m, u0, u1, k, p, ray, &r, &var);
      within += e < 1.0;
      if (e < best) {
        best = e;
        label = static_cast<std::int8_t>(k);
      }
    }
    if (label >= 0) ++counts[label];
    const bool is_ambiguous =
        label >= 0 && (within == 2 || (mask && mask[i] == kMaskAmbiguous));
    labels[i] = is_ambiguous ? static_cast<std::int8_t>(label + kAmbiguous) : label;
    checksum = checksum * 0x100000001b3ull + static_cast<std::uint64_t>(labels[i] + 2);
  }
  return checksum;
}

// Keeps the largest run of edge k's inliers whose consecutive spacing along the edge is at most
// max(max_gap, max_spacings * the median spacing), and at most max_gap where the scan's range
// profile (ctx.profile, 3-D scans) sees through the gap; the others become outliers. Returns the
// kept run's extent.
Extent GapFilter(const Context& ctx, const Model& m, int k, double max_gap, double max_spacings,
                 std::int8_t* labels, std::vector<double>* proj, std::vector<double>* gaps) {
  const Eigen::Vector2d along = (k == 0) ? m.U0() : m.U1();
  proj->clear();
  for (int i = 0; i < ctx.n; ++i) {
    if (EdgeOf(labels[i]) == k) proj->push_back(along.dot(ctx.P(i) - m.c));
  }
  Extent ext;
  if (proj->empty()) return ext;
  std::sort(proj->begin(), proj->end());
  const std::vector<double>& s = *proj;
  const int n = static_cast<int>(s.size());
  // A gap wider than max_gap that the sensor sees through (something farther seen in it, no
  // return near the face: two cars of a parked row) is no run of missing returns, however wide
  // the spacing: the run ends there.
  const double seen_gap = max_gap;  // [m]
  if (n >= 3) {
    gaps->resize(n - 1);
    for (int i = 0; i + 1 < n; ++i) (*gaps)[i] = s[i + 1] - s[i];
    std::nth_element(gaps->begin(), gaps->begin() + (n - 1) / 2, gaps->end());
    max_gap = std::max(max_gap, max_spacings * (*gaps)[(n - 1) / 2]);
  }
  const auto at = [&](double a) { return Eigen::Vector2d(ctx.profile_origin + m.c + along * a); };
  const auto seen_through = [&](int i) {
    return ctx.profile != nullptr && s[i] - s[i - 1] > seen_gap &&
           ctx.profile->SeenThrough(at(s[i - 1]), at(s[i]), kEndOccluderMargin);
  };
  int best_lo = 0, best_hi = 0, lo = 0;
  for (int i = 1; i <= n; ++i) {
    if (i == n || s[i] - s[i - 1] > max_gap || seen_through(i)) {
      if (i - 1 - lo > best_hi - best_lo) {
        best_lo = lo;
        best_hi = i - 1;
      }
      lo = i;
    }
  }
  ext.n = best_hi - best_lo + 1;
  ext.s_min = s[best_lo];
  ext.s_max = s[best_hi];
  if (ext.n < n) {
    for (int i = 0; i < ctx.n; ++i) {
      if (EdgeOf(labels[i]) != k) continue;
      const double a = along.dot(ctx.P(i) - m.c);
      if (a < ext.s_min || a > ext.s_max) labels[i] = FitResult::kOutlier;
    }
  }
  return ext;
}

// A perpendicular face met at one end of a single edge (FindPerpendicularFaces).
struct PerpendicularFace {
  bool found = false;
  double s_corner = 0.0;  // [m] the corner's position along the edge, from the model point
  double var = 0.0;       // [m^2] its variance
  double zone = 0.0;      // [m] edge inliers this close to the corner are ambiguous
};

// One candidate model (corner or edge) during refinement.
struct Candidate {
  Model model;
  std::array<Extent, 2> ext;
  std::array<EndOffset, 2> lo, hi;        // per edge
  std::array<PerpendicularFace, 2> perp;  // single edge: at its lo and hi end
  int counts[2] = {0, 0};
};

// The bearing step delta of the scanner, as the median bearing difference of edge k's inliers
// (differences of ~0, from several layers at one bearing, are skipped), and the share q of the
// beams over the inliers' bearing span that returned no inlier (dropouts, or returns replaced
// by early spurious ones).
void BearingStep(const Context& ctx, const Model& m, int k, const Extent& ext,
                 const std::int8_t* labels, std::vector<double>* buf, double* delta, double* q) {
  const Eigen::Vector2d along = (k == 0) ? m.U0() : m.U1();
  const Eigen::Vector2d ref = m.c + along * (0.5 * (ext.s_min + ext.s_max)) - ctx.sensor;
  buf->clear();
  for (int i = 0; i < ctx.n; ++i) {
    if (EdgeOf(labels[i]) != k) continue;
    const Eigen::Vector2d v = ctx.P(i) - ctx.sensor;
    buf->push_back(std::atan2(Cross(ref, v), ref.dot(v)));  // bearing relative to ref
  }
  std::vector<double>& b = *buf;
  std::sort(b.begin(), b.end());
  const int n = static_cast<int>(b.size());
  const double span = n > 0 ? b[n - 1] - b[0] : 0.0;
  int gaps = 0;
  for (int j = 0; j + 1 < n; ++j) {
    const double g = b[j + 1] - b[j];
    if (g > 1e-6) b[gaps++] = g;
  }
  *delta = 0.0;
  if (gaps > 0) {
    std::nth_element(b.begin(), b.begin() + gaps / 2, b.begin() + gaps);
    *delta = b[gaps / 2];
  }
  *q = *delta > 0.0 ? std::clamp(1.0 - n / (span / *delta + 1.0), 0.0, 0.8) : 0.0;
}

// Along-face distance [m] between neighbouring beams at the point s_end of edge k.
double StepAt(const Context& ctx, const Model& m, int k, double s_end, double delta) {
  const Eigen::Vector2d along = (k == 0) ? m.U0() : m.U1();
  const Eigen::Vector2d normal = (k == 0) ? m.U1() : m.U0();
  const Eigen::Vector2d v = m.c + along * s_end - ctx.sensor;
  const double range = v.norm();
  if (!(range > 0.0)) return 0.0;
  return range * delta / std::max(std::abs(normal.dot(v / range)), 0.05);
}

// The ends of edge k's extent (lo: s_min, hi: s_max). A scanning LADAR samples a face at equal
// bearing steps delta, so the beam that hits nearest to the face's end falls uniformly within one
// step of it; beams may also return nothing, each with probability q (BearingStep), so
// k ~ Geometric(q) beams at the end may be missing. With the along-face distance of one step at
// the end, d = range * delta / cos(incidence), the true end lies (k + U) d beyond the outermost
// return: mean d (q / (1 - q) + 1/2), variance d^2 (q / (1 - q)^2 + 1/12), plus the range noise
// along the face, sigma^2 sin^2(incidence). An end where a perpendicular face was found is
// taken from that face instead.
void EndOffsets(const Context& ctx, const Candidate& cand, int k, const std::int8_t* labels,
                std::vector<double>* buf, EndOffset* lo, EndOffset* hi) {
  const Model& m = cand.model;
  const Extent& ext = cand.ext[k];
  double delta, q;
  BearingStep(ctx, m, k, ext, labels, buf, &delta, &q);
  const Eigen::Vector2d along = (k == 0) ? m.U0() : m.U1();
  const double r = q / (1.0 - q);
  auto offset = [&](double s_end) {
    const double step = StepAt(ctx, m, k, s_end, delta);
    const double sin_a = along.dot(ctx.Ray(m.c + along * s_end));
    return EndOffset{step * (r + 0.5), step * step * (r / (1.0 - q) + 1.0 / 12.0) +
                                           ctx.sigma2 * sin_a * sin_a};
  };
  *lo = offset(ext.s_min);
  *hi = offset(ext.s_max);
  if (m.num_edges == 1) {
    if (cand.perp[0].found) *lo = EndOffset{ext.s_min - cand.perp[0].s_corner, cand.perp[0].var};
    if (cand.perp[1].found) *hi = EndOffset{cand.perp[1].s_corner - ext.s_max, cand.perp[1].var};
  }
}

// A single edge's end may meet a perpendicular face that is seen at a grazing angle (below s,
// Eq. 15) or too thinly to make a corner. Its points near the corner lie within the inlier
// threshold of the edge and would be taken as inliers at the end, tilting the edge. Evidence: at
// least kMinPerpendicularPoints non-inliers behind the face (away from the sensor, within
// max_depth) on the perpendicular through the end (within their own threshold, allowing the
// corner to lie up to two beam steps beyond the outermost inlier). Their mean along-face position
// is the corner; its variance adds their noise along the edge and the tilt of the perpendicular
// by the edge's heading uncertainty over their depth.
constexpr int kMinPerpendicularPoints = 2;

bool FindPerpendicularFaces(const Context& ctx, const Candidate& cand, const std::int8_t* labels,
                            double max_depth, std::vector<double>* buf,
                            std::array<PerpendicularFace, 2>* perp) {
  const Model& m = cand.model;
  const Extent& ext = cand.ext[0];
  const Eigen::Vector2d u = m.U0();
  Eigen::Vector2d n_out = m.U1();
  if (n_out.dot(ctx.sensor - (m.c + u * (0.5 * (ext.s_min + ext.s_max)))) < 0.0) n_out = -n_out;
  double delta, q;
  BearingStep(ctx, m, 0, ext, labels, buf, &delta, &q);
  // Heading variance of the edge alone, 1 / sum w (t - mean t)^2, for the tilt term.
  double sw = 0.0, swt = 0.0, swt2 = 0.0;
  for (int i = 0; i < ctx.n; ++i) {
    if (labels[i] != 0) continue;
    const Eigen::Vector2d p = ctx.P(i);
    const double w = 1.0 / ctx.PerpVar(n_out.dot(ctx.RayAt(i)));
    const double t = u.dot(p - m.c);
    sw += w;
    swt += w * t;
    swt2 += w * t * t;
  }
  const double spread = swt2 - (sw > 0.0 ? swt * swt / sw : 0.0);
  const double var_heading = spread > 0.0 ? 1.0 / spread : 0.0;
  bool any = false;
  for (int e = 0; e < 2; ++e) {
    PerpendicularFace& f = (*perp)[e];
    f = PerpendicularFace();
    const double s_end = e == 0 ? ext.s_min : ext.s_max;
    const Eigen::Vector2d outward = e == 0 ? Eigen::Vector2d(-u) : u;
    const Eigen::Vector2d p_end = m.c + u * s_end;
    const double window = 2.0 * StepAt(ctx, m, 0, s_end, delta);
    int count = 0;
    double sum_w = 0.0, sum_w_off = 0.0, sum_depth2 = 0.0, zone = 0.0;
    for (int i = 0; i < ctx.n; ++i) {
      if (labels[i] >= 0) continue;
      const Eigen::Vector2d p = ctx.P(i);
      const Eigen::Vector2d v = p - p_end;
      const double depth = -n_out.dot(v);
      if (depth <= 0.0 || depth > max_depth) continue;
      // Clearly behind the edge, not one of its own points beyond an end.
      if (depth * depth < ctx.Threshold2(ctx.PerpVar(n_out.dot(ctx.RayAt(i))))) continue;
      const double var = ctx.PerpVar(u.dot(ctx.RayAt(i)));  // its face's normal is u
      const double t = std::sqrt(ctx.Threshold2(var));
      const double off = outward.dot(v);
      if (off < -t || off > window + t) continue;
      ++count;
      sum_w += 1.0 / var;
      sum_w_off += off / var;
      sum_depth2 += depth * depth;
      zone = std::max(zone, 2.0 * t);
    }
    if (count < kMinPerpendicularPoints) continue;
    const double off = sum_w_off / sum_w;
    f.found = true;
    f.s_corner = s_end + (e == 0 ? -off : off);
    f.var = 1.0 / sum_w + var_heading * sum_depth2 / count;
    f.zone = zone;
    any = true;
  }
  return any;
}

// The heading (Eq. 17 with the predicted heading) and the face of a single edge; its outward
// normal points to the sensor's side.
void EdgeHeading(const Context& ctx, const FitRequest& req, const FitParams& params,
                 const Model& m, double extent, double* theta, Face* face,
                 Eigen::Vector2d* n_out, const Eigen::Vector2d& mid) {
  *n_out = m.U1();
  if (n_out->dot(ctx.sensor - mid) < 0.0) *n_out = -*n_out;
  const double normal_angle = AngleOf(*n_out);
  if (req.predicted_theta) {
    const double tau =
        0.5 * kPi * std::round(AngleDiff(*req.predicted_theta, normal_angle) / (0.5 * kPi));
    *theta = WrapToPi(normal_angle + tau);
  } else {
    // Seen at a grazing angle, a face's seen extent says nothing of its length (the side of a car
    // parked along the road, seen from afar); a car's end ahead is seen nearly square.
    const Eigen::Vector2d to_sensor = ctx.sensor - mid;
    const bool grazing = params.side_face_min_incidence_deg < 90.0 &&
                         to_sensor.squaredNorm() > 0.0 &&
                         n_out->dot(to_sensor.normalized()) <
                             std::cos(DegToRad(params.side_face_min_incidence_deg));
    const bool side = extent > req.width_m + params.side_face_min_excess_m || grazing;
    *theta = InRightHalfPlane(side ? normal_angle + 0.5 * kPi : normal_angle);
  }
  *face = FaceFromNormal(normal_angle, *theta);
}

// With a known shape and face, a single edge's inliers longer than the face (clutter beside the
// vehicle on the line's extension) are trimmed to the window of the face's length (plus a
// margin of 3 sigma + 0.1 m for noise) that holds the most of them; the others are marked
// excluded. Returns true if any was.
bool TrimToKnownLength(const Context& ctx, const FitRequest& req, const FitParams& params,
                       const Candidate& cand, const std::int8_t* labels,
                       std::vector<double>* buf, std::int8_t* mask) {
  const Model& m = cand.model;
  const Extent& e = cand.ext[0];
  const Eigen::Vector2d u = m.U0();
  const Eigen::Vector2d mid = m.c + u * (0.5 * (e.s_min + e.s_max));
  double theta;
  Face face;
  Eigen::Vector2d n_out;
  EdgeHeading(ctx, req, params, m, e.s_max - e.s_min, &theta, &face, &n_out, mid);
  const double window =
      (IsSideFace(face) ? req.length_m : req.width_m) + 3.0 * std::sqrt(ctx.sigma2) + 0.1;
  if (e.s_max - e.s_min <= window) return false;
  std::vector<double>& s = *buf;
  s.clear();
  for (int i = 0; i < ctx.n; ++i) {
    if (EdgeOf(labels[i]) == 0) s.push_back(u.dot(ctx.P(i) - m.c));
  }
  std::sort(s.begin(), s.end());
  const int n = static_cast<int>(s.size());
  int best = 0, best_lo = 0;
  for (int lo = 0, hi = 0; lo < n; ++lo) {
    while (hi < n && s[hi] - s[lo] <= window) ++hi;
    if (hi - lo > best) {
      best = hi - lo;
      best_lo = lo;
    }
  }
  const double keep_lo = s[best_lo], keep_hi = s[best_lo + best - 1];
  bool any = false;
  for (int i = 0; i < ctx.n; ++i) {
    if (EdgeOf(labels[i]) != 0) continue;
    const double t = u.dot(ctx.P(i) - m.c);
    if (t < keep_lo || t > keep_hi) {
      mask[i] = kMaskExcluded;
      any = true;
    }
  }
  return any;
}

// Marks the edge's inliers within a perpendicular face's zone of its corner.
void MarkCornerZones(const Context& ctx, const Candidate& cand,
                     const std::array<PerpendicularFace, 2>& perp, std::int8_t* mask) {
  const Eigen::Vector2d u = cand.model.U0();
  for (int i = 0; i < ctx.n; ++i) {
    if (mask[i] == kMaskExcluded) continue;
    const double s = u.dot(ctx.P(i) - cand.model.c);
    if ((perp[0].found && s < perp[0].s_corner + perp[0].zone) ||
        (perp[1].found && s > perp[1].s_corner - perp[1].zone)) {
      mask[i] = kMaskAmbiguous;
    }
  }
}

// One weighted Gauss-Newton step on Eq. (16). Parameters (x_c, y_c, phi) for a corner; for a
// straight edge the position along the edge is no parameter (only the offset along its normal).
// Edge 0 runs along u0 = (cos phi, sin phi): its residual is u1 . (p - c), the second sum of
// Eq. (16); edge 1 runs along u1: residual u0 . (p - c), the first sum. Returns false if the
// normal equations are singular.
bool GaussNewtonStep(const Context& ctx, const std::int8_t* labels, Model* m,
                     double* step_size) {
  const Eigen::Vector2d u0 = m->U0(), u1 = m->U1();
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  for (int i = 0; i < ctx.n; ++i) {
    const int k = labels[i];
    if (k < 0 || k >= kAmbiguous) continue;
    const Eigen::Vector2d p = ctx.P(i);
    const Eigen::Vector2d v = p - m->c;
    const Eigen::Vector2d& normal = (k == 0) ? u1 : u0;
    // d(normal)/d(phi): d(u1)/d(phi) = -u0, d(u0)/d(phi) = u1.
    const Eigen::Vector2d d_normal = (k == 0) ? Eigen::Vector2d(-u0) : u1;
    const double r = normal.dot(v);
    const double w = 1.0 / ctx.PerpVar(normal.dot(ctx.RayAt(i)));
    const Eigen::Vector3d J(-normal.x(), -normal.y(), d_normal.dot(v));
    H.noalias() += w * J * J.transpose();
    g.noalias() += w * r * J;
  }
  Eigen::Vector3d delta;
  Eigen::Matrix3d cov;
  if (m->num_edges == 2) {
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(H);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 1e-12 * H.trace())) {
      return false;
    }
    delta = -ldlt.solve(g);
    cov = ldlt.solve(Eigen::Matrix3d::Identity());
  } else {
    Eigen::Matrix<double, 3, 2> B = Eigen::Matrix<double, 3, 2>::Zero();
    B(0, 0) = u1.x();
    B(1, 0) = u1.y();
    B(2, 1) = 1.0;
    const Eigen::Matrix2d H2 = B.transpose() * H * B;
    const Eigen::Vector2d g2 = B.transpose() * g;
    const Eigen::LDLT<Eigen::Matrix2d> ldlt(H2);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 1e-12 * H2.trace())) {
      return false;
    }
    delta = -B * ldlt.solve(g2);
    cov = B * ldlt.solve(Eigen::Matrix2d::Identity()) * B.transpose();
  }
  if (!delta.allFinite() || !cov.allFinite()) return false;
  m->cov = cov;
  *step_size = std::max(delta.head<2>().norm(), std::abs(delta.z()));
  m->c += delta.head<2>();
  m->phi = WrapToPi(m->phi + delta.z());
  return true;
}


}  // namespace

const char* ToString(FitFailure failure) {
  switch (failure) {
    case FitFailure::kNone: return "none";
    case FitFailure::kTooFewPoints: return "too few points";
    case FitFailure::kNonFinitePoint: return "non-finite point coordinate";
    case FitFailure::kNoConsensus: return "no visible edge with enough inliers";
    case FitFailure::kNotVisible: return "fitted edge not visible from the sensor (Eq. 15)";
    case FitFailure::kTooFewInliers: return "too few inliers";
    case FitFailure::kTooFewPointsInside: return "too few points inside the vehicle rectangle";
  }
  return "unknown";
}

namespace {

// |p[(m + 1) % 3] - p[m]|^2 for m = 0, 1, 2: every distance the three hypotheses of a triple
// use, once each (their norms: std::sqrt of these, as Eigen's norm()). A difference taken the
// other way is its exact negation (rounding to nearest is symmetric): the same square.
std::array<double, 3> SquaredSides(const Eigen::Vector2d& p0, const Eigen::Vector2d& p1,
                                   const Eigen::Vector2d& p2) {
  return {(p1 - p0).squaredNorm(), (p2 - p1).squaredNorm(), (p0 - p2).squaredNorm()};
}

// The corner from p_k's perpendicular foot on the line through p_i and p_j; len = |p_j - p_i|,
// other = |p_k - p_i|.
CornerHypothesis CornerHypothesisOf(const Eigen::Vector2d& pi, const Eigen::Vector2d& pj,
                                    const Eigen::Vector2d& pk, double len, double other) {
  CornerHypothesis h;
  const Eigen::Vector2d d = pj - pi;
  const double scale = std::max({len, other, 1e-300});
  if (!(len > 1e-9 * scale)) return h;  // coincident pair
  const Eigen::Vector2d u = d / len;
  h.corner = pi + u * u.dot(pk - pi);
  const Eigen::Vector2d b = pk - h.corner;
  const double blen = b.norm();
  if (!(blen > 1e-9 * scale)) return h;  // p_k on the line: collinear
  h.dir_b = b / blen;
  const double ti = u.dot(pi - h.corner), tj = u.dot(pj - h.corner);
  h.a_both_ways = (ti > 0.0) != (tj > 0.0);
  h.dir_a = (ti + tj > 0.0) ? u : Eigen::Vector2d(-u);
  h.degenerate = false;
  return h;
}

}  // namespace

std::array<CornerHypothesis, 3> CornerHypothesesFromPoints(const Eigen::Vector2d& p0,
                                                           const Eigen::Vector2d& p1,
                                                           const Eigen::Vector2d& p2) {
  const std::array<const Eigen::Vector2d*, 3> p = {&p0, &p1, &p2};
  const std::array<double, 3> sq = SquaredSides(p0, p1, p2);
  const std::array<double, 3> side = {std::sqrt(sq[0]), std::sqrt(sq[1]), std::sqrt(sq[2])};
  std::array<CornerHypothesis, 3> out;
  for (int k = 0; k < 3; ++k) {
    out[k] = CornerHypothesisOf(*p[(k + 1) % 3], *p[(k + 2) % 3], *p[k], side[(k + 1) % 3], side[k]);
  }
  return out;
}

namespace {

// Eq. (15) as written: the bearing of the view within limit of both edge directions (and of the
// reverse of a, when a runs both ways).
bool CornerVisibleByAngles(const CornerHypothesis& h, const Eigen::Vector2d& view,
                           double min_slant_rad) {
  const double theta_c = AngleOf(view);
  const double theta_a = AngleOf(h.dir_a), theta_b = AngleOf(h.dir_b);
  const double limit = 0.5 * kPi - min_slant_rad;
  bool visible = std::abs(AngleDiff(theta_c, theta_a)) < limit &&
                 std::abs(AngleDiff(theta_c, theta_b)) < limit;
  if (h.a_both_ways) visible = visible && std::abs(AngleDiff(theta_c, theta_a + kPi)) < limit;
  return visible;
}

enum class Clear { kYes, kNo, kUnsure };

// Whether the angle between u and v is below limit, without atan2: for limit in (0, pi/2] it
// is iff u.v > 0 and |u x v| < u.v tan(limit). kUnsure within a relative 1e-9 of that boundary
// (far beyond the rounding of this or the atan2 form) and for a zero vector.
Clear AngleBelow(const Eigen::Vector2d& u, const Eigen::Vector2d& v, double tan_limit) {
  constexpr double kMargin = 1e-9;
  const double dot = u.dot(v), cross = std::abs(u.x() * v.y() - u.y() * v.x());
  const double scale = u.norm() * v.norm();
  if (!(scale > 0.0)) return Clear::kUnsure;
  if (dot > kMargin * scale) {
    const double bound = dot * tan_limit;
    if (cross < bound * (1.0 - kMargin)) return Clear::kYes;
    if (cross > bound * (1.0 + kMargin)) return Clear::kNo;
  } else if (dot < -kMargin * scale) {
    return Clear::kNo;
  }
  return Clear::kUnsure;
}

// std::tan(limit), kept for the last limit asked on this thread: the fits ask for the one limit
// of their parameters a few thousand times a scan (std::tan on every call would be ~1 % of a
// KITTI scan's time). Any other limit (NaN, or a zero of the other sign) is computed anew.
double TanOf(double limit) {
  thread_local double last_limit = std::numeric_limits<double>::quiet_NaN();
  thread_local double last_tan = 0.0;
  if (!(limit == last_limit) || std::signbit(limit) != std::signbit(last_limit)) {
    last_tan = std::tan(limit);
    last_limit = limit;
  }
  return last_tan;
}

}  // namespace

bool CornerVisible(const CornerHypothesis& h, const Eigen::Vector2d& sensor_xy,
                   double min_slant_rad) {
  if (h.degenerate) return false;
  const Eigen::Vector2d view = h.corner - sensor_xy;
  if (view.squaredNorm() == 0.0) return false;
  // Eq. (15) by dot and cross products (three atan2 and remainders were a visible share of a
  // KITTI sweep); where any test is not clear, the angles themselves, so the answer is always
  // CornerVisibleByAngles'.
  const double limit = 0.5 * kPi - min_slant_rad;
  if (!(limit > 0.0 && limit <= 0.5 * kPi)) return CornerVisibleByAngles(h, view, min_slant_rad);
  const double tan_limit = TanOf(limit);
  const Clear a = AngleBelow(view, h.dir_a, tan_limit), b = AngleBelow(view, h.dir_b, tan_limit);
  const Clear c = h.a_both_ways ? AngleBelow(view, -h.dir_a, tan_limit) : Clear::kYes;
  if (a == Clear::kUnsure || b == Clear::kUnsure || c == Clear::kUnsure) {
    return CornerVisibleByAngles(h, view, min_slant_rad);
  }
  return a == Clear::kYes && b == Clear::kYes && c == Clear::kYes;
}

bool EdgeVisible(const Eigen::Vector2d& point, const Eigen::Vector2d& dir,
                 const Eigen::Vector2d& sensor_xy, double min_slant_rad) {
  const Eigen::Vector2d to_sensor = sensor_xy - point;
  if (to_sensor.squaredNorm() == 0.0 || dir.squaredNorm() == 0.0) return false;
  Eigen::Vector2d normal = Perp(dir);
  if (normal.dot(to_sensor) < 0.0) normal = -normal;
  const double limit = 0.5 * kPi - min_slant_rad;
  if (limit > 0.0 && limit <= 0.5 * kPi) {  // as in CornerVisible: the angles where not clear
    const Clear c = AngleBelow(normal, to_sensor, TanOf(limit));
    if (c != Clear::kUnsure) return c == Clear::kYes;
  }
  return std::abs(AngleDiff(AngleOf(normal), AngleOf(to_sensor))) < limit;
}

SegmentFitter::SegmentFitter(const FitParams& params) : params_(params) {
  std::string error;
  if (!params_.Validate(&error)) throw std::invalid_argument(error);
}

FitResult SegmentFitter::Fit(const FitRequest& request) {
  FitResult result;
  Fit(request, &result);
  return result;
}

namespace {

// Resets every output but the per-point flags (their buffer is reused, and they hold the labels
// while a candidate is measured).
void ResetKeepingFlags(FitResult* out) {
  std::vector<std::int8_t> flags = std::move(out->point_edge);
  std::vector<std::uint8_t> in_fit = std::move(out->point_in_fit);
  *out = FitResult();
  out->point_edge = std::move(flags);
  out->point_in_fit = std::move(in_fit);
}

// The message is composed only for a request refused: a stream built and destroyed per fit took
// about 0.2 % of a KITTI scan's instructions.
template <class... Parts>
[[noreturn]] void RefuseRequest(const Parts&... parts) {
  std::ostringstream os;
  (os << ... << parts);
  throw std::invalid_argument(os.str());
}

void CheckRequest(const FitRequest& r) {
  if (r.x.size() != r.y.size()) {
    RefuseRequest("FitRequest: x has ", r.x.size(), " points but y has ", r.y.size());
  } else if (r.x.size() > static_cast<std::size_t>(std::numeric_limits<int>::max() / 2)) {
    RefuseRequest("FitRequest: ", r.x.size(), " points are too many");
  } else if (!r.sensor_xy.allFinite()) {
    RefuseRequest("FitRequest.sensor_xy = (", r.sensor_xy.x(), ", ", r.sensor_xy.y(),
                  "): must be finite");
  } else if (!(r.length_m > 0.0 && std::isfinite(r.length_m))) {
    RefuseRequest("FitRequest.length_m = ", r.length_m, ": must be > 0");
  } else if (!(r.width_m > 0.0 && std::isfinite(r.width_m))) {
    RefuseRequest("FitRequest.width_m = ", r.width_m, ": must be > 0");
  } else if (!(r.length_std_m >= 0.0 && std::isfinite(r.length_std_m))) {
    RefuseRequest("FitRequest.length_std_m = ", r.length_std_m, ": must be >= 0");
  } else if (!(r.width_std_m >= 0.0 && std::isfinite(r.width_std_m))) {
    RefuseRequest("FitRequest.width_std_m = ", r.width_std_m, ": must be >= 0");
  } else if (r.predicted_theta && !std::isfinite(*r.predicted_theta)) {
    RefuseRequest("FitRequest.predicted_theta = ", *r.predicted_theta, ": must be finite");
  } else if (r.predicted_center && !r.predicted_center->allFinite()) {
    RefuseRequest("FitRequest.predicted_center = (", r.predicted_center->x(), ", ",
                  r.predicted_center->y(), "): must be finite");
  } else if (!r.profile_offset.allFinite()) {
    RefuseRequest("FitRequest.profile_offset = (", r.profile_offset.x(), ", ",
                  r.profile_offset.y(), "): must be finite");
  } else if (!(r.range_sigma_m > 0.0 && std::isfinite(r.range_sigma_m))) {
    RefuseRequest("FitRequest.range_sigma_m = ", r.range_sigma_m, ": must be > 0");
  } else if (!(r.min_inside_fraction >= 0.0 && r.min_inside_fraction <= 1.0)) {
    RefuseRequest("FitRequest.min_inside_fraction = ", r.min_inside_fraction,
                  ": must be in [0, 1]");
  }
}

// The rectangle a candidate places (Eq. 17): heading, centre and the dimensions used, with what
// the fit says of the seen extents in *out, and the parts of R that come from the shape.
struct CentreGeometry {
  double theta = 0.0;
  Eigen::Vector2d center = Eigen::Vector2d::Zero();     // local
  Eigen::Vector2d along_t = Eigen::Vector2d::Zero();    // single edge: the face's direction
  Eigen::Vector2d along_mid = Eigen::Vector2d::Zero();  // single edge: middle of the seen part
  double along_var = 0.0;                  // single edge: prior variance along the face
  Eigen::Matrix2d shape_cov = Eigen::Matrix2d::Zero();
  double length_used = 0.0, width_used = 0.0;
};

// A corner: the heading from the prediction (Eq. 17) or the longer seen edge; the centre half the
// dimensions in from the corner along both edges.
CentreGeometry CornerGeometry(const FitRequest& req, const FitParams& params, const Candidate& cand,
                              FitResult* out) {
  const Model& m = cand.model;
  const Eigen::Vector2d u0 = m.U0(), u1 = m.U1();
  const double k_full = params.partial_view_sigmas;
  CentreGeometry g;
  const Extent& e0 = cand.ext[0];
  const Extent& e1 = cand.ext[1];
  // Extents from the corner to the far end, corrected outwards (EndOffsets).
  const double E0 = e0.s_max + cand.hi[0].mean, E1 = e1.s_max + cand.hi[1].mean;
  // Far end, and the corner's own position along the edge.
  const Eigen::Matrix2d cov_c = m.cov.topLeftCorner<2, 2>();
  const double var_E0 = cand.hi[0].var + u0.dot(cov_c * u0);
  const double var_E1 = cand.hi[1].var + u1.dot(cov_c * u1);
  if (req.predicted_theta) {
    // Eq. (17): tau is the multiple of 90 deg bringing phi nearest the prediction (note 6).
    const double tau = 0.5 * kPi * std::round(AngleDiff(*req.predicted_theta, m.phi) / (0.5 * kPi));
    g.theta = WrapToPi(m.phi + tau);
  } else {
    g.theta = InRightHalfPlane(E0 >= E1 ? m.phi : m.phi + 0.5 * kPi);
  }
  // Edge 0's outward normal is -u1 (the body lies towards +u1), edge 1's is -u0.
  out->edges[0].face = FaceFromNormal(AngleOf(-u1), g.theta);
  out->edges[1].face = FaceFromNormal(AngleOf(-u0), g.theta);
  const bool edge0_is_length = IsSideFace(out->edges[0].face);
  const double E_len = edge0_is_length ? E0 : E1, E_wid = edge0_is_length ? E1 : E0;
  const double var_len = edge0_is_length ? var_E0 : var_E1;
  const double var_wid = edge0_is_length ? var_E1 : var_E0;
  g.length_used = req.shape_known ? req.length_m : std::max(req.length_m, E_len);
  g.width_used = req.shape_known ? req.width_m : std::max(req.width_m, E_wid);
  const Eigen::Vector2d u_len = edge0_is_length ? u0 : u1, u_wid = edge0_is_length ? u1 : u0;
  g.center = m.c + u_len * (0.5 * g.length_used) + u_wid * (0.5 * g.width_used);
  out->observed_length_m = E_len;
  out->observed_width_m = E_wid;
  out->observed_length_std_m = std::sqrt(var_len);
  out->observed_width_std_m = std::sqrt(var_wid);
  out->length_full_view = req.shape_known && req.length_m - E_len <= k_full * std::sqrt(var_len);
  out->width_full_view = req.shape_known && req.width_m - E_wid <= k_full * std::sqrt(var_wid);
  const Eigen::Vector2d axis = Dir(g.theta), lateral = Perp(axis);
  g.shape_cov = 0.25 * req.length_std_m * req.length_std_m * axis * axis.transpose() +
                0.25 * req.width_std_m * req.width_std_m * lateral * lateral.transpose();
  return g;
}

// A single edge: which face it is (EdgeHeading), the centre half the other dimension behind it,
// and along the face the seen part's middle (or, for a parked track, the prediction).
CentreGeometry EdgeGeometry(const Context& ctx, const FitRequest& req, const FitParams& params,
                            const Candidate& cand, FitResult* out) {
  const Model& m = cand.model;
  const Eigen::Vector2d u0 = m.U0();
  const double k_full = params.partial_view_sigmas;
  CentreGeometry g;
  const Extent& e = cand.ext[0];
  const double lo = e.s_min - cand.lo[0].mean, hi = e.s_max + cand.hi[0].mean;
  g.along_mid = m.c + u0 * (0.5 * (lo + hi));
  const double E = hi - lo;
  Eigen::Vector2d n_out;
  Face face;
  EdgeHeading(ctx, req, params, m, E, &g.theta, &face, &n_out, g.along_mid);
  out->edges[0].face = face;
  const bool side = IsSideFace(face);
  const double D_face = side ? req.length_m : req.width_m;
  const double D_perp = side ? req.width_m : req.length_m;
  const double std_face = side ? req.length_std_m : req.width_std_m;
  const double std_perp = side ? req.width_std_m : req.length_std_m;
  const double D_face_used = req.shape_known ? D_face : std::max(D_face, E);
  g.length_used = side ? D_face_used : D_perp;
  g.width_used = side ? D_perp : D_face_used;
  const double var_E = cand.lo[0].var + cand.hi[0].var;
  const bool full = req.shape_known && D_face - E <= k_full * std::sqrt(var_E);
  if (!full && req.predicted_center) {
    // Where along the face the seen part lies is not measured: the part's middle, taken anew on
    // every scan of the same partial view (a car half hidden behind another), is the same error
    // each time, and the filter would follow it (a parked car's track slid 2 m along its side at
    // 1.4 m/s). The centre stays where predicted if the seen part (its ends corrected outwards)
    // lies on the predicted face; else, the part's middle as before. (Moving the centre just far
    // enough to hold a part that sticks out instead gave parked cars whose corner fit took the
    // wrong axis a second track.) The variance along the face stays the paper's (below): the
    // filter still grows too sure of the position along a face it sees only in part over many
    // scans; the mean is no longer pulled.
    const double half = 0.5 * D_face_used;
    const double s_pred = u0.dot(*req.predicted_center - ctx.origin - m.c);
    if (s_pred >= hi - half && s_pred <= lo + half) g.along_mid = m.c + u0 * s_pred;
  }
  g.center = g.along_mid - n_out * (0.5 * D_perp);
  g.along_var = var_E / 4.0;
  if (!full) {
    const double missing = std::max(D_face_used - E, 0.0);
    g.along_var += 0.25 * (missing * missing + std_face * std_face);
  }
  g.along_t = u0;
  (side ? out->observed_length_m : out->observed_width_m) = E;
  (side ? out->observed_length_std_m : out->observed_width_std_m) = std::sqrt(var_E);
  (side ? out->length_full_view : out->width_full_view) = full;
  g.shape_cov = 0.25 * std_perp * std_perp * n_out * n_out.transpose();
  return g;
}

// Eq. (18) at the vehicle centre, weighted (see header): the information of the inliers' rows
// [-n_x, -n_y, n x (p - c)], scaled down by the variance factor when the residuals say the
// noise is larger than modelled.
struct CentreInformation {
  Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
  double factor = 1.0, sum_r2 = 0.0;
  int count = 0, fitted = 0;  // inliers; those not ambiguous
};
CentreInformation InformationAtCentre(const Context& ctx, const FitParams& params, const Model& m,
                                      const Eigen::Vector2d& center, const FitResult& out) {
  const Eigen::Vector2d u0 = m.U0(), u1 = m.U1();
  CentreInformation ci;
  double chi2 = 0.0;
  for (int i = 0; i < ctx.n; ++i) {
    const int k = out.point_edge[i];
    if (k < 0) continue;
    ++ci.count;
    if (k >= kAmbiguous) continue;
    const Eigen::Vector2d p = ctx.P(i);
    const Eigen::Vector2d& normal = (k == 0) ? u1 : u0;
    const double r = normal.dot(p - m.c);
    const double w = 1.0 / ctx.PerpVar(normal.dot(ctx.RayAt(i)));
    const Eigen::Vector3d J(-normal.x(), -normal.y(), Cross(normal, p - center));
    ci.info.noalias() += w * J * J.transpose();
    chi2 += w * r * r;
    ci.sum_r2 += r * r;
    ++ci.fitted;
  }
  const int dof = ci.fitted - (m.num_edges == 2 ? 3 : 2);
  if (params.variance_factor_sigmas > 0.0 && dof > 0) {
    const double ratio = chi2 / dof;
    if (ratio > 1.0 + params.variance_factor_sigmas * std::sqrt(2.0 / dof)) ci.factor = ratio;
  }
  ci.info /= ci.factor;
  return ci;
}

// R = the inverse information, with the single edge's position along the face and its second
// order term, and the shape's part. False if the information is singular.
bool CovarianceAtCentre(const CentreGeometry& g, bool corner, Eigen::Matrix3d info,
                        Eigen::Matrix3d* R_out) {
  if (!corner) {
    // The position along the face: residual t . (c - m) about the extent's middle m.
    const Eigen::Vector3d e(g.along_t.x(), g.along_t.y(), Perp(g.along_t).dot(g.center - g.along_mid));
    info.noalias() += e * e.transpose() / g.along_var;
  }
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(info);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 1e-12 * info.trace())) {
    return false;  // cannot happen with >= min_edge_inliers spread points
  }
  Eigen::Matrix3d R = ldlt.solve(Eigen::Matrix3d::Identity());
  if (!corner) {
    // Second order: the face line is known about the seen part; a heading error d_theta moves it
    // by (s - s_hat) d_theta at the centre's true position s along the face, a product of two
    // independent errors with variance var_along * var_theta. It matters when part of the face
    // is hidden (var_along large): the linear R above cannot contain it.
    const double var_along = g.along_t.dot(R.topLeftCorner<2, 2>() * g.along_t);
    const Eigen::Vector2d normal = Perp(g.along_t);
    R.topLeftCorner<2, 2>() += var_along * R(2, 2) * normal * normal.transpose();
  }
  R.topLeftCorner<2, 2>() += g.shape_cov;
  *R_out = 0.5 * (R + R.transpose()).eval();
  return true;
}

// The fit's outputs: kind, edges, z, R and the points' labels.
void FillResult(const Context& ctx, const Candidate& cand, const CentreGeometry& g,
                const CentreInformation& ci, const Eigen::Matrix3d& R, FitResult* out) {
  const Model& m = cand.model;
  const bool corner = m.num_edges == 2;
  out->kind = corner ? FitKind::kCorner : FitKind::kEdge;
  out->num_edges = m.num_edges;
  out->phi = WrapToPi(m.phi);
  out->corner = corner ? Eigen::Vector2d(m.c + ctx.origin) : Eigen::Vector2d::Constant(kNaN);
  for (int k = 0; k < m.num_edges; ++k) {
    const Eigen::Vector2d u = k == 0 ? m.U0() : m.U1();
    const Extent& e = cand.ext[k];
    out->edges[k].start = ctx.origin + m.c + u * (corner ? 0.0 : e.s_min);
    out->edges[k].end = ctx.origin + m.c + u * e.s_max;
    out->edges[k].num_inliers = cand.counts[k];
  }
  out->z << g.center + ctx.origin, g.theta;
  out->R = R;
  out->length_used_m = g.length_used;
  out->width_used_m = g.width_used;
  out->num_inliers = ci.count;
  out->variance_factor = ci.factor;
  out->rms_residual_m = std::sqrt(ci.sum_r2 / std::max(ci.fitted, 1));
  out->point_in_fit.resize(ctx.n);
  for (int i = 0; i < ctx.n; ++i) {
    std::int8_t& label = out->point_edge[i];
    out->point_in_fit[i] = label >= 0 && label < kAmbiguous;
    label = static_cast<std::int8_t>(EdgeOf(label));
  }
}

// Turns a refined candidate into z, R and the geometry outputs (Eq. 17, 18). Returns the reason
// if the candidate is rejected (inside fraction) or kNone.
FitFailure Measure(const Context& ctx, const FitRequest& req, const FitParams& params,
                   const Candidate& cand, FitResult* out) {
  const bool corner = cand.model.num_edges == 2;
  const CentreGeometry g = corner ? CornerGeometry(req, params, cand, out)
                                  : EdgeGeometry(ctx, req, params, cand, out);
  const CentreInformation ci = InformationAtCentre(ctx, params, cand.model, g.center, *out);
  Eigen::Matrix3d R;
  if (!CovarianceAtCentre(g, corner, ci.info, &R)) return FitFailure::kNoConsensus;
  // Required share of the segment inside the rectangle (the hypothesis' constraint).
  OrientedBox box{g.center, g.theta, g.length_used, g.width_used};
  int inside = 0;
  for (int i = 0; i < ctx.n; ++i) inside += box.Contains(ctx.P(i), params.inside_margin_m) ? 1 : 0;
  out->inside_fraction = static_cast<double>(inside) / ctx.n;
  if (out->inside_fraction < req.min_inside_fraction) return FitFailure::kTooFewPointsInside;
  FillResult(ctx, cand, g, ci, R, out);
  return FitFailure::kNone;
}

// The scoring subset of RANSAC (internal::Subset): one point drawn from each of S equal strata
// of the point order (local coordinates and ray directions).
using internal::Subset;

Subset DrawSubset(const Context& ctx, int max_points, std::minstd_rand& rng, std::vector<double>* sx,
                  std::vector<double>* sy, std::vector<double>* srx, std::vector<double>* sry) {
  const int n = ctx.n;
  const int S = std::min(n, max_points);
  sx->resize(S);
  sy->resize(S);
  srx->resize(S);
  sry->resize(S);
  // The strata hold floor(n / S) or one more points: one IndexDraw for each size.
  const int small = n / S;
  const internal::IndexDraw in_small(0, std::max(small - 1, 0)), in_large(0, small);
  for (int i = 0; i < S; ++i) {
    const int lo = static_cast<int>(static_cast<std::int64_t>(i) * n / S);
    const int hi = static_cast<int>(static_cast<std::int64_t>(i + 1) * n / S) - 1;
    const int idx = hi > lo ? lo + (hi - lo + 1 == small ? in_small : in_large)(rng) : lo;
    const Eigen::Vector2d p = ctx.P(idx);
    const Eigen::Vector2d ray = ctx.RayAt(idx);
    (*sx)[i] = p.x();
    (*sy)[i] = p.y();
    (*srx)[i] = ray.x();
    (*sry)[i] = ray.y();
  }
  return {sx->data(), sy->data(), srx->data(), sry->data(), S};
}

// Adaptive RANSAC: draws samples until the iterations needed for the best model so far (or the
// cap) have passed, and at least min_iterations. try_sample(&best, &best_cost, &needed) draws
// and scores one sample, replacing the best model and the iterations needed when it is better.
template <class TrySample>
Model AdaptiveRansac(int max_iterations, int min_iterations, TrySample&& try_sample) {
  Model best;
  double best_cost = std::numeric_limits<double>::infinity();
  int needed = max_iterations;
  for (int it = 0; it < max_iterations; ++it) {
    if (it >= needed && it >= min_iterations) break;
    try_sample(&best, &best_cost, &needed);
  }
  return best;
}

// RANSAC for a straight edge (2 points): the truncated quadratic cost of Eq. (16) over the
// subset; samples whose edge the sensor cannot see (Eq. 15) are skipped.
Model RansacEdge(const Context& ctx, const Subset& sub, const FitParams& P, double slant,
                 const internal::IndexDraw& pick, std::minstd_rand& rng) {
  const int S = sub.size;
  const double min_sep2 = P.min_sample_separation_m * P.min_sample_separation_m;
  auto try_sample = [&](Model* best, double* best_cost, int* needed) {
    const int i = pick(rng), j = pick(rng);
    if (i == j) return;
    const Eigen::Vector2d pi = sub.P(i), pj = sub.P(j);
    const Eigen::Vector2d d = pj - pi;
    if (d.squaredNorm() < std::max(min_sep2, 1e-18)) return;
    const Eigen::Vector2d u = d.normalized();
    const Eigen::Vector2d mid = 0.5 * (pi + pj);
    if (!EdgeVisible(mid, u, ctx.sensor, slant)) return;
    int inliers = 0;
    const double cost = internal::EdgeCost(ctx, sub, mid, Perp(u), *best_cost, &inliers);
    if (cost < *best_cost) {
      *best_cost = cost;
      best->num_edges = 1;
      best->c = mid;
      best->phi = AngleOf(u);
      const double w = static_cast<double>(inliers) / S;
      *needed = IterationsFor(w * w, P.ransac_confidence);
    }
  };
  return AdaptiveRansac(P.max_edge_iterations, P.min_iterations, try_sample);
}

// RANSAC for a corner (3 points, the three corners of Figure 3 each, filtered by Eq. 15).
Model RansacCorner(const Context& ctx, const Subset& sub, const FitParams& P, double slant,
                   const internal::IndexDraw& pick, std::minstd_rand& rng) {
  const int S = sub.size;
  if (S < 3) return Model{};
  const double min_sep2 = P.min_sample_separation_m * P.min_sample_separation_m;
  auto try_sample = [&](Model* best, double* best_cost, int* needed) {
    const int idx[3] = {pick(rng), pick(rng), pick(rng)};
    if (idx[0] == idx[1] || idx[1] == idx[2] || idx[0] == idx[2]) return;
    const Eigen::Vector2d q[3] = {sub.P(idx[0]), sub.P(idx[1]), sub.P(idx[2])};
    // CornerHypothesesFromPoints' hypotheses, each built only if its pair is far enough apart
    // (the test does not depend on the hypothesis: the same ones are scored).
    const std::array<double, 3> sq = SquaredSides(q[0], q[1], q[2]);
    const std::array<double, 3> side = {std::sqrt(sq[0]), std::sqrt(sq[1]), std::sqrt(sq[2])};
    for (int k = 0; k < 3; ++k) {
      if (sq[(k + 1) % 3] < min_sep2) continue;  // |q_j - q_i|^2
      const CornerHypothesis h =
          CornerHypothesisOf(q[(k + 1) % 3], q[(k + 2) % 3], q[k], side[(k + 1) % 3], side[k]);
      if (h.degenerate || h.a_both_ways) continue;
      if ((q[k] - h.corner).squaredNorm() < min_sep2) continue;
      if (!CornerVisible(h, ctx.sensor, slant)) continue;
      const Eigen::Vector2d u0 = Cross(h.dir_a, h.dir_b) > 0.0 ? h.dir_a : h.dir_b;
      const Eigen::Vector2d u1 = Perp(u0);
      int n0 = 0, n1 = 0;
      const double cost = internal::CornerCost(ctx, sub, h.corner, u0, u1, *best_cost, &n0, &n1);
      if (cost < *best_cost) {
        *best_cost = cost;
        best->num_edges = 2;
        best->c = h.corner;
        best->phi = AngleOf(u0);
        const double wa = static_cast<double>(n0) / S, wb = static_cast<double>(n1) / S;
        // A triple is a good sample if it holds points of both edges and no outlier.
        *needed = IterationsFor(3.0 * wa * wb * (wa + wb), P.ransac_confidence);
      }
    }
  };
  return AdaptiveRansac(P.max_corner_iterations, P.min_iterations, try_sample);
}

// Refinement of RANSAC's models on all points, and the measurement of the chosen one.
class Refiner {
 public:
  Refiner(const Context& ctx, const FitRequest& req, const FitParams& P, FitResult* out,
          std::vector<double>* proj, std::vector<double>* gaps)
      : ctx_(ctx), req_(req), P_(P), out_(out), labels_(out->point_edge.data()), proj_(proj),
        gaps_(gaps) {}

  // Single edge: points marked ambiguous or excluded (nullptr: none).
  void set_mask(const std::int8_t* mask) { mask_ = mask; }
  const std::int8_t* mask() const { return mask_; }
  std::int8_t* labels() const { return labels_; }
  FitFailure failure() const { return failure_; }
  void set_failure(FitFailure f) { failure_ = f; }

  // Inliers of the candidate's model into the labels, their runs and extents; a checksum of
  // the classification.
  std::uint64_t Classify(Candidate* cand) {
    std::uint64_t checksum = vtrack::Classify(ctx_, cand->model, mask_, labels_, cand->counts);
    for (int k = 0; k < cand->model.num_edges; ++k) {
      cand->ext[k] = GapFilter(ctx_, cand->model, k, P_.max_inlier_gap_m, P_.max_gap_spacings,
                               labels_, proj_, gaps_);
      cand->counts[k] = cand->ext[k].n;
      checksum = checksum * 31 + static_cast<std::uint64_t>(cand->ext[k].n);
    }
    return checksum;
  }

  // Eq. (16) from a RANSAC sample: the inlier set changes as the model improves, so steps and
  // classification alternate until the step is negligible and the inliers stay the same (the
  // model is then the minimum of Eq. 16 over exactly the inliers reported and used for R). The
  // inlier set can oscillate between two models (a point at the threshold): then it finishes on
  // the last classification held fixed.
  void Refine(const Model& start, Candidate* cand) {
    cand->model = start;
    std::uint64_t checksum = Classify(cand);
    bool converged = false;
    for (int it = 0; it < P_.gauss_newton_iterations; ++it) {
      if (!Step(cand)) break;
      const std::uint64_t previous = checksum;
      checksum = Classify(cand);
      if (last_step_ < kConvergedStep && checksum == previous) {
        converged = true;
        break;
      }
    }
    for (int it = 0; !converged && it < P_.gauss_newton_iterations; ++it) {
      if (!Step(cand)) break;
      converged = last_step_ < kConvergedStep;
    }
  }

  // Enough inliers, then the measurement (Measure); true if the candidate is the fit.
  bool Accept(Candidate& cand) {
    const int total = cand.counts[0] + cand.counts[1];
    if (total < P_.min_inlier_fraction * ctx_.n) {
      failure_ = FitFailure::kTooFewInliers;
      return false;
    }
    for (int k = 0; k < cand.model.num_edges; ++k) {
      EndOffsets(ctx_, cand, k, labels_, proj_, &cand.lo[k], &cand.hi[k]);
    }
    ResetKeepingFlags(out_);  // a rejected corner leaves nothing behind for the edge
    failure_ = Measure(ctx_, req_, P_, cand, out_);
    return failure_ == FitFailure::kNone;
  }

 private:
  // One Gauss-Newton step of Eq. (16) on the current inliers; false if none was possible.
  bool Step(Candidate* cand) {
    if (cand->counts[0] + cand->counts[1] < 3) return false;
    Model stepped = cand->model;
    double step = 0.0;
    if (!GaussNewtonStep(ctx_, labels_, &stepped, &step)) return false;
    cand->model = stepped;
    last_step_ = step;
    return true;
  }

  const Context& ctx_;
  const FitRequest& req_;
  const FitParams& P_;
  FitResult* out_;
  std::int8_t* labels_;
  std::vector<double>* proj_;
  std::vector<double>* gaps_;
  const std::int8_t* mask_ = nullptr;
  FitFailure failure_ = FitFailure::kNoConsensus;
  double last_step_ = 0.0;
};

// The corner, if it explains enough more than the edge and both its edges are seen.
bool TryCorner(const Context& ctx, const Model& best_corner, const Candidate& edge_cand,
               const FitParams& P, double slant, Refiner* r) {
  Candidate cand;
  r->Refine(best_corner, &cand);
  const int total = cand.counts[0] + cand.counts[1];
  const int need = std::max<int>(P.min_edge_inliers,
                                 static_cast<int>(std::ceil(P.min_second_edge_fraction * total)));
  CornerHypothesis refined;
  refined.corner = cand.model.c;
  refined.dir_a = cand.model.U0();
  refined.dir_b = cand.model.U1();
  refined.degenerate = false;
  return cand.counts[0] >= need && cand.counts[1] >= need && total >= edge_cand.counts[0] + need &&
         CornerVisible(refined, ctx.sensor, slant) && r->Accept(cand);
}

// The edge: inliers beyond the vehicle's known length and those near a perpendicular face
// behind an end are set aside and the edge refined again; then, if the sensor sees it (Eq. 15),
// measured.
bool FitEdge(const Context& ctx, const FitRequest& req, const FitParams& P, double slant,
             bool edge_labelled, Candidate* edge_cand, std::vector<std::int8_t>* mask_buf,
             std::vector<double>* proj, Refiner* r) {
  Candidate& cand = *edge_cand;
  if (!edge_labelled) r->Classify(&cand);  // the corner overwrote the labels
  // Longer than the vehicle: keep the inliers that fit in its known length.
  if (cand.counts[0] >= P.min_edge_inliers && req.shape_known && req.predicted_theta) {
    mask_buf->assign(ctx.n, 0);
    if (TrimToKnownLength(ctx, req, P, cand, r->labels(), proj, mask_buf->data())) {
      r->set_mask(mask_buf->data());
      r->Refine(cand.model, &cand);
    }
  }
  // A perpendicular face behind an end: its points near the corner are no face points.
  const double max_depth = std::max(req.length_m, req.width_m) + P.inside_margin_m;
  if (cand.counts[0] >= P.min_edge_inliers &&
      FindPerpendicularFaces(ctx, cand, r->labels(), max_depth, proj, &cand.perp)) {
    if (r->mask() == nullptr) mask_buf->assign(ctx.n, 0);
    MarkCornerZones(ctx, cand, cand.perp, mask_buf->data());
    r->set_mask(mask_buf->data());
    r->Refine(cand.model, &cand);
    FindPerpendicularFaces(ctx, cand, r->labels(), max_depth, proj, &cand.perp);
  }
  if (cand.counts[0] < P.min_edge_inliers) return false;
  const Extent& e = cand.ext[0];
  const Eigen::Vector2d mid = cand.model.c + cand.model.U0() * (0.5 * (e.s_min + e.s_max));
  if (!EdgeVisible(mid, cand.model.U0(), ctx.sensor, slant)) {
    r->set_failure(FitFailure::kNotVisible);
    return false;
  }
  return r->Accept(cand);
}

// At least min_points points, all finite; otherwise the failure in *out.
bool UsablePoints(const FitRequest& req, const FitParams& P, FitResult* out) {
  const int n = static_cast<int>(req.x.size());
  if (n < P.min_points) {
    out->failure = FitFailure::kTooFewPoints;
    return false;
  }
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(req.x[i]) || !std::isfinite(req.y[i])) {
      out->failure = FitFailure::kNonFinitePoint;
      out->bad_point = i;
      return false;
    }
  }
  return true;
}

// Local coordinates (about the first point) and rays once per fit, into the buffers: every
// classification pass reuses them.
Context MakeContext(const FitRequest& req, const FitParams& P, std::vector<double>* px,
                    std::vector<double>* py, std::vector<double>* rx, std::vector<double>* ry) {
  const int n = static_cast<int>(req.x.size());
  Context ctx;
  ctx.n = n;
  ctx.origin = Eigen::Vector2d(req.x[0], req.y[0]);
  ctx.sensor = req.sensor_xy - ctx.origin;
  ctx.profile = req.profile;
  ctx.profile_origin = req.profile_offset + ctx.origin;
  px->resize(n);
  py->resize(n);
  rx->resize(n);
  ry->resize(n);
  for (int i = 0; i < n; ++i) {
    (*px)[i] = static_cast<double>(req.x[i]) - ctx.origin.x();
    (*py)[i] = static_cast<double>(req.y[i]) - ctx.origin.y();
    const Eigen::Vector2d ray = ctx.Ray({(*px)[i], (*py)[i]});
    (*rx)[i] = ray.x();
    (*ry)[i] = ray.y();
  }
  ctx.px = px->data();
  ctx.py = py->data();
  ctx.rx = rx->data();
  ctx.ry = ry->data();
  ctx.sigma2 = req.range_sigma_m * req.range_sigma_m;
  ctx.surface2 = P.surface_std_m * P.surface_std_m;
  ctx.k2 = P.inlier_sigmas * P.inlier_sigmas;
  ctx.min_t2 = P.min_inlier_distance_m * P.min_inlier_distance_m;
  return ctx;
}

}  // namespace

bool SegmentFitter::Consensus::Matches(const FitRequest& req) const {
  // Bit for bit, not by ==: -0.0 == 0.0, but a signed zero can turn an atan2 by 2 pi.
  const auto same = [](const void* a, const void* b, std::size_t bytes) {
    return bytes == 0 || std::memcmp(a, b, bytes) == 0;
  };
  return valid && seed == req.seed && x.size() == req.x.size() &&
         same(&range_sigma_m, &req.range_sigma_m, sizeof(double)) &&
         same(sensor_xy.data(), req.sensor_xy.data(), 2 * sizeof(double)) &&
         same(x.data(), req.x.data(), x.size() * sizeof(float)) &&
         same(y.data(), req.y.data(), y.size() * sizeof(float));
}

void SegmentFitter::Fit(const FitRequest& req, FitResult* out) {
  CheckRequest(req);
  const FitParams& P = params_;
  const int n = static_cast<int>(req.x.size());
  ResetKeepingFlags(out);
  out->point_edge.assign(n, FitResult::kOutlier);
  out->point_in_fit.assign(n, 0);
  if (!UsablePoints(req, P, out)) return;
  const Context ctx = MakeContext(req, P, &px_, &py_, &rx_, &ry_);
  const double slant = DegToRad(P.min_slant_deg);
  // A small-state engine: seeding std::mt19937 (2.5 kB of state) would cost more than a small
  // fit; minstd is plenty for drawing sample indices.
  Model best_edge, best_corner;
  if (consensus_.Matches(req)) {
    best_edge.num_edges = consensus_.num_edges[0];
    best_edge.c = consensus_.c[0];
    best_edge.phi = consensus_.phi[0];
    best_corner.num_edges = consensus_.num_edges[1];
    best_corner.c = consensus_.c[1];
    best_corner.phi = consensus_.phi[1];
  } else {
    std::minstd_rand rng(
        static_cast<std::uint_fast32_t>((req.seed ^ (req.seed >> 32)) % 2147483646u) + 1u);
    const Subset sub = DrawSubset(ctx, P.max_scoring_points, rng, &sx_, &sy_, &srx_, &sry_);
    const internal::IndexDraw pick(0, sub.size - 1);
    best_edge = RansacEdge(ctx, sub, P, slant, pick, rng);
    best_corner = RansacCorner(ctx, sub, P, slant, pick, rng);
    consensus_.x.assign(req.x.begin(), req.x.end());
    consensus_.y.assign(req.y.begin(), req.y.end());
    consensus_.sensor_xy = req.sensor_xy;
    consensus_.range_sigma_m = req.range_sigma_m;
    consensus_.seed = req.seed;
    consensus_.num_edges[0] = best_edge.num_edges;
    consensus_.c[0] = best_edge.c;
    consensus_.phi[0] = best_edge.phi;
    consensus_.num_edges[1] = best_corner.num_edges;
    consensus_.c[1] = best_corner.c;
    consensus_.phi[1] = best_corner.phi;
    consensus_.valid = true;
  }
  // Refinement on all points, then the choice between corner and edge: the best edge first, a
  // corner must explain what it cannot.
  Refiner r(ctx, req, P, out, &proj_, &gaps_);
  Candidate edge_cand;
  if (best_edge.num_edges == 1) r.Refine(best_edge, &edge_cand);
  bool edge_labelled = true;  // the labels hold edge_cand's classification
  if (best_corner.num_edges == 2) {
    edge_labelled = false;
    if (TryCorner(ctx, best_corner, edge_cand, P, slant, &r)) return;
  }
  if (best_edge.num_edges == 1 &&
      FitEdge(ctx, req, P, slant, edge_labelled, &edge_cand, &mask_, &proj_, &r)) {
    return;
  }
  // No fit: reset the partial outputs.
  ResetKeepingFlags(out);
  std::fill(out->point_edge.begin(), out->point_edge.end(), FitResult::kOutlier);
  out->point_in_fit.assign(n, 0);
  out->failure = r.failure();
}
}  // namespace vtrack
