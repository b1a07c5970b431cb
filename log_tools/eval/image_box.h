// The 2-D box that a track's 3-D box makes in a camera image (KITTI's camera 2), for the KITTI
// export's bbox column and for the DontCare rule of the scoring (a track whose image box lies
// mostly inside a region KITTI left unlabelled is not a false positive).
#pragma once

#include <Eigen/Geometry>

#include <cstdint>
#include <optional>
#include <string>

#include "log_tools/eval/overlap.h"
#include "vtrack/track_list_t.hpp"
#include "vtrack/track_t.hpp"

namespace vtrack::eval {

// A camera to project into: rect_from_sensor (camera, rectified, from the LADAR), P (image from
// rect, 3x4, pixels) and the image size. A track without a detector's bottom and height
// (track_t.z, height NaN) stands on the road sensor_height_m below the sensor, box_height_m tall.
struct ImageProjection {
  Eigen::Affine3d rect_from_sensor = Eigen::Affine3d::Identity();
  Eigen::Matrix<double, 3, 4> P = Eigen::Matrix<double, 3, 4>::Zero();  // [px]
  int image_width = 1242;           // [px] > 0
  int image_height = 375;           // [px] > 0
  double sensor_height_m = 1.73;    // [m] LADAR above the road (KITTI's Velodyne); > 0
  double box_height_m = 1.6;        // [m] height of a track without one; > 0
  std::string Validate() const;     // "" if valid, else names the key and the value
};

// The KITTI frame of the index-th track list of a log (from 0): its scan_seq (the frame index in
// logs from vtrack-kitti2lcm), or the index where the list has none (scan_seq < 0).
inline std::int64_t KittiFrame(const vtrack::track_list_t& list, std::int64_t index) {
  return list.scan_seq >= 0 ? list.scan_seq : index;
}

// The box of a track in the sensor frame: bottom centre, unit heading in the sensor's xy plane,
// and the height used.
struct SensorBox {
  Eigen::Vector3d bottom = Eigen::Vector3d::Zero();
  Eigen::Vector3d heading = Eigen::Vector3d::UnitX();
  double height = 0.0;
};

// The track's box in the sensor frame, its centre at (x, y) and heading theta (world frame;
// the caller may have advanced them in time), placed by sensor_from_world.
SensorBox TrackBoxInSensor(const vtrack::track_t& tr, double x, double y, double theta,
                           const Eigen::Isometry3d& sensor_from_world, const ImageProjection& cam);

// The image box of the 8 corners of b (length and width from the track), clipped to the image;
// nullopt if a corner lies behind the camera (rect z < 0.1 m) or nothing of it is in the image.
std::optional<ImageBox> ProjectToImage(const SensorBox& b, double length, double width,
                                       const ImageProjection& cam);

}  // namespace vtrack::eval
