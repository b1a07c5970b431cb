// vtrack-kitti2lcm: converts a KITTI tracking sequence into an LCM log with LADAR_SCAN, EGO_POSE
// and GROUND_TRUTH. See sensor_driver/kitti/README.md.
#include <boost/program_options.hpp>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>

#include "lcmtypes/util/command_line.h"
#include "lcmtypes/util/process.h"
#include "log_tools/kitti2lcm/converter.h"
#include "sensor_driver/kitti/kitti_sequence.h"

namespace po = boost::program_options;

int main(int argc, char** argv) {
  using vtrack::kitti::ConvertOptions;
  using vtrack::kitti::SequenceOptions;
  SequenceOptions seq_opt;
  ConvertOptions conv;
  double pose_rate_hz = 100.0;
  bool quiet = false;

  po::options_description desc(
      "vtrack-kitti2lcm: convert a KITTI tracking sequence to an LCM log\n\n"
      "  vtrack-kitti2lcm --kitti DIR [--sequence NNNN] --out F.lcm [--poses F | --oxts F]\n\n"
      "DIR is the standard KITTI tracking layout (training/ or the folder holding it:\n"
      "velodyne/NNNN/*.bin, label_02/NNNN.txt, calib/NNNN.txt, oxts/NNNN.txt) or a folder\n"
      "with velodyne_NNNN.tar.zst instead of velodyne/ (unpacked once into --cache-dir).\n"
      "Without --poses/--oxts the ego motion is DIR/oxts/NNNN.txt, else\n"
      "DIR/ego_pose_estimated/poses_velo_icp.txt.\n"
      "The boxes layout (no point clouds: label_02/, calib/, detections/pointrcnn_Car/NNNN.txt,\n"
      "ego_pose_orbslam3/NNNN.txt camera-frame poses) gives EGO_POSE, GROUND_TRUTH and\n"
      "DETECTIONS at each frame's time and no LADAR_SCAN. Where detections/pointrcnn_Car/NNNN.txt\n"
      "exists, its boxes are written to DETECTIONS (in the body frame) unless --no-detections.\n\nOptions");
  desc.add_options()
      ("help,h", "print this help")
      ("kitti", po::value<std::string>(&seq_opt.dir)->required(), "KITTI directory")
      ("sequence", po::value<std::string>(&seq_opt.sequence),
       "sequence number (default: the folder's only sequence with point clouds)")
      ("out,o", po::value<std::string>(&conv.out)->required(), "output LCM log file")
      ("poses", po::value<std::string>(&seq_opt.poses_file),
       "ego poses, KITTI odometry layout (3x4 per line, Velodyne frame i -> frame 0)")
      ("oxts", po::value<std::string>(&seq_opt.oxts_file), "ego poses from an OXTS GPS/IMU file")
      ("cache-dir", po::value<std::string>(&seq_opt.cache_dir),
       "where packed point clouds are unpacked (default $XDG_CACHE_HOME/vtrack or ~/.cache/vtrack)")
      ("start-utime", po::value<std::int64_t>(&seq_opt.start_utime)->default_value(seq_opt.start_utime),
       "time of frame 0 [us since the Unix epoch]")
      ("first-frame", po::value<int>(&conv.first_frame)->default_value(0), "first frame to convert")
      ("num-frames", po::value<int>(&conv.num_frames)->default_value(-1), "frames to convert (-1 = all)")
      ("pose-rate", po::value<double>(&pose_rate_hz)->default_value(100.0), "EGO_POSE rate [Hz], 10..1000")
      ("no-ground-truth", "do not write GROUND_TRUTH")
      ("no-detections", "do not write DETECTIONS (the detector's boxes, where the folder has them)")
      ("no-scans", po::bool_switch(&seq_opt.no_scans),
       "do not write LADAR_SCAN: the sequence is written as the boxes layout is (GROUND_TRUTH\n"
       "and DETECTIONS at each frame's time), for tracking from the boxes alone")
      ("image-width", po::value<int>(&seq_opt.image_width)->default_value(seq_opt.image_width),
       "camera 2 image width [px], for in_labelled_region")
      ("image-height", po::value<int>(&seq_opt.image_height)->default_value(seq_opt.image_height),
       "camera 2 image height [px]")
      ("moving-threshold", po::value<double>(&seq_opt.moving_threshold_m)->default_value(seq_opt.moving_threshold_m),
       "a labelled track is 'moving' if it leaves a disc of this radius [m] about its mean position")
      ("scan-channel", po::value<std::string>(&conv.scan_channel)->default_value(conv.scan_channel), "")
      ("pose-channel", po::value<std::string>(&conv.pose_channel)->default_value(conv.pose_channel), "")
      ("truth-channel", po::value<std::string>(&conv.truth_channel)->default_value(conv.truth_channel), "")
      ("detections-channel", po::value<std::string>(&conv.detections_channel)->default_value(conv.detections_channel), "")
      ("quiet,q", po::bool_switch(&quiet), "no progress output");

  po::variables_map vm;
  try {
    if (!vtrack::lcm_util::StoreCommandLine(po::parse_command_line(argc, argv, desc), desc, &vm)) {
      return 0;
    }
    vtrack::lcm_util::RefuseOverwritingInputs(
        {{"--poses", seq_opt.poses_file}, {"--oxts", seq_opt.oxts_file}}, {{"--out", conv.out}});
  } catch (const po::error& e) {
    std::cerr << "vtrack-kitti2lcm: " << e.what() << "\n(see vtrack-kitti2lcm --help)\n";
    return 2;
  }
  if (!(pose_rate_hz >= 10.0 && pose_rate_hz <= 1000.0)) {
    std::cerr << "vtrack-kitti2lcm: --pose-rate must be in [10, 1000] Hz, got " << pose_rate_hz << "\n";
    return 2;
  }
  conv.pose_period_us = static_cast<std::int64_t>(1e6 / pose_rate_hz + 0.5);
  conv.ground_truth = vm.count("no-ground-truth") == 0;
  conv.detections = vm.count("no-detections") == 0;
  if (const std::string err = conv.Validate(); !err.empty()) {
    std::cerr << "vtrack-kitti2lcm: bad option: " << err << "\n";
    return 2;
  }
  if (const std::string err = seq_opt.Validate(); !err.empty()) {
    std::cerr << "vtrack-kitti2lcm: bad option: " << err << "\n";
    return 2;
  }
  seq_opt.sink = [quiet](const std::string& msg) {
    if (!quiet) std::cerr << "vtrack-kitti2lcm: " << msg << std::endl;
  };

  // SIGINT/SIGTERM set a flag: an unpack in progress fails cleanly (tar gets the signal too), a
  // conversion stops after the current frame; either way no partial output is left.
  vtrack::lcm_util::InstallStopHandlers();
  try {
    const auto start = std::chrono::steady_clock::now();
    const vtrack::kitti::Sequence seq(seq_opt);
    {
      // The sequence's own files, once found, are inputs too.
      const vtrack::kitti::SequencePaths& p = seq.paths();
      vtrack::lcm_util::RefuseOverwritingInputs(
          {{"the calibration", p.calib_file}, {"the labels", p.label_file}, {"the poses", p.poses_file},
           {"the OXTS file", p.oxts_file}, {"the camera poses", p.camera_poses_file},
           {"the detections", p.detections_file}},
          {{"--out", conv.out}});
    }
    if (!quiet) {
      std::cerr << "vtrack-kitti2lcm: sequence " << seq.sequence() << ": " << seq.num_frames()
                << " frames from "
                << (seq.has_scans() ? seq.paths().velodyne_dir : std::string("(no point clouds)"))
                << ", ego motion from "
                << (!seq.paths().camera_poses_file.empty() ? seq.paths().camera_poses_file
                    : seq.paths().poses_file.empty()       ? seq.paths().oxts_file
                                                           : seq.paths().poses_file)
                << (seq.has_labels() ? ", labels from " + seq.paths().label_file : ", no labels")
                << std::endl;
    }
    auto last_print = std::chrono::steady_clock::now() - std::chrono::hours(1);
    const auto progress = [&](int done, int total, std::int64_t bytes) {
      // Ctrl-C: stop after this frame; the converter removes the partial log.
      if (vtrack::lcm_util::StopRequested()) {
        throw std::runtime_error("interrupted after frame " + std::to_string(done) + " of " +
                                 std::to_string(total) + "; no log written");
      }
      const auto now = std::chrono::steady_clock::now();
      if (quiet || (done != total && now - last_print < std::chrono::seconds(1))) return;
      last_print = now;
      std::fprintf(stderr, "vtrack-kitti2lcm: frame %d/%d (%.0f%%), %.0f MB written\n", done, total,
                   100.0 * done / total, bytes / 1e6);
    };
    const auto stats = vtrack::kitti::ConvertSequence(seq, conv, progress);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("vtrack-kitti2lcm: wrote %s: %d frames, %lld scans (%lld points), %lld poses, "
                "%lld ground-truth lists (%lld objects), %lld detection lists (%lld boxes), "
                "%.1f MB in %.1f s\n",
                conv.out.c_str(), stats.frames, static_cast<long long>(stats.scans),
                static_cast<long long>(stats.points), static_cast<long long>(stats.poses),
                static_cast<long long>(stats.truth_lists), static_cast<long long>(stats.truth_objects),
                static_cast<long long>(stats.detection_lists), static_cast<long long>(stats.detections),
                stats.bytes / 1e6, secs);
  } catch (const std::exception& e) {
    std::cerr << "vtrack-kitti2lcm: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
