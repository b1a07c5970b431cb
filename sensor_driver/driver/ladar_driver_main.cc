// vtrack-ladar-driver: publishes LADAR_SLICE (3-D sweeps, --slices) or LADAR_SCAN and GROUND_TRUTH live, from a simulated scenario or
// a replayed KITTI tracking sequence. Time: realtime.h (shared with vtrack-ego-pose).
#include <boost/program_options.hpp>

#include <cstdio>
#include <memory>
#include <string>

#include "sensor_driver/driver/live_process.h"
#include "sensor_driver/driver/sim_cli.h"
#include "sensor_driver/driver/timelines.h"
#ifdef VTRACK_HAVE_KITTI
#include "sensor_driver/driver/kitti_timelines.h"
#endif

namespace po = boost::program_options;

int main(int argc, char** argv) {
  const char* name = "vtrack-ladar-driver";
  po::options_description desc("Options");
  vtrack::sim::AddLiveSourceOptions(
      &desc, vtrack::sim::AddSensorOptions,
      "replay a KITTI tracking sequence from DIR instead of a scenario");
  vtrack::sim::AddSweepOutputOptions(&desc, /*live=*/true);
  desc.add_options()
      ("truth-channel", po::value<std::string>()->default_value("GROUND_TRUTH"), "channel of the ground truth")
      ("no-truth", "do not publish ground truth")
      ("detections-channel", po::value<std::string>()->default_value("DETECTIONS"),
       "--kitti: channel of the detector's boxes (detections/pointrcnn_Car, where the folder has them)")
      ("no-detections", "--kitti: do not publish the detector's boxes");
  vtrack::sim::AddLiveRunOptions(&desc);
  const std::string usage =
      "vtrack-ladar-driver: publish LADAR scans and ground truth live, from a scenario or KITTI\n"
      "(and, for KITTI, the detector's boxes on DETECTIONS).\n\n"
      "usage: vtrack-ladar-driver --scenario NAME [--sensor S] [--seed N] [--start-utime U]\n"
      "       vtrack-ladar-driver --kitti DIR [--sequence N] [--poses F | --oxts F]\n"
      "Run vtrack-ego-pose with the same scenario/KITTI options and --start-utime (or none) for\n"
      "the matching EGO_POSE; the two agree on time through the wall clock (sensor_driver/README.md).";
  po::variables_map vm;
  vtrack::sim::SimCli cli;
  if (const auto status =
          vtrack::sim::ParseLiveCommandLine(argc, argv, desc, usage, name, &vm, &cli)) {
    return *status;
  }
  vtrack::sim::SweepOutput output;
  try {
    output = vtrack::sim::ReadSweepOutputOptions(vm);
  } catch (const po::error& e) {
    std::fprintf(stderr, "%s: %s (see --help)\n", name, e.what());
    return 2;
  }
  const std::string truth_channel =
      vm.count("no-truth") ? "" : vm["truth-channel"].as<std::string>();
  vtrack::sim::LiveSource source;
#ifdef VTRACK_HAVE_KITTI
  source.kitti = [&](lcm::LCM* lcm) {
    const std::string detections_channel =
        vm.count("no-detections") ? "" : vm["detections-channel"].as<std::string>();
    auto t = std::make_unique<vtrack::sim::KittiScanTimeline>(
        vtrack::sim::KittiCliOptions(vm), lcm, output, truth_channel, detections_channel);
    std::fprintf(stderr, "vtrack-ladar-driver: KITTI sequence %s, %d frames\n",
                 t->Sequence().c_str(), t->Count());
    return t;
  };
#endif
  source.scenario = [&](vtrack::sim::Simulator* sim, lcm::LCM* lcm) {
    std::fprintf(stderr,
                 "vtrack-ladar-driver: scenario '%s', sensor '%s' (%d layers, %.1f Hz, %d "
                 "columns), seed %llu, %d scans per run\n",
                 sim->scenario().name.c_str(), sim->sensor().name.c_str(),
                 sim->sensor().NumLayers(), sim->sensor().rate_hz, sim->sensor().NumColumns(),
                 static_cast<unsigned long long>(sim->seed()), sim->NumScans());
    if (const std::string w =
            vtrack::sim::SweepsLeftOutWarning(*sim, "pose_rate_hz in the scenario", true);
        !w.empty()) {
      std::fprintf(stderr, "vtrack-ladar-driver: %s\n", w.c_str());
    }
    return std::make_unique<vtrack::sim::SimScanTimeline>(sim, lcm, output, truth_channel);
  };
  return vtrack::sim::RunLive(vm, cli, name, "scans", source);
}
