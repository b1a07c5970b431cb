// vtrack-sim-log: writes a scenario's whole run (LADAR_SCAN, GROUND_TRUTH, EGO_POSE) straight to
// an LCM log file, as fast as possible. See sensor_driver/README.md and sim/sim_log.h.
#include <boost/program_options.hpp>

#include <chrono>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "lcmtypes/util/command_line.h"
#include "lcmtypes/util/log_reader.h"
#include "sensor_driver/driver/sim_cli.h"
#include "sensor_driver/sim/describe.h"
#include "sensor_driver/sim/scenario.h"
#include "sensor_driver/sim/sim_log.h"

namespace po = boost::program_options;
using vtrack::sim::SimLogChannels;

int main(int argc, char** argv) {
  po::options_description desc("Options");
  desc.add_options()("help,h", "print this help and exit");
  vtrack::sim::AddScenarioOptions(&desc, /*start_utime_is_live=*/false);
  vtrack::sim::AddSensorOptions(&desc);
  vtrack::sim::AddPoseOptions(&desc);
  vtrack::sim::AddSweepOutputOptions(&desc, /*live=*/false);
  desc.add_options()
      ("out,o", po::value<std::string>(), "LCM log file to write (overwritten)")
      ("truth-channel", po::value<std::string>()->default_value("GROUND_TRUTH"), "channel of the ground truth")
      ("pose-channel", po::value<std::string>()->default_value("EGO_POSE"), "channel of the ego poses")
      ("describe", "print the scenario's objects and each vehicle's path instead of writing a log")
      ("quiet,q", "no progress output");
  const std::string usage =
      "vtrack-sim-log: write a scenario's complete log (scans, ground truth, ego poses) to an LCM\n"
      "log file as fast as possible, with the contents a live run of vtrack-ladar-driver and\n"
      "vtrack-ego-pose (same --start-utime and seed) recorded by lcm-logger would have.\n\n"
      "usage: vtrack-sim-log --scenario NAME --out run.lcm [--seed N] [--sensor S] [...]";
  auto check = [](const po::variables_map& vm) {
    if (!vm.count("scenario")) throw po::error("--scenario is required");
    if (!vm.count("out") && !vm.count("describe")) throw po::error("--out is required");
    if (vm.count("out")) {
      // The file the scenario's name resolves to (config/scenarios/NAME.yaml, ...), if any.
      std::string scenario = vm["scenario"].as<std::string>();
      try {
        scenario = vtrack::sim::ResolveScenarioPath(scenario);
      } catch (const std::exception&) {
        // no such scenario: said when it is loaded
      }
      vtrack::lcm_util::RefuseOverwritingInputs({{"--scenario", scenario}},
                                                {{"--out", vm["out"].as<std::string>()}});
    }
    vtrack::sim::ReadSweepOutputOptions(vm);
  };
  po::variables_map vm;
  vtrack::sim::SimCli cli;
  if (const auto status = vtrack::sim::ParseSimCommandLine(argc, argv, desc, usage,
                                                           "vtrack-sim-log", check, &vm, &cli)) {
    return *status;
  }
  const bool quiet = vm.count("quiet") > 0;
  try {
    auto sim = vtrack::sim::MakeSimulator(cli);
    if (vm.count("describe")) {
      vtrack::sim::Describe(*sim, std::cout);
      return 0;
    }
    const std::string out = vm["out"].as<std::string>();
    const std::int64_t start = cli.start_utime.value_or(sim->scenario().start_utime);
    SimLogChannels ch;
    ch.sweep = vtrack::sim::ReadSweepOutputOptions(vm);
    ch.truth = vm["truth-channel"].as<std::string>();
    ch.pose = vm["pose-channel"].as<std::string>();
    if (!quiet) {
      std::fprintf(stderr,
                   "vtrack-sim-log: scenario '%s' (%s), %.1f s, sensor '%s' (%d layers, %.1f Hz), "
                   "seed %llu, %d scans, %d poses at %.0f Hz -> %s\n",
                   sim->scenario().name.c_str(), sim->scenario().path.c_str(),
                   sim->scenario().duration, sim->sensor().name.c_str(), sim->sensor().NumLayers(),
                   sim->sensor().rate_hz, static_cast<unsigned long long>(sim->seed()),
                   sim->NumScans(), sim->NumPoses(), sim->pose_rate_hz(), out.c_str());
    }
    if (const std::string w = vtrack::sim::SweepsLeftOutWarning(*sim, "--pose-rate", true);
        !w.empty()) {
      std::fprintf(stderr, "vtrack-sim-log: %s\n", w.c_str());
    }
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t cpu0 = std::clock();
    int last_decile = -1;
    auto progress = [&](double f) {
      const int decile = static_cast<int>(f * 10.0);
      if (quiet || decile == last_decile || decile == 0) return;
      last_decile = decile;
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::fprintf(stderr, "vtrack-sim-log: %3.0f%% (%.1f s)\n", 100.0 * f, s);
    };
    vtrack::lcm_util::LogWriter writer(out);
    const auto stats = vtrack::sim::WriteSimLog(*sim, start, ch, &writer, progress);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double cpu = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
    if (!quiet) {
      const double run = sim->RunDurationUs() * 1e-6;
      std::fprintf(stderr,
                   "vtrack-sim-log: wrote %s: %d scans (%.0f points/scan, %lld slices), %d "
                   "ground-truth lists, %d poses, %.1f MB; %.1f s of scenario in %.2f s wall = "
                   "%.1fx real time (%.2f s CPU = %.1fx)\n",
                   out.c_str(), stats.scans,
                   stats.scans ? static_cast<double>(stats.points) / stats.scans : 0.0,
                   static_cast<long long>(stats.slices),
                   stats.scans, stats.poses, stats.bytes / 1e6, run, wall, run / wall, cpu,
                   cpu > 0 ? run / cpu : 0.0);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vtrack-sim-log: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
