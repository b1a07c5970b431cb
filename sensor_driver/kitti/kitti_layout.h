// Where the files of one KITTI tracking sequence are, in either layout that vtrack reads:
//
//  standard (the KITTI tracking download; DIR may be the folder holding training/ or training/):
//    DIR/velodyne/NNNN/000000.bin ...   DIR/label_02/NNNN.txt   DIR/calib/NNNN.txt
//    DIR/oxts/NNNN.txt
//  boxes (../shared/data/kitti_tracking_boxes): no point clouds; label_02/, calib/,
//    detections/pointrcnn_Car/NNNN.txt and ego_pose_orbslam3/NNNN.txt (camera-frame poses).
//  packed (../shared/data/kitti_tracking_0000): as above, but the point clouds are one archive
//    DIR/velodyne_NNNN.tar.zst (+ .sha256), unpacked once into a cache directory, and the ego
//    motion is DIR/ego_pose_estimated/poses_velo_icp.txt (KITTI odometry poses layout).
//
// The cache: <cache_dir>/kitti/<archive name>-<first 16 hex digits of its SHA-256>/velodyne/NNNN.
// It is filled by `tar --zstd` into a temporary folder that is renamed into place when complete,
// so a crash never leaves a half-unpacked cache and concurrent users (parallel tests) are safe.
// The archive is checked against its .sha256 before unpacking when that file is present.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace vtrack::kitti {

// Progress and information messages ("unpacking ... into ..."). nullptr = print to stderr.
using MessageSink = std::function<void(const std::string&)>;

struct SequencePaths {
  std::string root;           // the folder holding velodyne/ (or the archive), label_02/, calib/
  std::string velodyne_dir;   // folder of 000000.bin ... (after unpacking, if packed); "" in
                              //     the boxes layout
  std::string calib_file;
  std::string label_file;     // "" if the sequence has no labels (test split)
  std::string poses_file;     // KITTI odometry layout poses (exactly one of poses/oxts/camera
  std::string oxts_file;      //     poses is set)
  std::string camera_poses_file;  // boxes layout: rect frame i -> rect frame 0 (odometry layout)
  std::string detections_file;    // detections/pointrcnn_Car/NNNN.txt; "" if absent
  bool packed = false;        // velodyne came from an archive
};

// The default cache root: $XDG_CACHE_HOME/vtrack, else $HOME/.cache/vtrack, else
// <temp dir>/vtrack-cache.
std::string DefaultCacheDir();

// Resolves the files of a sequence (NNNN, e.g. "0000"). poses_file / oxts_file: an explicit ego
// motion source (at most one); when both are empty the first that exists of DIR/oxts/NNNN.txt,
// DIR/ego_pose_estimated/poses_velo_icp.txt is used. cache_dir "" = DefaultCacheDir().
// Throws KittiError with what is missing and where it looked.
SequencePaths LocateSequence(const std::string& dir, const std::string& sequence,
                             const std::string& poses_file, const std::string& oxts_file,
                             const std::string& cache_dir, const MessageSink& sink);

// Unpacks <archive> (a .tar.zst holding velodyne/NNNN/*.bin) into the cache unless it is there
// already; returns the velodyne/NNNN folder. Verifies the archive against <archive>.sha256 when
// that file exists (and refuses a mismatch).
std::string UnpackVelodyneArchive(const std::string& archive, const std::string& sequence,
                                  const std::string& cache_dir, const MessageSink& sink);

// The sequences of DIR (or DIR/training) that have point clouds: every velodyne/NNNN/ folder and
// velodyne_NNNN.tar.zst archive, sorted, each once. Empty if DIR holds none.
std::vector<std::string> PointCloudSequences(const std::string& dir);

// The sequence to read from DIR: `requested` normalised if it is not empty, else the folder's
// only point-cloud sequence (PointCloudSequences; where there are none, its only calib/NNNN.txt), so that any folder of the same layout (e.g. a
// held-out kitti_tracking_NNNN) is read without naming its number. Throws KittiError if it is
// empty and DIR holds no such sequence or several (naming them).
std::string ResolveSequence(const std::string& dir, const std::string& requested);

// Normalises a sequence name: "0", "00", "0000" -> "0000". Throws KittiError for anything that is
// not 1-4 decimal digits.
std::string NormaliseSequence(const std::string& sequence);

}  // namespace vtrack::kitti
