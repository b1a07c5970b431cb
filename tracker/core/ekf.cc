#include "tracker/core/ekf.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "base/angle.h"

namespace vtrack {
namespace {

// .eval(): assigning an expression with the transpose of its destination would alias.
void Symmetrise(Matrix6d* P) { *P = (0.5 * (*P + P->transpose())).eval(); }

[[noreturn]] void ThrowInvalid(const std::string& what, double value) {
  std::ostringstream os;
  os.precision(10);
  os << what << " = " << value;
  throw std::invalid_argument(os.str());
}

void CheckKind(const MotionModel& model, const Hypothesis& h) {
  if (h.kind != model.kind()) {
    throw std::invalid_argument(std::string("hypothesis of kind ") + ToString(h.kind) +
                                " given to the " + ToString(model.kind()) + " model");
  }
}

}  // namespace

void EkfPredict(const MotionModel& model, double dt, double noise_scale, Hypothesis* h) {
  CheckKind(model, *h);
  if (!std::isfinite(dt) || dt < 0.0) ThrowInvalid("EkfPredict: dt [s] must be finite and >= 0, got dt", dt);
  if (!std::isfinite(noise_scale) || noise_scale <= 0.0) {
    ThrowInvalid("EkfPredict: noise_scale [-] must be finite and > 0, got noise_scale",
                 noise_scale);
  }
  // Eq. (19): x- = f(x+), P- = Phi P+ Phi^T + k Q. Q is evaluated at x+, where it was derived.
  Matrix6d Phi;
  const Matrix6d Q = model.ProcessNoise(h->x, dt);
  h->x = model.Propagate(h->x, dt, &Phi);
  h->P = Phi * h->P * Phi.transpose() + noise_scale * Q;
  Symmetrise(&h->P);
}

UpdateResult EkfUpdate(const MotionModel& model, const CentreMeasurement& m, double gate_nis,
                       Hypothesis* h) {
  CheckKind(model, *h);
  UpdateResult result;
  result.gate = gate_nis;

  // R must be a covariance: finite, symmetric (to rounding) and positive definite.
  if (!m.z.allFinite() || !m.R.allFinite()) {
    result.reason = UpdateStatus::kInvalidMeasurement;
    return result;
  }
  const double r_scale = m.R.cwiseAbs().maxCoeff();
  if (!((m.R - m.R.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * r_scale) ||
      Eigen::LLT<Eigen::Matrix3d>(m.R).info() != Eigen::Success) {
    result.reason = UpdateStatus::kInvalidMeasurement;
    return result;
  }
  if (!h->x.allFinite() || !h->P.allFinite()) {
    result.reason = UpdateStatus::kInvalidState;
    return result;
  }

  // Eq. (14): H picks the measured (x, y, theta) out of the state.
  const std::array<int, 3> idx = model.PoseIndices();
  Eigen::Matrix<double, 3, 6> H = Eigen::Matrix<double, 3, 6>::Zero();
  for (int r = 0; r < 3; ++r) H(r, idx[r]) = 1.0;

  Eigen::Vector3d nu(m.z(0) - h->x(idx[0]), m.z(1) - h->x(idx[1]),
                     AngleDiff(m.z(2), h->x(idx[2])));
  result.innovation = nu;

  const Eigen::Matrix<double, 6, 3> PHt = h->P * H.transpose();
  const Eigen::Matrix3d S_raw = H * PHt + m.R;
  const Eigen::Matrix3d S = 0.5 * (S_raw + S_raw.transpose());
  result.innovation_cov = S;
  const Eigen::LLT<Eigen::Matrix3d> llt(S);
  if (llt.info() != Eigen::Success) {
    result.reason = UpdateStatus::kSingularInnovation;
    return result;
  }
  result.nis = nu.dot(llt.solve(nu));
  if (!(result.nis <= gate_nis)) {
    result.reason = UpdateStatus::kGated;
    return result;
  }

  // Eq. (19): K = P- H^T S^-1 (S symmetric, so K^T = S^-1 H P-).
  const Eigen::Matrix<double, 6, 3> K = llt.solve(PHt.transpose()).transpose();
  h->x += K * nu;
  h->x(idx[2]) = WrapToPi(h->x(idx[2]));
  // Joseph form of P+ = P- - K H P-.
  const Matrix6d A = Matrix6d::Identity() - K * H;
  h->P = A * h->P * A.transpose() + K * m.R * K.transpose();
  Symmetrise(&h->P);

  result.accepted = true;
  result.reason = UpdateStatus::kAccepted;
  return result;
}

double ChiSquareCdf(double x, int dof) {
  if (dof < 1 || dof > 1000) ThrowInvalid("ChiSquareCdf: dof must be in [1, 1000], got dof", dof);
  if (std::isnan(x)) ThrowInvalid("ChiSquareCdf: x must not be NaN, got x", x);
  if (x <= 0.0) return 0.0;
  if (std::isinf(x)) return 1.0;
  // Regularised lower incomplete gamma P(dof/2, x/2) for integer dof:
  //   even dof = 2m:   1 - e^-y sum_{i=0}^{m-1} y^i / i!
  //   odd dof = 2m+1:  erf(sqrt y) - e^-y sum_{i=1}^{m} y^(i-1/2) / Gamma(i + 1/2)
  const double y = 0.5 * x;
  const int m = dof / 2;
  double sum = 0.0;
  if (dof % 2 == 0) {
    double term = 1.0;
    for (int i = 0; i < m; ++i) {
      if (i > 0) term *= y / i;
      sum += term;
    }
    return std::max(0.0, 1.0 - std::exp(-y) * sum);
  }
  double term = std::sqrt(y) / (0.5 * std::sqrt(kPi));  // y^(1/2) / Gamma(3/2)
  for (int i = 1; i <= m; ++i) {
    if (i > 1) term *= y / (i - 0.5);
    sum += term;
  }
  return std::clamp(std::erf(std::sqrt(y)) - std::exp(-y) * sum, 0.0, 1.0);
}

double ChiSquareQuantile(double p, int dof) {
  if (!(p > 0.0 && p < 1.0)) ThrowInvalid("ChiSquareQuantile: p must be in (0, 1), got p", p);
  if (dof < 1 || dof > 1000) ThrowInvalid("ChiSquareQuantile: dof must be in [1, 1000], got dof", dof);
  // The CDF is monotone: bracket, then bisect to the resolution of a double.
  double lo = 0.0, hi = std::max(1.0, static_cast<double>(dof));
  while (ChiSquareCdf(hi, dof) < p) {
    lo = hi;
    hi *= 2.0;
  }
  for (int i = 0; i < 200 && hi - lo > 1e-14 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (ChiSquareCdf(mid, dof) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

Ekf::Ekf(const IsmParams& ism, const VasmParams& vasm, const EkfParams& ekf, const CvParams& cv)
    : ism_(ism), vasm_(vasm), cv_(cv), params_(ekf) {
  std::string error;
  if (!params_.Validate(&error)) throw std::invalid_argument(error);
  gate_nis_ = ChiSquareQuantile(params_.gate_probability, 3);
}

const MotionModel& Ekf::model(ModelKind kind) const {
  switch (kind) {
    case ModelKind::kIsm:
      return ism_;
    case ModelKind::kVasm:
      return vasm_;
    case ModelKind::kCv:
      return cv_;
  }
  throw std::invalid_argument("Ekf::model: unknown model kind " +
                              std::to_string(static_cast<int>(kind)));
}

void Ekf::Predict(double dt, double noise_scale, Hypothesis* h) const {
  EkfPredict(model(h->kind), dt, noise_scale, h);
}

UpdateResult Ekf::Update(const CentreMeasurement& m, Hypothesis* h) const {
  return EkfUpdate(model(h->kind), m, gate_nis_, h);
}

CentreEstimate Ekf::Centre(const Hypothesis& h) const {
  const MotionModel& mm = model(h.kind);
  Matrix6d D;
  const Vector6d ism = mm.ToIsmState(h.x, &D);
  const Matrix6d P_ism = D * h.P * D.transpose();

  CentreEstimate e;
  e.pose << ism(0), ism(2), ism(4);
  const int pose_idx[3] = {0, 2, 4};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) e.pose_cov(r, c) = P_ism(pose_idx[r], pose_idx[c]);
  }
  e.velocity << ism(1), ism(3);
  e.velocity_cov << P_ism(1, 1), P_ism(1, 3), P_ism(3, 1), P_ism(3, 3);
  e.yaw_rate = ism(5);
  e.yaw_rate_var = P_ism(5, 5);
  if (h.kind == ModelKind::kVasm) {
    double dtheta_c = 0.0;
    VasmModel::CentreVelocity(h.x, &dtheta_c, &e.speed);  // Eq. (7)
    e.velocity_heading = WrapToPi(h.x(4) + dtheta_c);
    e.rear_axle_offset = h.x(2);
    e.rear_axle_offset_var = h.P(2, 2);
  } else {
    e.speed = e.velocity.norm();
    e.velocity_heading =
        e.speed > 0.0 ? std::atan2(e.velocity.y(), e.velocity.x()) : WrapToPi(h.x(4));
    e.rear_axle_offset = std::numeric_limits<double>::quiet_NaN();
    e.rear_axle_offset_var = std::numeric_limits<double>::quiet_NaN();
  }
  return e;
}

std::vector<PredictedPose> Ekf::PredictTrajectory(const Hypothesis& h, double horizon_s,
                                                  double step_s, double noise_scale) const {
  if (!std::isfinite(step_s) || step_s <= 0.0) {
    ThrowInvalid("PredictTrajectory: step_s [s] must be finite and > 0, got step_s", step_s);
  }
  if (!std::isfinite(horizon_s) || horizon_s < 0.0 || horizon_s / step_s > 10000.0) {
    ThrowInvalid(
        "PredictTrajectory: horizon_s [s] must be finite, >= 0 and at most 10000 steps, got "
        "horizon_s",
        horizon_s);
  }
  const int n = static_cast<int>(std::floor(horizon_s / step_s + 1e-9)) + 1;
  const MotionModel& mm = model(h.kind);
  const std::array<int, 3> idx = mm.PoseIndices();
  std::vector<PredictedPose> out;
  out.reserve(n);
  Hypothesis p = h;
  for (int k = 0; k < n; ++k) {
    if (k > 0) EkfPredict(mm, step_s, noise_scale, &p);
    PredictedPose s;
    s.t = k * step_s;
    s.pose << p.x(idx[0]), p.x(idx[1]), p.x(idx[2]);
    // Largest eigenvalue of the symmetric 2x2 position covariance, in closed form.
    const double a = p.P(idx[0], idx[0]), b = p.P(idx[0], idx[1]), c = p.P(idx[1], idx[1]);
    const double lambda = 0.5 * (a + c) + std::hypot(0.5 * (a - c), b);
    s.pos_std = std::sqrt(std::max(0.0, lambda));
    out.push_back(s);
  }
  return out;
}

Hypothesis Ekf::InitIsm(const CentreMeasurement& m) const { return ism_.InitFromMeasurement(m); }

Hypothesis Ekf::Convert(const Hypothesis& h, ModelKind target, double heading_offset) const {
  if (!std::isfinite(heading_offset)) {
    ThrowInvalid("Ekf::Convert: heading_offset [rad] must be finite, got heading_offset",
                 heading_offset);
  }
  if (h.kind == target && heading_offset == 0.0) return h;
  const MotionModel& from = model(h.kind);
  const MotionModel& to = model(target);
  Matrix6d D_ism_x, D_out_ism;
  Vector6d ism = from.ToIsmState(h.x, &D_ism_x);
  ism(4) = WrapToPi(ism(4) + heading_offset);  // Jacobian of the turn: identity
  Hypothesis out;
  out.kind = target;
  out.x = to.FromIsmState(ism, &D_out_ism);
  const Matrix6d D = D_out_ism * D_ism_x;
  out.P = D * h.P * D.transpose() + to.FromIsmPriorCovariance();
  Symmetrise(&out.P);
  return out;
}

}  // namespace vtrack
