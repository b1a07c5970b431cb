// vtrack-compare: the tracker's three modes side by side on scenarios and real data.
//
// For each item, a log with scans, ego pose and ground truth is made once:
//   scenario NAME: vtrack-sim-log --scenario NAME --out <work>/<item>/run.lcm --seed N
//   KITTI DIR:     vtrack-kitti2lcm --kitti DIR --sequence S --out <work>/<item>/run.lcm [--poses F | --oxts F]
//   KITTI boxes DIR, each sequence S: vtrack-kitti2lcm --kitti DIR --sequence S (the boxes layout:
//                  DETECTIONS, EGO_POSE, GROUND_TRUTH), tracked with --input-mode boxes; the
//                  sum over the sequences is a row of its own (CLEAR MOT counts summed)
// then for each mode M:  vtrack-tracker --input run.lcm --output tracks_M.lcm --mode M [--config F]
//                        [--seed N]  (N: the item's seed, passed unless 1, the tracker's default)
// With several seeds, every scenario and every KITTI item measured by scans (input modes scans and
// fused; boxes alone draw nothing at random) is one item per seed (NAME_seedN) followed by a row
// of their CLEAR MOT counts summed (NAME_seeds; HOTA the mean over the seeds): a simulated run is
// one draw of the sensor noise and of the fits' random draws (RANSAC), a run over a real log one
// draw of the latter, and the tracker's discrete decisions (a track confirmed, split or deleted a
// scan earlier) make its scores jump from draw to draw.
// and the tracks are scored with vtrack_eval (a library call, the same code as vtrack-eval).
// KITTI items are scored inside camera 2's view (its labelled region) within kitti_range_m; an
// unmatched track in one of the labels' DontCare regions is not a false positive (the KITTI
// devkit's rule; kitti_dont_care false scores it as one).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "log_tools/eval/cli_common.h"

namespace vtrack::eval {

struct CompareItem {
  // kKittiBoxes: a sequence of a folder in the boxes layout (no point clouds), tracked from
  // its DETECTIONS (vtrack-tracker --input-mode boxes).
  enum class Kind { kScenario, kKitti, kKittiBoxes };
  Kind kind = Kind::kScenario;
  std::string name;      // [-] key in the table and the JSON: scenario name, or kitti_<sequence>
  std::string source;    // [-] scenario NAME or path; KITTI directory
  std::string sequence;  // [-] kKitti, kKittiBoxes: its sequence (NNNN)
  std::string input_mode = "scans";  // [-] kKitti: vtrack-tracker --input-mode (scans | boxes | fused)
  std::int64_t seed = 1;             // [-] simulator seed (kScenario) and vtrack-tracker --seed
  // [-] The summed row this item is part of ("" none): kitti_boxes_sum for the boxes sequences,
  // NAME_seeds for a scenario run with several seeds.
  std::string sum_row;
};

struct CompareOptions {
  std::vector<CompareItem> items;
  std::vector<std::string> modes = {"ism", "vasm", "mht"};
  std::string json_path;              // [-] "" = no JSON
  std::string plots_dir;              // [-] "" = no plots
  std::string work_dir;               // [-] "" = a fresh temporary directory, removed at the end
  bool keep_work = false;             // [-] keep the temporary directory
  bool reuse = false;                 // [-] reuse run.lcm / tracks_M.lcm already in work_dir
  std::string tracker_config;         // [-] passed to vtrack-tracker --config
  std::string bin_dir;                // [-] where the vtrack executables are
  double timeout_s = 3600.0;          // [s] per child process; > 0
  std::string kitti_sequence;  // [-] --kitti-sequence; "" = each folder's only point-cloud sequence
  std::string kitti_poses, kitti_oxts, kitti_calib;  // [-] "" = the converter's / DIR's default
  double kitti_range_m = 40.0;        // [m] KITTI scoring range; > 0
  bool kitti_dont_care = true;        // [-] KITTI: tracks in the labels' DontCare regions are not FP
  double kitti_iou = 0.25;            // [-] --kitti-boxes: 3-D IoU threshold of vtrack-eval-kitti
  EvalCliOptions eval;                // scoring options for the scenarios
  bool quiet = false;
};

// Scenario item from a NAME or path ("urban_intersection", "config/scenarios/x.yaml").
CompareItem ScenarioItem(const std::string& name_or_path);

// An item's runs for seeds (not empty): the item itself with that seed if there is one, else
// one per seed named NAME_seedN, all in the summed row NAME_seeds. Throws std::invalid_argument
// for a repeated seed.
std::vector<CompareItem> SeedItems(const CompareItem& item, const std::vector<std::int64_t>& seeds);

// The sequences of a boxes-layout folder: every DIR/label_02/NNNN.txt that has its
// ego_pose_orbslam3/NNNN.txt, in order. Throws std::invalid_argument if there is none.
std::vector<std::string> BoxesSequences(const std::string& dir);

// Runs everything, prints progress to stderr and the table to stdout. Returns the exit status:
// 0 if every (item, mode) was scored, 1 otherwise. Throws std::invalid_argument for bad options.
int RunCompare(const CompareOptions& options);

}  // namespace vtrack::eval
