#include "sensor_driver/driver/live_process.h"

#include <cstdio>
#include <exception>
#include <stdexcept>

#include "lcmtypes/util/process.h"

namespace vtrack::sim {

namespace po = boost::program_options;

void AddLiveSourceOptions(po::options_description* desc,
                          void (*add_model_options)(po::options_description*),
                          const char* kitti_help) {
  desc->add_options()("help,h", "print this help and exit");
  AddScenarioOptions(desc, /*start_utime_is_live=*/true);
  add_model_options(desc);
  desc->add_options()
      ("kitti", po::value<std::string>(), kitti_help)
      ("sequence", po::value<std::string>()->default_value(""),
       "KITTI sequence number (default: the folder's only sequence with point clouds)")
      ("poses", po::value<std::string>(), "KITTI: odometry poses file (velo i -> velo 0)")
      ("oxts", po::value<std::string>(), "KITTI: OXTS file instead of poses")
      ("cache-dir", po::value<std::string>(), "KITTI: where packed point clouds are unpacked")
      ("lcm-url", po::value<std::string>()->default_value(""),
       "LCM URL (default: LCM's own, or $LCM_DEFAULT_URL)");
}

void AddLiveRunOptions(po::options_description* desc) {
  desc->add_options()("quiet,q", "no progress output");
  AddRealtimeOptions(desc);
}

std::optional<int> ParseLiveCommandLine(int argc, char** argv, const po::options_description& desc,
                                        const std::string& usage, const char* name,
                                        po::variables_map* vm, SimCli* cli) {
  auto check = [](const po::variables_map& given) {
    if (given.count("scenario") == given.count("kitti")) {
      throw po::error("give exactly one of --scenario and --kitti");
    }
    if (given.count("poses") && given.count("oxts")) {
      throw po::error("give at most one of --poses and --oxts");
    }
    CheckRealtimeOptions(given);
  };
  return ParseSimCommandLine(argc, argv, desc, usage, name, check, vm, cli);
}

int RunLive(const po::variables_map& vm, const SimCli& cli, const char* name, const char* what,
            const LiveSource& source) {
  try {
    lcm_util::InstallStopHandlers();
    auto lcm = lcm_util::OpenLcm(vm["lcm-url"].as<std::string>());
    RealtimeOptions ro;
    ReadRealtimeOptions(vm, cli, &ro);
    ro.name = name;
    ro.what = what;
    if (vm.count("quiet")) ro.progress_interval_s = 0.0;
    std::unique_ptr<Simulator> sim;
    std::unique_ptr<Timeline> timeline;
    if (vm.count("kitti")) {
      if (!source.kitti) {
        throw std::runtime_error(
            "this build has no KITTI reader (sensor_driver/kitti was not built)");
      }
      timeline = source.kitti(lcm.get());
    } else {
      sim = MakeSimulator(cli);
      timeline = source.scenario(sim.get(), lcm.get());
    }
    ro.lap_us = timeline->LapUs();
    const RealtimeStats stats = RunRealtime(*timeline, ro);
    std::fprintf(stderr, "%s: stopped: %lld %s published, %lld skipped\n", name,
                 static_cast<long long>(stats.published), what,
                 static_cast<long long>(stats.skipped));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", name, e.what());
    return 1;
  }
  return 0;
}

}  // namespace vtrack::sim
