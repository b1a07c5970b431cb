// vtrack-ego-pose: publishes EGO_POSE live (100 Hz by default) from a simulated scenario or a
// KITTI poses / OXTS file. Time: realtime.h (shared with vtrack-ladar-driver).
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
  const char* name = "vtrack-ego-pose";
  po::options_description desc("Options");
  vtrack::sim::AddLiveSourceOptions(&desc, vtrack::sim::AddPoseOptions,
                                    "publish the ego poses of a KITTI tracking sequence in DIR");
  desc.add_options()
      ("channel", po::value<std::string>()->default_value("EGO_POSE"), "channel of the poses");
  vtrack::sim::AddLiveRunOptions(&desc);
  const std::string usage =
      "vtrack-ego-pose: publish the ego vehicle's pose live, from a scenario or KITTI.\n\n"
      "usage: vtrack-ego-pose --scenario NAME [--pose-rate HZ] [--pose-noise-pos M] [--start-utime U]\n"
      "       vtrack-ego-pose --kitti DIR [--sequence N] [--poses F | --oxts F] [--pose-rate HZ]\n"
      "Pairs with vtrack-ladar-driver given the same scenario/KITTI options and --start-utime (or\n"
      "none); the two agree on time through the wall clock (sensor_driver/README.md).";
  po::variables_map vm;
  vtrack::sim::SimCli cli;
  if (const auto status =
          vtrack::sim::ParseLiveCommandLine(argc, argv, desc, usage, name, &vm, &cli)) {
    return *status;
  }
  const std::string channel = vm["channel"].as<std::string>();
  vtrack::sim::LiveSource source;
#ifdef VTRACK_HAVE_KITTI
  source.kitti = [&](lcm::LCM* lcm) {
    const double rate = cli.run.pose_rate_hz.value_or(100.0);
    auto t = std::make_unique<vtrack::sim::KittiPoseTimeline>(vtrack::sim::KittiCliOptions(vm),
                                                              rate, lcm, channel);
    std::fprintf(stderr, "vtrack-ego-pose: KITTI sequence %s, %d poses at %.0f Hz per run\n",
                 t->Sequence().c_str(), t->Count(), rate);
    return t;
  };
#endif
  source.scenario = [&](vtrack::sim::Simulator* sim, lcm::LCM* lcm) {
    std::fprintf(stderr,
                 "vtrack-ego-pose: scenario '%s', %.0f Hz, noise %.3f m / %.3f deg, seed %llu\n",
                 sim->scenario().name.c_str(), sim->pose_rate_hz(), sim->pose_noise().position,
                 sim->pose_noise().yaw_deg, static_cast<unsigned long long>(sim->seed()));
    if (const std::string w = vtrack::sim::SweepsLeftOutWarning(*sim, "--pose-rate", false);
        !w.empty()) {
      std::fprintf(stderr, "vtrack-ego-pose: %s\n", w.c_str());
    }
    return std::make_unique<vtrack::sim::SimPoseTimeline>(sim, lcm, channel);
  };
  return vtrack::sim::RunLive(vm, cli, name, "poses", source);
}
