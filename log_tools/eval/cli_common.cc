#include "log_tools/eval/cli_common.h"

#include <cstdio>
#include <limits>
#include <stdexcept>

#include "lcmtypes/util/text.h"
#include "sensor_driver/kitti/kitti_io.h"

namespace po = boost::program_options;

namespace vtrack::eval {

void AddEvalOptions(po::options_description* desc, EvalCliOptions* o) {
  desc->add_options()
    ("mode", po::value(&o->mode), "tracker mode whose TRACKS to score (cv, ism, vasm, mht); "
                                  "default: the only one in the logs")
    ("gate", po::value(&o->gate_m)->default_value(o->gate_m),
     "[m] CLEAR MOT match gate on the centre distance")
    ("hota-gate", po::value(&o->hota_gate_m)->default_value(o->hota_gate_m),
     "[m] HOTA similarity S = max(0, 1 - d / hota-gate)")
    ("score-coasting", po::bool_switch(&o->score_coasting),
     "also score coasting tracks (default: confirmed tracks only)")
    ("region-range", po::value(&o->region_range_m)->default_value(o->region_range_m),
     "[m] score only within this distance of the ego vehicle (0 = no limit)")
    ("region-fov", po::value(&o->region_fov_deg)->default_value(o->region_fov_deg),
     "[deg] score only within this full angle about the ego vehicle's heading (360 = all)")
    ("region-camera", po::bool_switch(&o->region_camera),
     "score only inside camera 2's horizontal view (needs --kitti-calib): KITTI's labelled region")
    ("horizons", po::value(&o->horizons)->default_value(o->horizons),
     "[s] prediction horizons, comma separated")
    ("truth-time-offset", po::value(&o->truth_time_offset)->default_value(o->truth_time_offset),
     "[s] the ground truth stamped u describes u + this; tracks are advanced to it before scoring. "
     "'half-sweep' = half the LADAR sweep (KITTI logs)")
    ("truth-channel", po::value(&o->truth_channel)->default_value(o->truth_channel), "ground truth channel")
    ("tracks-channel", po::value(&o->tracks_channel)->default_value(o->tracks_channel), "tracks channel")
    ("pose-channel", po::value(&o->pose_channel)->default_value(o->pose_channel), "ego pose channel")
    ("scan-channel", po::value(&o->scan_channel)->default_value(o->scan_channel),
     "LADAR scan channel (read for the sensor mounting)")
    ("slice-channel", po::value(&o->slice_channel)->default_value(o->slice_channel),
     "LADAR slice channel (the same, for sweeps sent as slices)")
    ("kitti-calib", po::value(&o->kitti_calib), "KITTI calibration file (calib/NNNN.txt) for "
                                                "--region-camera and --kitti-out")
    ("kitti-dontcare", po::value(&o->kitti_dont_care),
     "KITTI label file (label_02/NNNN.txt): an unmatched track whose image box lies more than "
     "half in one of its DontCare regions is not a false positive, as in the KITTI devkit "
     "(needs --region-camera)")
    ("kitti-image-size", po::value(&o->kitti_image_size)->default_value(o->kitti_image_size),
     "[px] camera 2 image size WxH")
    ("kitti-sensor-height", po::value(&o->kitti_sensor_height_m)->default_value(o->kitti_sensor_height_m),
     "[m] LADAR height above the road (bottom of exported boxes of tracks without track_t.z)")
    ("kitti-box-height", po::value(&o->kitti_box_height_m)->default_value(o->kitti_box_height_m, "1.6"),
     "[m] box height written for exported tracks without track_t.height (scans only)")
    ("kitti-tentative", po::value(&o->kitti_tentative)->default_value(o->kitti_tentative),
     "--kitti-out: also write tentative tracks in the frames a detector's box measured them "
     "(0 = confirmed tracks only)")
    ("kitti-coast-frames", po::value(&o->kitti_coast_frames)->default_value(o->kitti_coast_frames),
     "--kitti-out: write a coasting track for this many frames after the last that measured it "
     "(--score-coasting: all)")
    ("kitti-time-offset", po::value(&o->kitti_time_offset_s)->default_value(o->kitti_time_offset_s),
     "[s] advance of exported states (scan time -> label time); < 0 = half the sweep duration");
}

std::vector<double> ParseDoubleList(const std::string& option, const std::string& text) {
  std::string bad;
  const std::optional<std::vector<double>> out =
      lcm_util::ParseNumberList(text, ',', /*finite_only=*/false, &bad);
  if (!out) {
    throw std::invalid_argument("--" + option + ": '" + bad + "' is not a number (in '" + text +
                                "')");
  }
  if (out->empty()) throw std::invalid_argument("--" + option + ": empty list");
  return *out;
}

namespace {

std::pair<int, int> ParseImageSize(const std::string& text) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || x != 'x' || w <= 0 || h <= 0) {
    throw std::invalid_argument("--kitti-image-size: expected WxH with positive integers, got '" +
                                text + "'");
  }
  return {w, h};
}

kitti::Calibration ReadCalib(const std::string& path) {
  try {
    return kitti::ReadCalibration(path);
  } catch (const kitti::KittiError& e) {
    throw std::invalid_argument(std::string("--kitti-calib: ") + e.what());
  }
}

ImageProjection MakeImageProjection(const EvalCliOptions& o, const kitti::Calibration& calib) {
  ImageProjection cam;
  cam.rect_from_sensor = calib.RectFromVelo();
  cam.P = *calib.P[2];
  std::tie(cam.image_width, cam.image_height) = ParseImageSize(o.kitti_image_size);
  cam.sensor_height_m = o.kitti_sensor_height_m;
  cam.box_height_m = o.kitti_box_height_m;
  return cam;
}

}  // namespace

EvalParams MakeEvalParams(const EvalCliOptions& o) {
  EvalParams p;
  p.mode = o.mode;
  p.gate_m = o.gate_m;
  p.hota_gate_m = o.hota_gate_m;
  p.score_coasting = o.score_coasting;
  p.region_range_m = o.region_range_m;
  p.region_fov_deg = o.region_fov_deg;
  p.horizons_s = ParseDoubleList("horizons", o.horizons);
  if (o.truth_time_offset == "half-sweep") {
    p.truth_time_offset_s = std::numeric_limits<double>::quiet_NaN();
  } else {
    const auto v = ParseDoubleList("truth-time-offset", o.truth_time_offset);
    if (v.size() != 1) {
      throw std::invalid_argument("--truth-time-offset: one number or 'half-sweep', got '" +
                                  o.truth_time_offset + "'");
    }
    p.truth_time_offset_s = v[0];
  }
  p.truth_channel = o.truth_channel;
  p.tracks_channel = o.tracks_channel;
  p.pose_channel = o.pose_channel;
  p.scan_channel = o.scan_channel;
  p.slice_channel = o.slice_channel;
  if (o.region_camera) {
    if (o.kitti_calib.empty()) {
      throw std::invalid_argument("--region-camera needs --kitti-calib FILE");
    }
    const kitti::Calibration calib = ReadCalib(o.kitti_calib);
    CameraRegion cam;
    cam.rect_from_sensor = calib.RectFromVelo();
    cam.P = *calib.P[2];
    cam.width = ParseImageSize(o.kitti_image_size).first;
    p.region_camera = cam;
    if (!o.kitti_dont_care.empty()) {
      DontCareRegions dc;
      dc.camera = MakeImageProjection(o, calib);
      std::vector<kitti::Label> labels;
      try {
        labels = kitti::ReadLabels(o.kitti_dont_care);
      } catch (const kitti::KittiError& e) {
        throw std::invalid_argument(std::string("--kitti-dontcare: ") + e.what());
      }
      for (const kitti::Label& l : labels) {
        if (!l.IsDontCare()) continue;
        if (!(l.bbox(2) >= l.bbox(0) && l.bbox(3) >= l.bbox(1))) {
          throw std::invalid_argument("--kitti-dontcare: " + o.kitti_dont_care + ":" +
                                      std::to_string(l.line) +
                                      ": DontCare box with x2 < x1 or y2 < y1");
        }
        dc.boxes[l.frame].push_back({l.bbox(0), l.bbox(1), l.bbox(2), l.bbox(3)});
      }
      p.dont_care = std::move(dc);
    }
  } else if (!o.kitti_dont_care.empty()) {
    throw std::invalid_argument("--kitti-dontcare needs --region-camera");
  }
  if (const std::string err = p.Validate(); !err.empty()) {
    throw std::invalid_argument("bad evaluation option: " + err);
  }
  return p;
}

std::optional<KittiExportParams> MakeKittiExportParams(const EvalCliOptions& o) {
  if (o.kitti_calib.empty()) return std::nullopt;
  const kitti::Calibration calib = ReadCalib(o.kitti_calib);
  KittiExportParams k;
  k.camera = MakeImageProjection(o, calib);
  k.time_offset_s = o.kitti_time_offset_s;
  k.score_coasting = o.score_coasting;
  k.tentative_boxes = o.kitti_tentative;
  k.coast_frames = o.kitti_coast_frames;
  if (const std::string err = k.Validate(); !err.empty()) {
    throw std::invalid_argument("bad KITTI export option: " + err);
  }
  return k;
}

}  // namespace vtrack::eval
