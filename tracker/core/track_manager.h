// Tracks and their hypotheses: the paper's multi-hypothesis manager (Section 2.5) and the track
// life cycle. Decisions the paper leaves open are fixed here (docs/design.md, section 4.13); each
// is a parameter of TrackManagerParams.
//
// Hypotheses. Every object starts with one hypothesis: an ISM (modes mht and ism) or a VASM
// (mode vasm). In mode mht an object judged a mover gains VASM hypotheses, up to
// max_hypotheses per object (paper: four), each with its own required fraction of points inside
// the vehicle boundary (FitRequest::min_inside_fraction) and system-noise scale (Ekf::Predict):
//   slot 0  ISM   inside_fraction = ism_inside_fraction, noise 1
//   slot 1  VASM  vasm_variants[0]          (nominal)
//   slot 2  VASM  vasm_variants[1]          (stricter inside fraction), or, while the orientation
//                                            is ambiguous, vasm_variants[0] turned by 90 deg
//   slot 3  VASM  vasm_variants[2]          (larger system noise: trusts measurements more)
// Stationary objects keep exactly one hypothesis.
//
// Mover test. On every scan that updates the object, the centre velocity v (2-vector) and its
// covariance C of the reported hypothesis give d^2 = v^T C^-1 v. The scan is evidence of motion
// if d^2 exceeds the chi-square (2 dof) quantile of mover_confidence and |v| >= mover_min_speed.
// When the fit was a single edge, only the velocity across the edge counts (1 dof): along it the
// centre follows the extent of the returns, which slides as the ego passes a parked car. Centroid
// measurements (small objects) give no evidence. mover_scans consecutive such scans declare a
// mover; a mover stays a mover (a rectangle that grows out of a small object starts over).
//
// Orientation at the mover declaration. A fit gives theta modulo 90 deg (corner) or 180 deg
// (edge); the velocity heading psi tells the length axis of a moving vehicle. With delta the
// angle between psi and the nearest of theta + k 90 deg: the VASMs take the candidate heading
// nearest psi (and the sign that points along psi, so v > 0); if psi lies within
// ambiguity_deg of the diagonal between two candidates (45 deg), the orientation is ambiguous and
// slot 2 holds the other candidate.
//
// Score (lower is better): over the last score_window scans in which the object had points, the
// mean negative log-likelihood of the hypothesis' measurements, 0.5 (NIS + ln det(2 pi S)); a scan
// in which the hypothesis got no accepted update costs 0.5 (gate_nis + ln det(2 pi S_last)), as
// if the measurement had landed on the gate. Unlike the NIS alone, this does not reward a
// hypothesis for inflating its covariance. The reported hypothesis is the best score; it changes
// only when another is better by switch_margin (hysteresis against flicker).
//
// Track score (TrackReport::score, track_t.score): how likely the track is a real vehicle, for
// ranking tracks (the score-threshold sweep of sAMOTA). A track that a detector's box updated or
// started: the recency-weighted mean of those boxes' scores, on the detector's scale (the plain
// mean over the first DetectionParams::score_memory boxes, then each new box weighted
// 1 / score_memory; AB3DMOT takes the plain mean). A track measured by scans only: n / (n +
// confirm_updates) for its n updates, in [0, 1): 0.5 at confirmation. In fused mode a track no
// box ever measured thus ranks below a detected one of positive score.
//
// Failure and re-seeding. A hypothesis that gets no accepted update in fail_misses consecutive
// scans in which the object had points, while the reported one was updated, has failed ("fails to
// fit for a few frames"): it is re-seeded from the reported hypothesis (Ekf::Convert into its own
// model, same heading), keeps its own inside fraction and noise scale, copies the shape, and
// starts with the reported hypothesis' score history.
//
// Restart of a lost still object. An object that is not a mover and has one hypothesis has no
// other to re-seed it from. When that hypothesis has had no accepted update in fail_misses
// consecutive scans with returns, the gate has rejected this scan's measurement, and this scan's
// returns did not move with the hypothesis' velocity (ReturnsMovedWith against the last scan's
// returns, with the whole velocity: unlike the mover test, also its part along a single fitted
// face), the filter has lost an object that its returns still show in place. The typical cause is
// a jump of the fitted centre as the view changes (a single face turning into a corner puts the
// centre half a width or more elsewhere), which the filter's velocity took up in part while the
// gate refused the rest. The hypothesis restarts from the measurement, at rest (Ekf::InitIsm),
// keeping its shape. Returns that moved with the velocity leave it as it is: a moving object is
// not pulled onto a measurement its motion does not explain. A filter at rest cannot tell (zero
// displacement is no evidence of motion): an object that has just started to move, before its
// filter took up the motion, restarts at rest too. Small objects (measured by their centroid,
// never movers) take the same path.
//
// Axis of a stationary object. A fitted face whose both ends are seen (RangeProfile: beyond each
// end, nothing nearer), shorter than vehicle_min_length and not shorter by more than 0.5 m than
// the shape estimate along it (then part of it is unseen) is a front or rear face: the
// heading is turned by 90 deg if it runs along that face, and kept so (a parked row seen from
// behind shows full rear faces and the first metre of each side; the longer-edge rule would
// take the rear face for a side). Otherwise the length axis is the longer side: when the width
// estimate exceeds axis_swap_ratio times the length estimate and vehicle_min_length, the ISM
// heading turns by 90 deg.
//
// Life cycle. tentative -> confirmed after confirm_updates updates; a tentative track missed in
// tentative_max_misses consecutive scans is deleted. A confirmed track is reported confirmed
// on a scan that updates it or gives it returns, and coasting on one that does neither (a
// track in a lost wedge is not missed). The status says whether the object was seen, not
// whether its state moved: returns that update none of its hypotheses (a measurement outside
// the filter's NIS gate, too few returns to fit) still show the object there. It is deleted
// after coast_max_s without an accepted update (a parked object: not a mover,
// slower than mover_min_speed, after parked_coast_max_s: stopped traffic may hide it for longer)
// or when its position std exceeds max_position_std. A parked object missed on the previous scan
// is looked for where it was last measured, in its rectangle grown by the association's
// gate_margin only: it does not move while hidden (Predict). Of two tracks whose rectangles overlap by more than duplicate_overlap of
// the smaller one, one is deleted: a small object inside a vehicle's rectangle, else the one with
// less vehicle evidence (both confirmed or coasting, with some), else the one with fewer updates, else the younger. Ids are never reused within a run.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "tracker/core/association.h"
#include "base/box.h"
#include "tracker/core/classification.h"
#include "tracker/core/detections.h"
#include "tracker/core/ekf.h"
#include "tracker/core/fitting.h"
#include "tracker/core/measurement.h"
#include "tracker/core/range_profile.h"
#include "tracker/core/shape.h"
#include "tracker/core/track.h"
#include "tracker/core/vehicle_evidence.h"
#include "tracker/core/parameters.h"

namespace vtrack {

class TrackManager {
 public:
  // Throws std::invalid_argument naming the first invalid parameter.
  TrackManager(const TrackManagerParams& params, const Ekf& ekf, const FitParams& fit,
               const ShapeParams& shape);

  // Association input: every track's reported hypothesis predicted to utime (not stored).
  void Predict(std::int64_t utime, std::vector<PredictedObject>* out) const;

  // Updates track index with its returns; debug (optional) is filled for the scan's debug.
  // profile (optional, 3-D scans): the scan's nearest range per bearing, for the full-view test
  // of faces and the fits' see-through test of gaps (FitRequest::profile); given, the fits'
  // dimensions are weighted by how well they were seen (ObserveFitDimensions).
  // measurer (optional): the fitter to use (its buffers are scratch); updates of different
  // tracks may run at once on different threads, each with its own (NewMeasurer), and give the
  // same results as one after the other.
  void Update(std::size_t index, const PointSet& points, const Eigen::Vector2d& sensor_xy,
              std::uint64_t seed, TrackDebug* debug, const RangeProfile* profile = nullptr,
              TrackMeasurer* measurer = nullptr);
  // A fitter like the one Update uses by default, for another thread's updates.
  TrackMeasurer NewMeasurer() const { return measurer_; }
  // The reported rectangle of a track at its state time.
  OrientedBox Box(std::size_t index) const;
  // Updates track index with a detector's box (detections.h).
  void UpdateWithBox(std::size_t index, const BoxMeasurement& box, const DetectionParams& dp);
  // A new track from a detector's box.
  bool CreateFromBox(const BoxMeasurement& box, const DetectionParams& dp);
  // Marks a track without returns on this scan.
  void Miss(std::size_t index);
  // A new track from returns that no track claimed. Returns false if they cannot be measured.
  // profile (optional, 3-D scans): as for Update (the see-through test, weighted dimensions).
  bool Create(const PointSet& points, const Eigen::Vector2d& sensor_xy, std::uint64_t seed,
              const RangeProfile* profile = nullptr);
  // Create in two steps, so that the new objects of a scan can be measured at once, each on its
  // own thread: PrepareCreate measures a track from the points and changes nothing (false if
  // they cannot be measured; measurer: as for Update, its buffers scratch), AddCreated adds it
  // with the next id. Create is the two in a row with the manager's own fitter.
  struct NewTrack {
    Track track;
    TrackHypothesis hypothesis;
    std::int64_t utime = 0;
  };
  bool PrepareCreate(const PointSet& points, const Eigen::Vector2d& sensor_xy, std::uint64_t seed,
                     const RangeProfile* profile, TrackMeasurer* measurer, NewTrack* out) const;
  void AddCreated(NewTrack&& t);
  // Life cycle after a scan at utime: confirmation, coasting, deletion, duplicates.
  void EndScan(std::int64_t utime);
  // Every track, its reported hypothesis predicted to utime.
  void Report(std::int64_t utime, std::vector<TrackReport>* out) const;

  void Clear() { tracks_.clear(); }  // ids continue: never reused within a run
  // The id of the next track (>= 1; ids then count up from it). A process that restarts gives
  // a larger one than any id it gave before (the live tracker: from the wall clock).
  void SetNextId(std::int64_t id) { next_id_ = id; }
  // How tracks measured by a detector's boxes are classed (classification.h, Classify): a
  // vehicle from a mean box score of vehicle_box_score on; with needs_box (fused input) a track no
  // box has updated lately is other, whatever its size.
  // The vehicle-evidence model (vehicle_evidence.h); before any call, the defaults.
  void SetEvidence(const EvidenceParams& evidence) {
    evidence_ = evidence;
    evidence_roots_ = EvidenceRoots(evidence_);
  }
  // One scan's returns r of track index, after its update or creation: the features (with the
  // track's state), the scan's logit added to the track's log-odds; the features in *features
  // if not null. Returns the scan's logit.
  double ObserveEvidence(std::size_t index, const ReturnEvidence& r,
                         EvidenceFeatures* features = nullptr);
  void SetBoxClassRule(bool needs_box, double vehicle_box_score) {
    vehicle_needs_box_ = needs_box;
    vehicle_box_score_ = vehicle_box_score;
  }
  const std::vector<Track>& tracks() const { return tracks_; }
  const TrackManagerParams& params() const { return params_; }

 private:
  // The rectangle of t's reported hypothesis placed at state h.
  OrientedBox RectangleOf(const Track& t, const Hypothesis& h) const;
  // A small object whose returns have grown to small_object_grown_extent becomes a rectangle.
  void GrowIntoRectangle(const PointSet& points, const Eigen::Vector2d& sensor_xy,
                         std::uint64_t seed, TrackMeasurer* measurer, Track* t);
  // Measures and updates every hypothesis; true if any accepted its measurement. three_d: as for
  // ObserveShape.
  bool UpdateHypotheses(const PointSet& points, const Eigen::Vector2d& sensor_xy,
                        std::uint64_t seed, std::int64_t utime, bool three_d,
                        TrackMeasurer* measurer, Track* t);
  bool UpdateHypothesis(const Track& t, bool parked, const PointSet& points,
                        const Eigen::Vector2d& sensor_xy, std::uint64_t seed, double time_s,
                        bool three_d, TrackMeasurer* measurer, TrackHypothesis* h);
  // The shape estimate's observations after an accepted update, and on creation. three_d: the
  // returns come from a 3-D scan (a profile was given), whose fits' dimensions are weighted.
  void ObserveShape(bool small, const PointSet& points, double time_s, bool three_d,
                    TrackHypothesis* h) const;
  // The fit's observed length and width (h->fit). On 3-D scans each is weighted by how well its
  // ends were seen (DimensionSampleWeight; a view known to the range noise range_sigma or better
  // weighs 1): a few returns far apart on the side of a car seen at a grazing angle weigh little
  // beside dense views of it, and do not set the length by the longest-peak rule. On
  // single-plane scans every one weighs 1: weighted there, clutter grows lengths that the
  // single-plane evidence model calls vehicles (docs/design.md, note 8).
  void ObserveFitDimensions(double time_s, bool three_d, TrackHypothesis* h) const;
  // The restart of a lost still object (above); returns whether h was restarted from m.
  bool RestartLostStill(const Track& t, const PointSet& points, const CentreMeasurement& m,
                        TrackHypothesis* h) const;
  void ObserveFirstShape(bool small, const PointSet& points, bool three_d,
                         TrackHypothesis* h) const;
  // After the hypotheses' updates at utime (any: one was accepted): counts, the reported
  // hypothesis, re-seeding, the mover test. points: the returns that measured it (nullptr: a
  // detector's box).
  void AfterUpdate(bool any, std::int64_t utime, bool pose_measured, const PointSet* points,
                   Track* t);
  // A new track: its first hypothesis (shape, inside fraction), its filter started from the
  // first measurement with that measurement's score term, and the track added with the next id.
  TrackHypothesis FirstHypothesis() const;
  void StartFilter(const CentreMeasurement& m, TrackHypothesis* h) const;
  void AddTrack(Track t, TrackHypothesis h, std::int64_t utime);
  // The mover test on this scan, and what follows a mover declaration. pose_measured: the
  // update measured the whole pose (a detector's box), not a fit of the returns. With the
  // returns (points), a scan is evidence of motion only if they moved with the velocity since
  // the track's last returns (ReturnsMovedWith; after a single-edge fit, the velocity across the
  // edge). A scan that is no evidence restarts the count, and a mover's ISM is not turned to
  // that scan's velocity.
  void TestMotion(Track* t, bool pose_measured, const PointSet* points) const;
  // The score term and the filter update of one hypothesis with m (nullptr: nothing measured);
  // true if the update was accepted.
  bool ApplyMeasurement(const CentreMeasurement* m, TrackHypothesis* h);
  void ObserveBoxShape(const BoxMeasurement& b, double time_s, TrackHypothesis* h) const;
  bool Parked(const Track& t) const;
  void FillDebug(const Track& t, const PointSet& points, const Eigen::Vector2d& sensor_xy,
                 TrackDebug* debug) const;
  HypothesisReport ReportHypothesis(const Track& t, std::size_t k) const;
  // TrackReport::score (track_manager.h, "Track score").
  double TrackScore(const Track& t) const;

  TrackManagerParams params_;
  const Ekf& ekf_;
  TrackMeasurer measurer_;
  ShapeParams shape_params_;
  // What FirstHypothesis copies: built once, as each new object's shape histograms would be
  // built alike (their bins zeroed, the same smoothing kernel).
  TrackHypothesis first_hypothesis_;
  MoverTest mover_test_;
  std::vector<Track> tracks_;
  std::int64_t next_id_ = 1;
  EvidenceParams evidence_;
  EvidenceRoots evidence_roots_{evidence_};  // of evidence_: declared after it
  bool vehicle_needs_box_ = false;
  double vehicle_box_score_ = -std::numeric_limits<double>::infinity();  // [-] detector's scale
};

}  // namespace vtrack
