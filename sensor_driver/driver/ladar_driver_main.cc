// vtrack-ladar-driver: publishes LADAR_SCAN and GROUND_TRUTH live, from a simulated scenario or
// a replayed KITTI tracking sequence. Time: realtime.h (shared with vtrack-ego-pose).
#include <boost/program_options.hpp>

#include <cstdio>
#include <memory>

#include "lcmtypes/util/process.h"
#include "sensor_driver/driver/realtime.h"
#include "sensor_driver/driver/sim_cli.h"
#include "sensor_driver/driver/timelines.h"
#ifdef VTRACK_HAVE_KITTI
#include "sensor_driver/driver/kitti_timelines.h"
#endif

namespace po = boost::program_options;

int main(int argc, char** argv) {
  po::options_description desc("Options");
  desc.add_options()("help,h", "print this help and exit");
  vtrack::sim::AddScenarioOptions(&desc, /*start_utime_is_live=*/true);
  vtrack::sim::AddSensorOptions(&desc);
  desc.add_options()
      ("kitti", po::value<std::string>(), "replay a KITTI tracking sequence from DIR instead of a scenario")
      ("sequence", po::value<std::string>()->default_value("0000"), "KITTI sequence number")
      ("poses", po::value<std::string>(), "KITTI: odometry poses file (velo i -> velo 0)")
      ("oxts", po::value<std::string>(), "KITTI: OXTS file instead of poses")
      ("cache-dir", po::value<std::string>(), "KITTI: where packed point clouds are unpacked")
      ("lcm-url", po::value<std::string>()->default_value(""), "LCM URL (default: LCM's own, or $LCM_DEFAULT_URL)")
      ("scan-channel", po::value<std::string>()->default_value("LADAR_SCAN"), "channel of the scans")
      ("truth-channel", po::value<std::string>()->default_value("GROUND_TRUTH"), "channel of the ground truth")
      ("no-truth", "do not publish ground truth")
      ("quiet,q", "no progress output");
  vtrack::sim::AddRealtimeOptions(&desc);
  const std::string usage =
      "vtrack-ladar-driver: publish LADAR scans and ground truth live, from a scenario or KITTI.\n\n"
      "usage: vtrack-ladar-driver --scenario NAME [--sensor S] [--seed N] [--start-utime U]\n"
      "       vtrack-ladar-driver --kitti DIR [--sequence N] [--poses F | --oxts F]\n"
      "Run vtrack-ego-pose with the same scenario/KITTI options and --start-utime (or none) for\n"
      "the matching EGO_POSE; the two agree on time through the wall clock (sensor_driver/README.md).";
  po::variables_map vm;
  vtrack::sim::SimCli cli;
  try {
    if (!vtrack::sim::ParseCommandLine(argc, argv, desc, usage, &vm)) return 0;
    cli = vtrack::sim::ReadSimCli(vm);
    if (vm.count("scenario") == vm.count("kitti")) throw po::error("give exactly one of --scenario and --kitti");
    if (vm.count("poses") && vm.count("oxts")) throw po::error("give at most one of --poses and --oxts");
  } catch (const po::error& e) {
    std::fprintf(stderr, "vtrack-ladar-driver: %s (see --help)\n", e.what());
    return 2;
  }
  try {
    vtrack::lcm_util::InstallStopHandlers();
    auto lcm = vtrack::lcm_util::OpenLcm(vm["lcm-url"].as<std::string>());
    const std::string scan_channel = vm["scan-channel"].as<std::string>();
    const std::string truth_channel = vm.count("no-truth") ? "" : vm["truth-channel"].as<std::string>();
    vtrack::sim::RealtimeOptions ro;
    vtrack::sim::ReadRealtimeOptions(vm, cli, &ro);
    ro.name = "vtrack-ladar-driver";
    ro.what = "scans";
    if (vm.count("quiet")) ro.progress_interval_s = 0.0;

    std::unique_ptr<vtrack::sim::Simulator> sim;
    std::unique_ptr<vtrack::sim::Timeline> timeline;
    if (vm.count("kitti")) {
#ifdef VTRACK_HAVE_KITTI
      auto t = std::make_unique<vtrack::sim::KittiScanTimeline>(
          vtrack::sim::KittiCliOptions(vm), lcm.get(), scan_channel, truth_channel);
      ro.lap_us = t->LapUs();
      ro.late_limit_s = 0.5;
      std::fprintf(stderr, "vtrack-ladar-driver: KITTI sequence %s, %d frames\n",
                   vm["sequence"].as<std::string>().c_str(), t->Count());
      timeline = std::move(t);
#else
      throw std::runtime_error("this build has no KITTI reader (sensor_driver/kitti was not built)");
#endif
    } else {
      sim = vtrack::sim::MakeSimulator(cli);
      ro.lap_us = sim->RunDurationUs();
      ro.late_limit_s = 0.5;
      std::fprintf(stderr,
                   "vtrack-ladar-driver: scenario '%s', sensor '%s' (%d layers, %.1f Hz, %d "
                   "columns), seed %llu, %d scans per run\n",
                   sim->scenario().name.c_str(), sim->sensor().name.c_str(),
                   sim->sensor().NumLayers(), sim->sensor().rate_hz, sim->sensor().NumColumns(),
                   static_cast<unsigned long long>(sim->seed()), sim->NumScans());
      timeline = std::make_unique<vtrack::sim::SimScanTimeline>(sim.get(), lcm.get(), scan_channel,
                                                                truth_channel);
    }
    const auto stats = vtrack::sim::RunRealtime(*timeline, ro);
    std::fprintf(stderr, "vtrack-ladar-driver: stopped: %lld scans published, %lld skipped\n",
                 static_cast<long long>(stats.published), static_cast<long long>(stats.skipped));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vtrack-ladar-driver: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
