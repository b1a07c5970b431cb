// Readers for the files of the KITTI tracking benchmark (and the KITTI odometry poses layout).
//
// Each reader parses one file strictly: a malformed file throws KittiError with a message that
// names the file, the line (1-based) and the offending value, never a crash and never a silent
// guess. Conventions follow the KITTI devkits; frames are named as in docs/design.md:
//   velo  Velodyne HDL-64E frame: x forward, y left, z up (sensor ~1.73 m above the road)
//   cam   camera 0 frame (unrectified): x right, y down, z forward
//   rect  rectified camera frame (the frame of the labels): x right, y down, z forward
//   imu   OXTS RT3003 frame: x forward, y left, z up
#pragma once

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace vtrack::kitti {

// Every error of this library: bad files, missing files, bad options.
class KittiError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One Velodyne sweep as stored in a KITTI .bin file: little-endian float32 (x, y, z, reflectance)
// per return, in the velo frame [m], reflectance in [0, 1]. Parallel arrays, in file order.
struct VelodyneFrame {
  std::vector<float> x, y, z, reflectance;
  std::size_t size() const { return x.size(); }
};

// Reads a .bin file. Throws KittiError naming the file if it cannot be read or its size is not a
// multiple of 16 bytes. Non-finite values are kept as they are (MakeScan marks them).
VelodyneFrame ReadVelodyneBin(const std::string& path);

// Calibration of one sequence (calib/NNNN.txt). Both spellings of the keys are accepted: the
// tracking benchmark's "R_rect", "Tr_velo_cam", "Tr_imu_velo" and the object/raw style
// "R0_rect:", "Tr_velo_to_cam:", "Tr_imu_to_velo:".
struct Calibration {
  // P0..P3: 3x4 projection matrices, image_from_rect of camera k (pixels from rect metres).
  std::array<std::optional<Eigen::Matrix<double, 3, 4>>, 4> P;
  Eigen::Matrix3d R0_rect = Eigen::Matrix3d::Identity();  // rect_from_cam
  Eigen::Affine3d cam_from_velo = Eigen::Affine3d::Identity();  // Tr_velo_to_cam
  std::optional<Eigen::Affine3d> velo_from_imu;  // Tr_imu_to_velo (needed only for OXTS poses)

  // X_rect = R0_rect * Tr_velo_to_cam * X_velo, and its exact inverse (the calibration's 3x3
  // blocks are orthonormal only to ~1e-6, so the general inverse is used, not the transpose).
  Eigen::Affine3d RectFromVelo() const;
  Eigen::Affine3d VeloFromRect() const;
};

// Reads a calibration file. P2, R0_rect and Tr_velo_to_cam are required; the others optional.
Calibration ReadCalibration(const std::string& path);

// One row of label_02/NNNN.txt (the tracking label format):
//   frame track_id type truncated occluded alpha x1 y1 x2 y2 h w l x y z rotation_y [score]
struct Label {
  int frame = 0;            // [-] frame index
  int track_id = -1;        // [-] persistent object id; -1 for DontCare
  std::string type;         // [-] Car, Van, Truck, Pedestrian, Person_sitting, Person, Cyclist, Tram, Misc, DontCare
  double truncated = 0.0;   // [-] 0 (in image) .. 1 (leaving the image)
  int occluded = 0;         // [-] 0 visible, 1 partly, 2 largely occluded, 3 unknown
  double alpha = 0.0;       // [rad] observation angle
  Eigen::Vector4d bbox = Eigen::Vector4d::Zero();  // [px] 2-D box x1 y1 x2 y2 in image 2
  double height = 0.0;      // [m] h
  double width = 0.0;       // [m] w
  double length = 0.0;      // [m] l
  Eigen::Vector3d bottom_center_rect = Eigen::Vector3d::Zero();  // [m] (x, y, z) bottom centre, rect frame
  double rotation_y = 0.0;  // [rad] yaw about the rect frame's y axis (down)
  int line = 0;             // [-] line in the file, for messages

  bool IsDontCare() const { return type == "DontCare"; }
};

// Reads a tracking label file. Every row is checked: 17 or 18 fields, numbers finite, a known
// type, positive dimensions (except DontCare), frame >= 0, track_id >= 0 (-1 only for DontCare).
std::vector<Label> ReadLabels(const std::string& path);

// One row of a detections file (detections/pointrcnn_Car/NNNN.txt, as distributed with the
// AB3DMOT baseline), comma separated: frame,type,x1,y1,x2,y2,score,h,w,l,x,y,z,rot_y,alpha; the
// box in the same rect frame and convention as the labels (type 2 = Car).
struct DetectionRow {
  int frame = 0;            // [-]
  int type = 0;             // [-] 1 Pedestrian, 2 Car, 3 Cyclist (AB3DMOT's numbering)
  double score = 0.0;       // [-] the detector's confidence (PointRCNN: a logit, may be < 0)
  double height = 0.0, width = 0.0, length = 0.0;  // [m] h w l
  Eigen::Vector3d bottom_center_rect = Eigen::Vector3d::Zero();  // [m] rect frame
  double rotation_y = 0.0;  // [rad]
  int line = 0;             // [-]
};

// Reads a detections file; every row checked (15 fields, finite numbers, frame >= 0, positive
// dimensions), a malformed one refused naming the file and line.
std::vector<DetectionRow> ReadDetections(const std::string& path);

// Object class of a label type as object_t::CLASS_*; throws KittiError for an unknown type.
std::int8_t ClassOfType(const std::string& type);

// KITTI odometry poses layout: one row-major 3x4 [R|t] per line, frame i -> frame 0. The rotation
// is checked to be orthonormal within 1e-3 and re-orthonormalised (the file has ~7 digits).
std::vector<Eigen::Isometry3d> ReadPoses(const std::string& path);

// One line of an OXTS file (30 values; the KITTI raw/tracking oxts format).
struct OxtsRecord {
  double lat = 0.0, lon = 0.0, alt = 0.0;       // [deg, deg, m] WGS84
  double roll = 0.0, pitch = 0.0, yaw = 0.0;    // [rad] yaw 0 = east, counter-clockwise positive
  double vn = 0.0, ve = 0.0, vf = 0.0, vl = 0.0, vu = 0.0;  // [m/s]
  double ax = 0.0, ay = 0.0, az = 0.0, af = 0.0, al = 0.0, au = 0.0;  // [m/s^2]
  double wx = 0.0, wy = 0.0, wz = 0.0, wf = 0.0, wl = 0.0, wu = 0.0;  // [rad/s]
  double pos_accuracy = 0.0, vel_accuracy = 0.0;  // [m, m/s]
  int navstat = 0, numsats = 0, posmode = 0, velmode = 0, orimode = 0;
};

// Reads an OXTS file: one record per line (tracking layout oxts/NNNN.txt). Throws KittiError
// naming the file, line and value for a malformed line.
std::vector<OxtsRecord> ReadOxts(const std::string& path);

// The standard KITTI conversion of OXTS records to poses (devkit convertOxtsToPose): position by
// a Mercator projection scaled by cos(latitude of the first record), orientation
// Rz(yaw) Ry(pitch) Rx(roll), all relative to the first record. Returns imu0_from_imu_i.
std::vector<Eigen::Isometry3d> OxtsToImuPoses(const std::vector<OxtsRecord>& records);

// velo0_from_velo_i = velo_from_imu * imu0_from_imu_i * imu_from_velo.
std::vector<Eigen::Isometry3d> ImuPosesToVeloPoses(const std::vector<Eigen::Isometry3d>& imu0_from_imu,
                                                   const Eigen::Affine3d& velo_from_imu);

}  // namespace vtrack::kitti
