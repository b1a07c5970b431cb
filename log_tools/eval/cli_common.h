// Command-line pieces shared by vtrack-eval and vtrack-compare: the evaluation options and their
// translation into EvalParams (and the KITTI calibration, read by sensor_driver/kitti).
#pragma once

#include <boost/program_options.hpp>

#include <optional>
#include <string>
#include <vector>

#include "log_tools/eval/evaluator.h"
#include "log_tools/eval/kitti_export.h"

namespace vtrack::eval {

// Raw option values, bound to boost::program_options.
struct EvalCliOptions {
  std::string mode;
  double gate_m = 2.0;
  double hota_gate_m = 2.0;
  bool score_coasting = false;
  double region_range_m = 0.0;
  double region_fov_deg = 360.0;
  bool region_camera = false;
  std::string horizons = "1,2,3";
  std::string truth_time_offset = "0";
  std::string truth_channel = "GROUND_TRUTH";
  std::string tracks_channel = "TRACKS";
  std::string pose_channel = "EGO_POSE";
  std::string scan_channel = "LADAR_SCAN";
  std::string slice_channel = "LADAR_SLICE";
  std::string kitti_calib;
  std::string kitti_dont_care;      // KITTI label file whose DontCare rows are not scored
  std::string kitti_image_size = "1242x375";
  double kitti_sensor_height_m = 1.73;
  double kitti_box_height_m = 1.6;
  double kitti_time_offset_s = -1.0;
  bool kitti_tentative = true;
  int kitti_coast_frames = 1;
};

// Adds the evaluation options (gate, region, horizons, channels, KITTI calibration) to desc.
void AddEvalOptions(boost::program_options::options_description* desc, EvalCliOptions* o);

// Builds EvalParams (and the KITTI export parameters if a calibration is given). Throws
// std::invalid_argument naming the option and value on a bad value.
EvalParams MakeEvalParams(const EvalCliOptions& o);
std::optional<KittiExportParams> MakeKittiExportParams(const EvalCliOptions& o);

// "1,2,3" -> {1, 2, 3}; throws std::invalid_argument naming the option for a bad element.
std::vector<double> ParseDoubleList(const std::string& option, const std::string& text);

}  // namespace vtrack::eval
