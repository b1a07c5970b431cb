// Export of tracks in the KITTI tracking result format, so that external evaluators (the KITTI
// devkit, TrackEval, AB3DMOT's 3-D evaluation) can score them. One line per track and frame:
//   frame track_id type truncated occluded alpha x1 y1 x2 y2 h w l x y z rotation_y score
// in camera 2's rectified frame (x right, y down, z forward):
//  - frame: the scan's seq (the KITTI frame index for logs from vtrack-kitti2lcm);
//  - type "Car" (vtrack classes vehicles, not car/van), truncated and occluded -1 (unknown);
//  - the track's state is advanced by time_offset_s at constant velocity and yaw rate: the KITTI
//    converter stamps a frame's scan half a sweep before the labels' time (kitti_sequence.h);
//  - world -> sensor by the ego pose at that time and the LADAR's mounting (from LADAR_SCAN),
//    sensor -> rect by the calibration (X_rect = R0_rect Tr_velo_to_cam X_velo);
//  - (x, y, z) is the bottom centre: the track's centre at its bottom z (track_t.z, world frame,
//    from a detector's boxes), or where it has none at z = -sensor_height_m in the sensor frame
//    (the road); h = the track's height (track_t.height) or box_height_m, w and l from the track;
//  - rotation_y = atan2(-d_z, d_x) for the heading direction d in rect (so that the KITTI
//    relation yaw_velo = -rotation_y - pi/2 holds), alpha = rotation_y - atan2(x, z);
//  - bbox: the 8 box corners projected with P2, clipped to the image; a track with a corner
//    behind the camera or a box outside the image is not written;
//  - score: the track's score (track_t.score: from a detector's boxes, the recency-weighted mean
//    of their scores; from scans, n / (n + confirm_updates)), which ranks the tracks for the
//    score-threshold sweep of sAMOTA;
//  - which tracks: confirmed vehicles and confirmed tracks a detector's box measured (a box track
//    is a vehicle only from a confident score, while the criterion sweeps the score itself);
//    tentative box tracks in the frames a box measured them (tentative_boxes); coasting ones for
//    coast_frames frames after their last measured frame (all of them with score_coasting).
#pragma once

#include <Eigen/Geometry>

#include <cstdint>
#include <string>

#include "log_tools/eval/evaluator.h"
#include "log_tools/eval/image_box.h"

namespace vtrack::eval {

struct KittiExportParams {
  ImageProjection camera;           // camera 2 (P2) from the calibration, image size, defaults
  double time_offset_s = -1.0;      // [s] state advance; < 0 = half the log's sweep duration
  bool score_coasting = false;      // [-] also write coasting tracks, every frame they coast
  // [-] also write a tentative track in the frames a detector's box measured it: the criterion
  // ranks tracks by score, so a track from a confident first box need not wait for confirmation.
  bool tentative_boxes = true;
  // [frames] >= 0: write a coasting track for this many frames after the last that measured it
  // (its state predicted), as AB3DMOT does for one; longer gaps are left out.
  int coast_frames = 1;
  std::string Validate() const;     // "" if valid, else names the key and the value
};

struct KittiExportStats {
  std::int64_t lines = 0;            // tracks written
  std::int64_t frames = 0;           // track lists read
  std::int64_t outside_image = 0;    // tracks not written: behind the camera or outside the image
  std::int64_t frames_without_pose = 0;
  double time_offset_s = 0.0;        // the advance used
};

// Writes the tracks of `mode` to path. Throws std::runtime_error with the reason (no pose, no
// tracks of that mode, unwritable file).
KittiExportStats ExportKittiTracking(const LogData& data, const std::string& mode,
                                     const KittiExportParams& params, const std::string& path);

}  // namespace vtrack::eval
