// One KITTI tracking sequence as vtrack messages: scans, ego poses and ground truth. Shared by
// vtrack-kitti2lcm (log_tools/kitti2lcm) and the replay driver's --kitti source.
//
// Frames and times (sensor_driver/kitti/README.md has the long form):
//  - world = the Velodyne frame of frame 0 (x forward, y left, z up, as mounted: level to ~1 deg);
//    body = sensor = the Velodyne frame (the sensor sits at the body origin).
//  - frame i is at FrameUtime(i) = start_utime + i * 100 ms: the moment the scanner faces forward
//    and the camera fires, the time of the labels and of the frame's ego pose. The scan of frame i
//    starts half a sweep earlier, ScanUtime(i) = FrameUtime(i) - sweep/2 (see kitti_scan.h).
//  - ground truth of frame i carries utime = ScanUtime(i) and scan_seq = i (object_list_t's
//    contract: the scan's utime); the labelled states are those at FrameUtime(i), the time at which
//    the scanner swept the labelled (camera) region.
#pragma once

#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <vector>

#include "sensor_driver/kitti/kitti_io.h"
#include "sensor_driver/kitti/kitti_layout.h"
#include "sensor_driver/kitti/kitti_scan.h"
#include "vtrack/detection_list_t.hpp"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/object_list_t.hpp"
#include "vtrack/pose_t.hpp"

namespace vtrack::kitti {

// 2011-09-26 00:00:00 UTC, the day KITTI recorded sequence 0000: a fixed default so that
// conversions are reproducible; the tracking benchmark gives no absolute times.
inline constexpr std::int64_t kDefaultStartUtime = 1'316'995'200'000'000;

struct SequenceOptions {
  std::string dir;                 // [-] KITTI folder, standard or packed layout (kitti_layout.h)
  std::string sequence;            // [-] sequence number, 1-4 digits; "" = the folder's only
                                   //     point-cloud sequence (ResolveSequence)
  std::string poses_file;          // [-] KITTI odometry poses (velo i -> velo 0); "" = default
  std::string oxts_file;           // [-] OXTS file instead of poses; "" = default
  std::int64_t start_utime = kDefaultStartUtime;  // [us since epoch] FrameUtime(0); > sweep/2
  std::string cache_dir;           // [-] where packed point clouds are unpacked; "" = DefaultCacheDir()
  VelodyneParams velodyne;         // sensor timing and size
  int image_width = 1242;          // [px] width of camera 2's image (in_labelled_region); > 0
  int image_height = 375;          // [px] height of camera 2's image; > 0
  double moving_threshold_m = 1.0; // [m] a track is moving if its world position leaves a disc of
                                   //     this radius about its mean position; > 0
  int velocity_half_window = 5;    // [frames] vx, vy, yaw_rate: least-squares slope over the track's
                                   //     labels within +-this many frames; >= 1
  bool no_scans = false;           // [-] leave the point clouds out: the sequence reads as the
                                   //     boxes layout (truth stamped with the frame's time)
  MessageSink sink;                // progress messages; nullptr = stderr

  // Empty if valid, else a message naming the key and its value.
  std::string Validate() const;
};

class Sequence {
 public:
  // Locates and reads the calibration, the ego motion and the labels, and counts the frames.
  // Point clouds are read per frame. Throws KittiError (bad option, missing or malformed file).
  explicit Sequence(SequenceOptions options);

  int num_frames() const { return num_frames_; }
  // False in the boxes layout (no point clouds): no scans; the ground truth is stamped with the
  // frame's time, as the detections are.
  bool has_scans() const { return !paths_.velodyne_dir.empty(); }
  // The detector's boxes of frame i (detections/pointrcnn_Car) in the body (Velodyne) frame at
  // FrameUtime(i), seq = i; empty list if the frame has none. has_detections(): the file exists.
  bool has_detections() const { return !paths_.detections_file.empty(); }
  vtrack::detection_list_t Detections(int i) const;
  const std::string& sequence() const { return sequence_; }
  const SequencePaths& paths() const { return paths_; }
  const Calibration& calibration() const { return calib_; }
  const SequenceOptions& options() const { return options_; }

  std::int64_t FrameUtime(int i) const;  // [us] frame i: labels, camera, ego pose
  std::int64_t ScanUtime(int i) const;   // [us] start of frame i's sweep

  // The point cloud of frame i, as in the file, and as a scan message (utime = ScanUtime(i),
  // seq = i). Throws KittiError for a bad index or file.
  VelodyneFrame ReadFrame(int i) const;
  vtrack::ladar_scan_t Scan(int i) const;
  vtrack::ladar_scan_t Scan(int i, const VelodyneFrame& frame) const;

  // world_from_body at FrameUtime(i).
  const Eigen::Isometry3d& WorldFromBody(int i) const;
  // Ego pose at FrameUtime(i), and at any time in [FirstPoseUtime(), LastPoseUtime()]: between
  // frames linear in position and slerp in rotation (base/pose.h InterpolatePose), beyond
  // the first/last frame (half a sweep) extrapolated at constant velocity. vel, rotation_rate and
  // accel come from central differences of the frame poses, interpolated linearly; accel is the
  // kinematic acceleration of the body origin (no gravity), in the body frame. pos_std and
  // yaw_std are -1 (unknown). Throws KittiError outside that interval.
  vtrack::pose_t EgoPose(int i) const;
  vtrack::pose_t PoseAt(std::int64_t utime) const;
  Eigen::Isometry3d WorldFromBodyAt(std::int64_t utime) const;
  std::int64_t FirstPoseUtime() const { return ScanUtime(0); }
  std::int64_t LastPoseUtime() const { return ScanUtime(num_frames_ - 1) + options_.velodyne.sweep_duration_us; }

  // Labelled objects of frame i in the world frame (DontCare skipped). num_points counts the
  // returns of frame i inside the labelled 3-D box (read from the file, or from `frame`).
  // Without labels (test split) the list is empty.
  bool has_labels() const { return !paths_.label_file.empty(); }
  vtrack::object_list_t GroundTruth(int i) const;
  vtrack::object_list_t GroundTruth(int i, const VelodyneFrame& frame) const;
  // Every label row of the sequence as read (including DontCare).
  const std::vector<Label>& labels() const { return labels_; }

  // The labelled region: a point (velo frame) is inside if it lies in front of camera 2 and
  // projects with P2 into its image_width x image_height image. GroundTruth sets
  // in_labelled_region from the box centre; evaluators can test tracks with the world version.
  bool InLabelledRegionVelo(const Eigen::Vector3d& p_velo) const;
  bool InLabelledRegionWorld(int frame, const Eigen::Vector3d& p_world) const;

 private:
  struct LabelledObject {
    std::size_t label_index = 0;  // into labels_
    vtrack::object_t object;  // num_points = -1 until counted
  };
  void CheckFrame(int i) const;
  void BuildGroundTruth();
  void BuildPoseRates();

  SequenceOptions options_;
  std::string sequence_;
  SequencePaths paths_;
  Calibration calib_;
  int num_frames_ = 0;
  std::vector<Eigen::Isometry3d> world_from_body_;  // per frame
  std::vector<Eigen::Vector3d> vel_world_;           // [m/s] per frame
  std::vector<std::vector<DetectionRow>> detections_;  // per frame
  std::vector<Eigen::Vector3d> rate_body_;           // [rad/s] per frame
  std::vector<Eigen::Vector3d> accel_body_;          // [m/s^2] per frame
  std::vector<Label> labels_;
  std::vector<std::vector<LabelledObject>> objects_;  // per frame
};

}  // namespace vtrack::kitti
