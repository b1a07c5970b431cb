// The extended Kalman filter step shared by both motion models (paper Eq. 19), and Ekf, the one
// object through which the tracker holds and processes hypotheses of either model.
//
// Prediction (Eq. 19, first two lines), with the model's nonlinear mean propagation f (ism.h,
// vasm.h) in place of Phi x, and a system-noise scale factor k (the multi-hypothesis manager
// varies it, paper Section 2.5):
//   x- = f(x+, dt),   P- = Phi P+ Phi^T + k Q(x+, dt),   Phi = df/dx at x+.
// Update (Eq. 19, last three lines) with the measurement z = (x, y, theta) of Eq. 14 and its R:
//   nu = z - H x-, with the theta component wrapped to (-pi, pi]: the fitting resolves theta's
//        90/180 deg ambiguity against the prediction (docs/design.md note 6), but the innovation must
//        still be the short way round the circle;
//   S  = H P- H^T + R,   NIS = nu^T S^-1 nu;
//   gate: the update is refused when NIS exceeds the chi-square (3 dof) quantile of the
//        configured gate probability, and the hypothesis is left as predicted;
//   K  = P- H^T S^-1,   x+ = x- + K nu (theta wrapped),
//   P+ = (I - K H) P- (I - K H)^T + K R K^T  (Joseph form, then symmetrised).
// The Joseph form equals Eq. 19's P- - K H P- in exact arithmetic and keeps P+ symmetric positive
// definite in floating point (docs/design.md note 7).
//
// Errors: caller mistakes (negative or non-finite dt, noise scale <= 0, a hypothesis of another
// kind than the model) throw std::invalid_argument naming the value. Bad data (a measurement
// with non-finite values or an R that is not symmetric positive definite, a diverged state) is
// not an exception: the update is refused and UpdateResult says why.
#pragma once

#include <Eigen/Core>

#include <limits>
#include <string>
#include <vector>

#include "tracker/core/cv.h"
#include "tracker/core/ism.h"
#include "tracker/core/motion_model.h"
#include "tracker/core/vasm.h"
#include "tracker/core/parameters.h"

namespace vtrack {

enum class UpdateStatus {
  kAccepted,
  kGated,               // NIS above the gate: the measurement does not fit this hypothesis
  kInvalidMeasurement,  // z or R not finite, or R not symmetric positive definite
  kInvalidState,        // the hypothesis holds non-finite values (diverged)
  kSingularInnovation,  // S = H P H^T + R is not positive definite
};

}  // namespace vtrack

template <>
struct vtrack::EnumNames<vtrack::UpdateStatus> {
  static constexpr std::array kNames{
      "accepted", "gated: NIS above the gate",
      "invalid measurement: z or R not finite, or R not symmetric positive definite",
      "invalid state: hypothesis holds non-finite values",
      "innovation covariance not positive definite"};
};

namespace vtrack {

inline const char* ToString(UpdateStatus status) { return NameOf(status); }

struct UpdateResult {
  bool accepted = false;
  double nis = std::numeric_limits<double>::quiet_NaN();  // [-] NaN where not computed
  double gate = 0.0;                                      // [-] NIS threshold applied
  UpdateStatus reason = UpdateStatus::kInvalidMeasurement;
  Eigen::Vector3d innovation = Eigen::Vector3d::Zero();  // [m, m, rad] nu, theta wrapped
  // [m^2, m rad, rad^2] S = H P- H^T + R, wherever it was computed (also when gated), e.g. for a
  // likelihood score 0.5 (NIS + ln det(2 pi S)); zero where it was not.
  Eigen::Matrix3d innovation_cov = Eigen::Matrix3d::Zero();
};

// Eq. (19) prediction of h by dt >= 0 [s] with the system noise scaled by noise_scale > 0.
void EkfPredict(const MotionModel& model, double dt, double noise_scale, Hypothesis* h);

// Eq. (19) update of h with m, refused if NIS > gate_nis. h is unchanged unless accepted.
UpdateResult EkfUpdate(const MotionModel& model, const CentreMeasurement& m, double gate_nis,
                       Hypothesis* h);

// Chi-square distribution with dof degrees of freedom (1 <= dof <= 1000): the CDF at x >= 0
// and its quantile for p in (0, 1). Closed forms of the regularised incomplete gamma function
// for integer dof; hand-written because vtrack_core depends on Eigen only.
double ChiSquareCdf(double x, int dof);
double ChiSquareQuantile(double p, int dof);

// One sample of a predicted trajectory, for the planner (track_t.pred_*).
struct PredictedPose {
  double t = 0.0;                                   // [s] after the hypothesis' time
  Eigen::Vector3d pose = Eigen::Vector3d::Zero();   // (x [m], y [m], theta [rad]) world frame
  double pos_std = 0.0;  // [m] sqrt of the largest eigenvalue of the (x, y) covariance
};

// Holds the models (ISM, VASM, CV) and the gate; every operation the tracker performs on a hypothesis.
class Ekf {
 public:
  // Throws std::invalid_argument with the Validate() message of the first invalid params.
  explicit Ekf(const IsmParams& ism = IsmParams(), const VasmParams& vasm = VasmParams(),
               const EkfParams& ekf = EkfParams(), const CvParams& cv = CvParams());

  const IsmModel& ism() const { return ism_; }
  const VasmModel& vasm() const { return vasm_; }
  const CvModel& cv() const { return cv_; }
  const MotionModel& model(ModelKind kind) const;
  const EkfParams& params() const { return params_; }
  double gate_nis() const { return gate_nis_; }  // [-] chi-square 3-dof quantile of the gate

  void Predict(double dt, double noise_scale, Hypothesis* h) const;
  UpdateResult Update(const CentreMeasurement& m, Hypothesis* h) const;

  // The centre pose, velocity (Eq. 7 for VASM), yaw rate and L with their covariances.
  CentreEstimate Centre(const Hypothesis& h) const;

  // Poses at t = 0, step, 2 step, ... up to horizon [s] (0..3 s by 0.1 s: 31 samples), predicted
  // in steps of step with the system noise scaled by noise_scale; h is not changed.
  std::vector<PredictedPose> PredictTrajectory(const Hypothesis& h, double horizon_s = 3.0,
                                               double step_s = 0.1,
                                               double noise_scale = 1.0) const;

  // An ISM hypothesis from a first measurement (IsmModel::InitFromMeasurement).
  Hypothesis InitIsm(const CentreMeasurement& m) const;

  // h expressed in the target model, its orientation turned by heading_offset [rad]:
  //  - ISM -> VASM when an object is judged a mover (offset 0), and the second VASM at +90 deg
  //    while a corner leaves the orientation ambiguous (offset pi/2);
  //  - re-seeding a failed hypothesis from the best one (either direction, or same kind).
  // The conversion goes through the ISM state (motion_model.h): centre, yaw rate and the world
  // velocity of the centre are kept, the orientation is turned. An ISM target keeps the whole
  // velocity; a VASM target keeps its component along the (new) heading as v and takes L from
  // its prior, so its velocity across the heading becomes -L theta_dot (Eq. 7). Covariances
  // propagate to first order, P' = D P D^T + the target's prior. Same kind with offset 0 returns
  // h unchanged.
  Hypothesis Convert(const Hypothesis& h, ModelKind target, double heading_offset = 0.0) const;

 private:
  IsmModel ism_;
  VasmModel vasm_;
  CvModel cv_;
  EkfParams params_;
  double gate_nis_;
};

}  // namespace vtrack
