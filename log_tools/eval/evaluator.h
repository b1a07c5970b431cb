// Scoring of a tracker run against ground truth, from LCM logs (docs/design.md, section 7).
//
// Input: one or more LCM logs (e.g. the simulator's run.lcm and the tracker's tracks.lcm) that
// together hold GROUND_TRUTH (object_list_t), TRACKS (track_list_t) and, for the scoring region
// and the KITTI export, EGO_POSE (pose_t) and one LADAR_SCAN (for the sensor's mounting). Logs are
// merged by message time: a TRACKS message is paired with the GROUND_TRUTH message of the same
// utime (the same scan).
//
// What is scored, per scan (see log_tools/README.md for the full definitions):
//  - truth: objects with in_labelled_region set, a vehicle class (car, van, truck, skid-steer),
//    and inside the optional scoring region (range and field of view around the ego vehicle);
//    every other truth object is "ignored";
//  - tracks: status confirmed (and coasting if score_coasting) and class vehicle. Tracks of other
//    objects (track_t.CLASS_OTHER, unknown) are neither scored nor false positives. A vehicle
//    track that one global assignment (centre distance < gate_m) pairs with an ignored truth
//    object is dropped, as is an unpaired track outside the scoring region, or (KITTI) one in a
//    DontCare region: none can be judged.
// Metrics: CLEAR MOT and HOTA (clear_mot.h) on the scored sets; state errors on the CLEAR MOT
// matches:
//  - position: centre distance [m];
//  - heading: the rectangle's orientation, so the track's theta vs the truth yaw is wrapped and
//    folded to (-90, 90] deg: a rectangle flipped by 180 deg is the same rectangle and is not a
//    heading error; how often it happens is reported separately (heading_flip_fraction);
//  - speed: track speed (centre, >= 0) vs |truth centre velocity|;
//  - yaw rate: track yaw_rate vs truth yaw_rate;
//  - rear-axle offset L: track L (sign-corrected when the heading is flipped) vs truth L, only
//    where both are finite and the truth moves faster than moving_speed_mps;
//  - prediction at k s: the track's predicted position at utime + k (linear interpolation of
//    pred_t/pred_x/pred_y) vs the position of the same truth object at that time (linear
//    interpolation between the two ground-truth scans around it, at most max_truth_gap_s
//    apart); only where the log holds ground truth at that time and the prediction reaches k;
//  - NEES: e^T P^-1 e with e = (dx, dy, folded heading error) and P the track's 3x3 covariance;
//    its mean (3 for a consistent filter) and the fraction below the 95 % chi-square(3) bound
//    7.8147 (0.95 for a consistent filter).
#pragma once

#include <Eigen/Geometry>

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "log_tools/eval/clear_mot.h"
#include "log_tools/eval/image_box.h"
#include "base/pose.h"
#include "vtrack/object_list_t.hpp"
#include "vtrack/track_list_t.hpp"

namespace vtrack::eval {

// A camera's horizontal field of view as a scoring region (for KITTI: camera 2, whose view is the
// labelled region). A point is inside if it lies in front of the camera and its image column
// u = (P X)_0 / (P X)_2 is in [0, width). Rows are not tested, so no object height is needed.
struct CameraRegion {
  Eigen::Affine3d rect_from_sensor = Eigen::Affine3d::Identity();  // camera (rectified) from LADAR
  Eigen::Matrix<double, 3, 4> P = Eigen::Matrix<double, 3, 4>::Zero();  // image from rect [px]
  int width = 0;                    // [px] image width; > 0
  double track_z_sensor_m = -1.0;   // [m] height of a track's centre in the sensor frame (tracks
                                    //     carry none); about mid-height of a car under a roof LADAR
  bool Contains(const Eigen::Vector3d& p_sensor) const;
};

// KITTI's DontCare regions: image boxes of camera 2 where KITTI left objects unlabelled (far,
// hidden or crowded cars among them), by KITTI frame (track_list_t.scan_seq). As the KITTI
// devkit does, a track paired with no truth object whose image box lies in one of them by more
// than min_overlap of its own area is not a false positive: it is dropped (needs region_camera
// for the ego pose and the sensor mounting).
struct DontCareRegions {
  ImageProjection camera;
  std::map<std::int64_t, std::vector<ImageBox>> boxes;
  double min_overlap = 0.5;         // [-] in (0, 1]
};

struct EvalParams {
  std::string truth_channel = "GROUND_TRUTH";  // [-] object_list_t channel
  std::string tracks_channel = "TRACKS";       // [-] track_list_t channel
  std::string pose_channel = "EGO_POSE";       // [-] pose_t channel
  std::string scan_channel = "LADAR_SCAN";     // [-] ladar_scan_t channel (sensor mounting only)
  std::string slice_channel = "LADAR_SLICE";   // [-] ladar_slice_t channel (the same, sliced)
  std::string mode;                 // [-] tracker mode to score ("" = the only one in the logs)
  double gate_m = 2.0;              // [m] CLEAR MOT match gate on the centre distance; > 0
  double hota_gate_m = 2.0;         // [m] HOTA similarity S = max(0, 1 - d / hota_gate_m); > 0
  double mostly_tracked_ratio = 0.8;  // [-] see ClearMotParams
  double mostly_lost_ratio = 0.2;     // [-]
  bool score_coasting = false;      // [-] also score coasting tracks (default: confirmed only)
  double region_range_m = 0.0;      // [m] score only within this distance of the ego; 0 = no limit
  double region_fov_deg = 360.0;    // [deg] full angle of the scored sector, centred on the ego
                                    //       vehicle's x axis; 360 = all around; (0, 360]
  std::vector<double> horizons_s = {1.0, 2.0, 3.0};  // [s] prediction horizons; each > 0
  double max_truth_gap_s = 0.5;     // [s] largest ground-truth gap interpolated across; > 0
  // [rad/s] a prediction sample is "turning" if the truth's heading changes by more than this
  // times the horizon between the sample's time and the horizon (its mean |yaw rate| over the
  // horizon, from the truth's headings alone), else "straight"; >= 0
  double turning_yaw_rate = 0.1;
  double moving_speed_mps = 0.5;    // [m/s] truth faster than this counts as moving (L error); >= 0
  double max_pose_gap_s = 0.5;      // [s] ego pose extrapolated at most this far for the region
  std::optional<CameraRegion> region_camera;  // score only inside this camera's view (also)
  std::optional<DontCareRegions> dont_care;    // KITTI's DontCare regions (above)
  // [s] the ground truth of a scan describes the objects at utime + this (KITTI logs: the labels
  // are half a sweep after the scan's utime, sensor_driver/kitti/kitti_sequence.h). Tracks are
  // advanced to that time at constant velocity and yaw rate before they are scored. NaN = half
  // the sweep duration of the log's LADAR_SCAN. Default 0: truth at the scan's utime.
  double truth_time_offset_s = 0.0;

  bool RegionEnabled() const {
    return region_range_m > 0.0 || region_fov_deg < 360.0 || region_camera.has_value();
  }
  std::string Validate() const;     // "" if valid, else names the key and the value
};

// Everything read from the logs that scoring needs.
struct LogData {
  std::vector<std::string> paths;
  std::map<std::int64_t, vtrack::object_list_t> truth;  // by utime
  // Track lists by tracker mode (track_list_t.mode), then by utime.
  std::map<std::string, std::map<std::int64_t, vtrack::track_list_t>> tracks;
  PoseHistory poses{std::int64_t{1} << 60};  // world_from_body over the whole log
  std::optional<Eigen::Isometry3d> body_from_sensor;  // from the first LADAR_SCAN, if any
  std::optional<std::int32_t> sweep_duration_us;       // [us] from the first LADAR_SCAN, if any
  std::map<std::string, std::int64_t> problems;       // counters of skipped input, by reason
  std::vector<std::string> damaged_logs;              // what was skipped of each damaged log
  std::vector<std::pair<std::int64_t, Eigen::Isometry3d>> pose_samples;  // as read, all logs
};

// Reads and merges logs. progress(path, fraction) is called while reading (may be empty).
// Throws std::runtime_error naming the file and the message on unreadable input, and on two
// different messages of one channel (and mode) with the same utime.
LogData LoadLogs(const std::vector<std::string>& paths, const EvalParams& params,
                 const std::function<void(const std::string&, double)>& progress = {});
// Adds one more log to data (as LoadLogs does for each of its paths).
void AddLog(LogData* data, const std::string& path, const EvalParams& params,
            const std::function<void(const std::string&, double)>& progress = {});

// One matched (truth, track) pair of one scan, with its errors.
struct PairSample {
  double t_s = 0.0;                  // [s] since the first scored scan
  std::int64_t utime = 0;
  std::int64_t truth_id = 0, track_id = 0;
  double position_error_m = 0.0;
  double heading_error_deg = 0.0;    // folded to (-90, 90]
  bool heading_flipped = false;
  double speed_error_mps = 0.0;      // track - truth
  double yaw_rate_error_dps = 0.0;   // track - truth
  double rear_axle_error_m = 0.0;    // NaN where not scored
  double nees = 0.0;                 // NaN if the covariance is not positive definite
  std::vector<double> prediction_error_m;  // per horizon; NaN where not available
  bool id_switch = false;
};

// Counts of one scored scan.
struct ScanCounts {
  double t_s = 0.0;
  std::int64_t utime = 0;
  int gt = 0, tp = 0, fp = 0, fn = 0, id_switches = 0;
};

struct TrackRow {
  std::int64_t track_id = 0;
  double first_s = 0.0, last_s = 0.0;  // [s] first and last scored scan
  std::int64_t scans = 0;              // scored scans
  std::int64_t matched = 0;            // scans matched to a truth object
  std::int64_t truth_id = -1;          // truth most often matched; -1 if never
  std::int64_t truth_scans = 0;        // scans matched to that truth
  std::int64_t id_switches = 0;        // switches onto this track
  double position_rmse_m = 0.0, heading_rmse_deg = 0.0, speed_rmse_mps = 0.0,
         yaw_rate_rmse_dps = 0.0, rear_axle_rmse_m = 0.0, nees_mean = 0.0;
  std::vector<double> prediction_error_m;  // mean per horizon
};

struct EvalSummary {
  std::string mode;
  std::vector<std::string> logs;
  EvalParams params;
  ClearMotResult clear;
  HotaResult hota;
  std::int64_t scans = 0;                 // scans scored (truth and tracks present)
  std::int64_t scans_without_tracks = 0;  // ground-truth scans with no TRACKS message
  std::int64_t tracks_without_truth = 0;  // TRACKS messages with no ground truth of their utime
  std::int64_t scored_tracks = 0;         // distinct track ids scored at least once
  std::int64_t ignored_track_detections = 0;  // dropped: paired with an ignored truth object
  std::int64_t outside_region_track_detections = 0;  // dropped: unpaired and outside the region
  std::int64_t dont_care_track_detections = 0;  // dropped: unpaired and in a DontCare region
  double position_rmse_m = 0.0;
  double heading_rmse_deg = 0.0;
  double heading_flip_fraction = 0.0;
  double speed_rmse_mps = 0.0;
  double yaw_rate_rmse_dps = 0.0;
  double rear_axle_rmse_m = 0.0;
  std::int64_t rear_axle_samples = 0;
  std::vector<double> prediction_error_m;         // mean per horizon
  std::vector<std::int64_t> prediction_samples;   // per horizon
  // The same split by the truth's motion over the horizon (EvalParams::turning_yaw_rate).
  std::vector<double> prediction_error_turning_m, prediction_error_straight_m;
  std::vector<std::int64_t> prediction_samples_turning, prediction_samples_straight;
  double nees_mean = 0.0;
  double nees_within_95 = 0.0;
  std::int64_t nees_samples = 0;
  std::int64_t nees_invalid = 0;          // matches whose covariance is not positive definite
  std::vector<PairSample> pairs;
  std::vector<ScanCounts> per_scan;
  std::vector<TrackRow> per_track;
  std::map<std::string, std::int64_t> problems;  // skipped input, by reason (from the logs too)
  double truth_time_offset_s = 0.0;       // [s] the offset applied (see EvalParams)
};

// One (frame, track) row of the labelled set vtrack-eval --track-labels writes: for every track
// (any status, any class) of every scored frame, whether it lies on a vehicle, judged against the
// ground truth with the scoring's own rules (truth time offset, region, gate).
struct TrackLabel {
  std::int64_t utime = 0;     // [us] the track list's utime
  std::int64_t track_id = 0;
  // 1: the nearest truth object within gate_m is a scored vehicle (vehicle class, labelled, in
  // the region); 0: it is of another class (wall, pole, pedestrian, ...) or no truth object is
  // within gate_m; -1 (ignore): the track centre is outside the scoring region, or the nearest
  // truth within gate_m is an unscored vehicle (outside the labelled region or the scoring
  // region) or of CLASS_UNKNOWN, or no truth object is within gate_m and the track lies in a
  // KITTI DontCare region (EvalParams::dont_care).
  int label = 0;
  double range_m = 0.0;       // [m] track centre from the ego position; NaN without an ego pose
  std::int64_t truth_id = -1;      // nearest truth object within gate_m; -1 if none
  int truth_class = -1;            // its object_t.object_class; -1 if none
  double distance_m = 0.0;    // [m] centre distance to the nearest truth object (any distance);
                              //     NaN if the frame holds none
};

// The 95 % quantile of chi-square with 3 degrees of freedom.
inline constexpr double kChi2Dof3Quantile95 = 7.814727903251178;

// Scores the logs' tracks of params.mode. Throws std::runtime_error with a clear message if the
// logs hold no ground truth, no tracks, tracks of several modes with no mode chosen, or no pose
// while a scoring region is requested.
// If labels is given, it receives one TrackLabel per admitted track (finite position and
// heading, first of its id) of every scored frame, in time order; the summary is the same.
EvalSummary Evaluate(const LogData& data, const EvalParams& params,
                     std::vector<TrackLabel>* labels = nullptr);

// The mode that Evaluate scores for these params (throws as Evaluate does).
std::string SelectMode(const LogData& data, const EvalParams& params);

}  // namespace vtrack::eval
