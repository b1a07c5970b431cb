// The tracker: plain structs in (scans, ego poses), plain structs out (track lists, debug,
// counters by reason). No LCM, no files, no clock: the same calls give the same results whether
// the adapter feeds it from the bus or from a log.
//
// Per scan, in order (Process): sequencing (sequencing.h: a scan waits for the poses that cover
// its sweep) -> compensation and ground (preprocess.h) -> segmentation (segmentation.h), then
// joining grazing pieces (grazing_pieces.h) -> association to the tracks predicted to the middle
// of the sweep (association.h) -> per track: its outline (outline.h) and the scan's range profile
// (range_profile.h) -> the track's update (track_manager.h) -> new tracks from what is left, in
// OrderNewObjects' order, a piece of a rectangle created from this scan merged into it -> life
// cycle -> report at the scan's utime (the time of the ground truth and of track_list_t.utime).
//
// A sweep with lost wedges (LadarScan::lost_wedges) is processed with the returns it has; a
// track whose predicted centre lies in a lost wedge gets no miss from it (as a track nobody
// looked at), counted as track_in_lost_wedge; the sweep is counted as sweep_partial.
//
// Bad input is dropped and counted by reason (rejects(); the keys are listed in
// tracker/README.md and docs/reliability.md). A message more than time_jump_reset_us older than the newest one (a
// looped log) resets the tracker: tracks, poses and queue are cleared, ids continue.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "tracker/core/association.h"
#include "tracker/core/ekf.h"
#include "tracker/core/outline.h"
#include "tracker/core/parallel_for.h"
#include "tracker/core/preprocess.h"
#include "tracker/core/range_profile.h"
#include "tracker/core/scan.h"
#include "tracker/core/segmentation.h"
#include "tracker/core/sequencing.h"
#include "tracker/core/track_manager.h"
#include "tracker/core/parameters.h"

namespace vtrack {

// The tracker's answer to one scan.
struct ScanOutput {
  std::int64_t utime = 0;       // [us] the scan's utime: the time of every reported state
  std::int64_t seq = 0;
  std::vector<TrackReport> tracks;
  // Filled when debug output is on.
  std::int32_t num_segments = 0;
  std::vector<TrackDebug> debug;
  PreprocessStats stats;
  // Filled when evidence recording is on (SetRecordEvidence): every track given returns by the
  // scan, its features and logit (the fitting set of scripts/fit-vehicle-evidence).
  struct EvidenceRow {
    std::int64_t track_id = 0;
    bool three_d = false;
    EvidenceFeatures features{};
    double logit = 0.0;       // [-] the scan's
    double log_odds = 0.0;    // [-] the track's, after it
  };
  std::vector<EvidenceRow> evidence;
  // Where the scan's time went, by the clock of Tracker::SetStageClock (all 0 without one):
  // the stages of the pipeline in their order (docs/design.md, section 4), each run to its end
  // on whichever threads it uses.
  struct StageSeconds {
    double preprocess = 0.0;    // [s] compensation, ground
    double segment = 0.0;       // [s] segmentation and grazing pieces, beside the range profile
                                //     and the tracks' prediction to mid-sweep
    double associate = 0.0;     // [s] association
    double update = 0.0;        // [s] every track's update (outline, fit, filters, hypotheses,
                                //     evidence)
    double create = 0.0;        // [s] new tracks
    double life_cycle = 0.0;    // [s] life cycle and report
  };
  StageSeconds stages;
};

// A first track id larger than every id of a tracker started earlier (for a process that may be
// restarted): the start time in milliseconds times 100000, plus 1 (a tracker would have to
// create 100000 tracks per millisecond it ran to reach the next start's range). 1 for times at
// or before the epoch.
std::int64_t FirstTrackIdAt(std::int64_t wall_utime);

class Tracker {
 public:
  // Throws std::invalid_argument naming the first invalid parameter.
  explicit Tracker(const TrackerParams& params, bool debug = false);

  // Whether trackers made from now on in this process may pin their threads to CPUs
  // (compute.pin_threads; off until allowed). Where threads run is the process's to decide:
  // vtrack-tracker allows it when it runs live; a program that builds a Tracker itself (a test,
  // a benchmark, an application with threads of its own) keeps its threads where they are unless
  // it allows it too.
  static void AllowThreadPinning(bool allow);

  // Each may process queued scans; their outputs are appended to *out in scan order.
  void AddPose(const EgoPose& pose, std::vector<ScanOutput>* out);
  void AddScan(LadarScan&& scan, std::vector<ScanOutput>* out);
  // A detector's boxes (used in the input modes boxes and fused, ignored with scans only).
  void AddDetections(DetectionList&& list, std::vector<ScanOutput>* out);
  void Flush(std::vector<ScanOutput>* out);
  // The latest scan the tracker is done with, its arrays to decode the next one into
  // (ScanSequencer::TakeSpare).
  LadarScan TakeSpareScan() { return sequencer_.TakeSpare(); }

  // Counters since construction.
  std::int64_t scans_received() const { return sequencer_.scans_received(); }
  std::int64_t scans_processed() const { return sequencer_.scans_processed(); }
  std::int64_t returns_processed() const { return returns_processed_; }  // in processed scans
  std::int64_t scans_dropped() const { return sequencer_.scans_dropped(); }
  std::int64_t poses_received() const { return sequencer_.poses_received(); }
  std::int64_t resets() const { return sequencer_.resets(); }
  const std::map<std::string, std::int64_t>& rejects() const { return rejects_.counts(); }
  std::int64_t latest_utime() const { return sequencer_.latest_utime(); }  // newest message time
  std::size_t queued_scans() const { return sequencer_.queued_scans(); }
  // Events since the last call (for rate-limited warnings).
  std::vector<TrackerEvent> TakeEvents() { return rejects_.TakeEvents(); }

  // A clock [s] (any origin; a process's CPU time, say) read at the stages' ends to fill
  // ScanOutput::stages; none (the default, or an empty function): nothing is measured. The
  // library itself reads no clock: its decisions depend on message time only.
  void SetStageClock(std::function<double()> seconds) { stage_clock_ = std::move(seconds); }

  // Records every scan's vehicle-evidence features in ScanOutput::evidence.
  void SetRecordEvidence(bool on) { record_evidence_ = on; }

  // The id of the next track (see TrackManager::SetNextId). Throws std::invalid_argument if < 1.
  void SetFirstTrackId(std::int64_t id);

  // The seed of the fits' random draws (RANSAC), default 1. Runs with one seed are identical;
  // another seed is another draw of the same data (vtrack-compare --seeds on a real log).
  void SetSeed(std::int64_t seed) { seed_ = seed; }

  const TrackManager& manager() const { return *manager_; }
  const TrackerParams& params() const { return params_; }

 private:
  // Processes the queued scans that are ready (flush: all of them).
  void ProcessReady(bool flush, std::vector<ScanOutput>* out);
  // The per-scan pipeline; false if the scan could not be placed in the world.
  bool Process(const LadarScan& scan, bool extrapolate, ScanOutput* out);
  // A detector's boxes: association by centre distance, box updates, new tracks; with boxes
  // only also the life cycle and the report. False if no pose places them.
  bool ProcessDetections(const DetectionList& list, bool extrapolate, ScanOutput* out);
  // Compensation and ground; false (counted) if no pose covers the sweep.
  bool Preprocess(const LadarScan& scan, bool extrapolate, PreprocessResult* pre);
  // Marks in unobserved_ the tracks whose centre predicted to mid-sweep (predicted_) lies in a
  // lost wedge of the sweep, seen from the sensor at mid-sweep; counts them and the sweep.
  void MarkUnobserved(const LadarScan& scan, bool extrapolate);
  // The scan's range profile (profile_) from the returns of points_, before the lost wedges are
  // marked in it (UpdateTracks).
  void BuildProfile(const LadarScan& scan, const Eigen::Vector2d& sensor_xy);
  // Updates every track with its returns (a miss if none, unless it was not observed).
  void UpdateTracks(const LadarScan& scan, const Eigen::Vector2d& sensor_xy, ScanOutput* out);
  // New tracks from the objects association left over.
  void CreateTracks(const LadarScan& scan, const Eigen::Vector2d& sensor_xy, ScanOutput* out);
  // The segment of every return and each segment's extent (for the vehicle evidence).
  void IndexSegments();
  // What one thread of UpdateTracks and CreateTracks works with.
  struct Worker {
    Worker(const OutlineParams& outline_params, TrackMeasurer m)
        : outline(outline_params), measurer(std::move(m)) {}
    OutlineExtractor outline;
    PointSet point_set;
    TrackMeasurer measurer;
    std::vector<float> evidence_scratch;
    std::vector<RingReturn> roughness_scratch;
  };
  // What the update of one track adds to the scan's output (kept per track so that the
  // output's order does not depend on the threads).
  struct TrackUpdateOutput {
    bool has_debug = false, has_evidence = false;
    TrackDebug debug;
    ScanOutput::EvidenceRow evidence;
  };
  // Updates track j with its returns of this scan (or misses it) on worker w.
  void UpdateTrack(std::size_t j, const LadarScan& scan, const Eigen::Vector2d& sensor_xy,
                   bool multi_ring, Worker* w, TrackUpdateOutput* out);
  // The vehicle evidence of track index from its returns idx on this scan; the row in *row if
  // evidence recording is on (true then).
  bool ObserveEvidence(std::size_t index, const std::vector<std::int32_t>& idx,
                       const Eigen::Vector2d& sensor_xy, bool three_d, Worker* w,
                       ScanOutput::EvidenceRow* row);
  // The two halves of ObserveEvidence: the features of returns idx (reads the scan only, on
  // worker w), and their logit added to track index's log-odds.
  ReturnEvidence MeasureEvidence(const std::vector<std::int32_t>& idx,
                                 const Eigen::Vector2d& sensor_xy, bool three_d, Worker* w) const;
  bool ApplyEvidence(std::size_t index, const ReturnEvidence& r, bool three_d,
                     ScanOutput::EvidenceRow* row);
  // A new object of the scan, measured (CreateTracks).
  struct NewObject {
    bool measured = false;
    TrackManager::NewTrack track;
    ReturnEvidence evidence;
  };

  TrackerParams params_;
  bool debug_;
  RejectCounter rejects_;
  ScanSequencer sequencer_;
  std::unique_ptr<Ekf> ekf_;
  std::unique_ptr<TrackManager> manager_;
  // compute.threads threads for the loops of a scan (the updates, the preprocessing), started
  // once.
  std::unique_ptr<WorkerPool> pool_;
  Preprocessor preprocessor_;
  Segmenter segmenter_;
  Associator associator_;
  CreatedRectangles created_;
  std::vector<Worker> workers_;  // compute.threads of them

  // Scratch reused from scan to scan.
  WorldPoints points_;
  Segments segments_;
  std::vector<PredictedObject> predicted_;
  AssociationResult association_;
  std::vector<TrackUpdateOutput> update_out_;  // per track of the scan being processed
  std::vector<NewObject> new_objects_;         // per new object of the scan being processed
  RangeProfile profile_;  // nearest return per bearing of the scan being processed
  std::vector<char> unobserved_;  // per track: in a lost wedge of the scan being processed
  std::vector<AzimuthWedge> lost_world_;  // the scan's lost wedges as world bearings [rad]
  std::vector<std::int32_t> segment_of_;  // per return of points_: its segment, or -1
  std::vector<float> segment_extent_;     // [m] per segment: bounding-box diagonal
  int top_ring_ = -1;                     // TopRing of the scan being processed
  bool record_evidence_ = false;
  // Whether the single-plane (0) and 3-D (1) evidence models use hidden_ends (roughness,
  // column_top): only then (or when recording) are a track's ends looked up in the profile (its
  // returns ordered along their rings, their columns' tops gathered). Set once from the
  // parameters.
  bool hidden_ends_used_[2] = {false, false};
  bool roughness_used_[2] = {false, false};
  bool column_top_used_[2] = {false, false};
  std::int64_t returns_processed_ = 0;
  std::int64_t seed_ = 1;  // SetSeed
  std::function<double()> stage_clock_;  // SetStageClock
};

}  // namespace vtrack
