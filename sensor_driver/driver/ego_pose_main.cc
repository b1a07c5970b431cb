// vtrack-ego-pose: publishes EGO_POSE live (100 Hz by default) from a simulated scenario or a
// KITTI poses / OXTS file. Time: realtime.h (shared with vtrack-ladar-driver).
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
  vtrack::sim::AddPoseOptions(&desc);
  desc.add_options()
      ("kitti", po::value<std::string>(), "publish the ego poses of a KITTI tracking sequence in DIR")
      ("sequence", po::value<std::string>()->default_value("0000"), "KITTI sequence number")
      ("poses", po::value<std::string>(), "KITTI: odometry poses file (velo i -> velo 0)")
      ("oxts", po::value<std::string>(), "KITTI: OXTS file instead of poses")
      ("cache-dir", po::value<std::string>(), "KITTI: where packed point clouds are unpacked")
      ("lcm-url", po::value<std::string>()->default_value(""), "LCM URL (default: LCM's own, or $LCM_DEFAULT_URL)")
      ("channel", po::value<std::string>()->default_value("EGO_POSE"), "channel of the poses")
      ("quiet,q", "no progress output");
  vtrack::sim::AddRealtimeOptions(&desc);
  const std::string usage =
      "vtrack-ego-pose: publish the ego vehicle's pose live, from a scenario or KITTI.\n\n"
      "usage: vtrack-ego-pose --scenario NAME [--pose-rate HZ] [--pose-noise-pos M] [--start-utime U]\n"
      "       vtrack-ego-pose --kitti DIR [--sequence N] [--poses F | --oxts F] [--pose-rate HZ]\n"
      "Pairs with vtrack-ladar-driver given the same scenario/KITTI options and --start-utime (or\n"
      "none); the two agree on time through the wall clock (sensor_driver/README.md).";
  po::variables_map vm;
  vtrack::sim::SimCli cli;
  try {
    if (!vtrack::sim::ParseCommandLine(argc, argv, desc, usage, &vm)) return 0;
    cli = vtrack::sim::ReadSimCli(vm);
    if (vm.count("scenario") == vm.count("kitti")) throw po::error("give exactly one of --scenario and --kitti");
    if (vm.count("poses") && vm.count("oxts")) throw po::error("give at most one of --poses and --oxts");
  } catch (const po::error& e) {
    std::fprintf(stderr, "vtrack-ego-pose: %s (see --help)\n", e.what());
    return 2;
  }
  try {
    vtrack::lcm_util::InstallStopHandlers();
    auto lcm = vtrack::lcm_util::OpenLcm(vm["lcm-url"].as<std::string>());
    const std::string channel = vm["channel"].as<std::string>();
    vtrack::sim::RealtimeOptions ro;
    vtrack::sim::ReadRealtimeOptions(vm, cli, &ro);
    ro.name = "vtrack-ego-pose";
    ro.what = "poses";
    ro.late_limit_s = 0.5;
    if (vm.count("quiet")) ro.progress_interval_s = 0.0;

    std::unique_ptr<vtrack::sim::Simulator> sim;
    std::unique_ptr<vtrack::sim::Timeline> timeline;
    if (vm.count("kitti")) {
#ifdef VTRACK_HAVE_KITTI
      const double rate = cli.run.pose_rate_hz.value_or(100.0);
      auto t = std::make_unique<vtrack::sim::KittiPoseTimeline>(vtrack::sim::KittiCliOptions(vm),
                                                                rate, lcm.get(), channel);
      ro.lap_us = t->LapUs();
      std::fprintf(stderr, "vtrack-ego-pose: KITTI sequence %s, %d poses at %.0f Hz per run\n",
                   vm["sequence"].as<std::string>().c_str(), t->Count(), rate);
      timeline = std::move(t);
#else
      throw std::runtime_error("this build has no KITTI reader (sensor_driver/kitti was not built)");
#endif
    } else {
      sim = vtrack::sim::MakeSimulator(cli);
      ro.lap_us = sim->RunDurationUs();
      std::fprintf(stderr,
                   "vtrack-ego-pose: scenario '%s', %.0f Hz, noise %.3f m / %.3f deg, seed %llu\n",
                   sim->scenario().name.c_str(), sim->pose_rate_hz(), sim->pose_noise().position,
                   sim->pose_noise().yaw_deg, static_cast<unsigned long long>(sim->seed()));
      timeline = std::make_unique<vtrack::sim::SimPoseTimeline>(sim.get(), lcm.get(), channel);
    }
    const auto stats = vtrack::sim::RunRealtime(*timeline, ro);
    std::fprintf(stderr, "vtrack-ego-pose: stopped: %lld poses published, %lld skipped\n",
                 static_cast<long long>(stats.published), static_cast<long long>(stats.skipped));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vtrack-ego-pose: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
