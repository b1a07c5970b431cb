#include "sensor_driver/driver/sim_cli.h"

#include <cmath>
#include <cstdio>
#include <type_traits>

#include "base/pose.h"
#include "lcmtypes/util/command_line.h"

namespace vtrack::sim {

namespace po = boost::program_options;

void AddScenarioOptions(po::options_description* desc, bool start_utime_is_live) {
  desc->add_options()
      ("scenario", po::value<std::string>(),
       "scenario NAME (config/scenarios/NAME.yaml) or path to a scenario file")
      ("seed", po::value<std::uint64_t>(), "seed of every random draw (default: the scenario's)")
      ("duration", po::value<double>(), "[s] override the scenario's duration (one run)")
      ("start-utime", po::value<std::int64_t>(),
       start_utime_is_live
           ? "[us since epoch] start of run 0 (scenario t = 0); runs repeat every duration. "
             "Default 0: runs on the wall-clock grid, so separately started processes agree"
           : "[us since epoch] utime of scenario t = 0 (default: the scenario's start_utime)");
}

void AddSensorOptions(po::options_description* desc) {
  desc->add_options()
      ("sensor", po::value<std::string>(),
       "sensor name: one of the scenario's `sensors` or a preset (single_plane, velodyne64)")
      ("range-noise", po::value<double>(), "[m] override the sensor's 1-sigma range noise")
      ("dropout", po::value<double>(), "[0,1) override the probability a return is lost")
      ("spurious", po::value<double>(), "[0,1) override the probability of a spurious return per ray");
}

void AddPoseOptions(po::options_description* desc) {
  desc->add_options()
      ("pose-rate", po::value<double>(), "[Hz] EGO_POSE rate (default: the scenario's, 100)")
      ("pose-noise-pos", po::value<double>(), "[m] 1-sigma Gauss-Markov noise on x and y")
      ("pose-noise-yaw-deg", po::value<double>(), "[deg] 1-sigma Gauss-Markov noise on yaw");
}

void AddRealtimeOptions(po::options_description* desc) {
  desc->add_options()
      ("laps", po::value<std::int64_t>()->default_value(0), "runs to publish; 0 = until stopped")
      ("stop-after", po::value<double>()->default_value(0.0), "[s] stop after this much wall time; 0 = never")
      ("rate", po::value<double>()->default_value(1.0),
       "data seconds per wall second: < 1 slow motion for a consumer slower than real time; "
       "stamps and contents stay those of rate 1. Needs --start-utime; give the driver and "
       "vtrack-ego-pose the same");
}

void CheckRealtimeOptions(const po::variables_map& vm) {
  // --stop-after inf would publish nothing and exit 0, nan would never stop: refused.
  const double stop_after = vm["stop-after"].as<double>();
  if (!std::isfinite(stop_after) || stop_after < 0) {
    throw po::error("--stop-after = " + std::to_string(stop_after) + ": must be finite and >= 0");
  }
  const double rate = vm["rate"].as<double>();
  if (!std::isfinite(rate) || !(rate > 0)) {
    throw po::error("--rate = " + std::to_string(rate) + ": must be finite and > 0");
  }
  if (vm["laps"].as<std::int64_t>() < 0) {
    throw po::error("--laps = " + std::to_string(vm["laps"].as<std::int64_t>()) + ": must be >= 0");
  }
}

void ReadRealtimeOptions(const po::variables_map& vm, const SimCli& cli, RealtimeOptions* o) {
  o->start_utime = cli.start_utime;
  o->laps = vm["laps"].as<std::int64_t>();
  o->stop_after_s = vm["stop-after"].as<double>();
  o->rate = vm["rate"].as<double>();
}

SimCli ReadSimCli(const po::variables_map& vm) {
  SimCli c;
  auto get = [&](const char* k, auto* out) {
    if (!vm.count(k)) return;
    using T = std::remove_reference_t<decltype(**out)>;
    const T v = vm[k].as<T>();
    if constexpr (std::is_floating_point_v<T>) {
      // Every numeric option of the simulator is a size, a rate or a probability: NaN, Inf or
      // a negative value is a mistake, never a request.
      if (!std::isfinite(v) || v < 0) {
        throw po::error(std::string("--") + k + " = " + std::to_string(v) + ": must be finite and >= 0");
      }
    }
    *out = v;
  };
  if (vm.count("scenario")) c.scenario = vm["scenario"].as<std::string>();
  get("duration", &c.duration);
  get("start-utime", &c.start_utime);
  if (c.start_utime && (*c.start_utime < 0 || *c.start_utime > vtrack::kMaxStartUtime)) {
    throw po::error("--start-utime = " + std::to_string(*c.start_utime) + ": must be in [0, " +
                    std::to_string(vtrack::kMaxStartUtime) + "] us (2^52: the year 2112)");
  }
  get("seed", &c.run.seed);
  if (vm.count("sensor")) c.run.sensor = vm["sensor"].as<std::string>();
  get("range-noise", &c.run.range_noise);
  get("dropout", &c.run.dropout);
  get("spurious", &c.run.spurious);
  get("pose-rate", &c.run.pose_rate_hz);
  get("pose-noise-pos", &c.run.pose_noise_position);
  get("pose-noise-yaw-deg", &c.run.pose_noise_yaw_deg);
  return c;
}

std::unique_ptr<Simulator> MakeSimulator(const SimCli& cli) {
  const std::string path = ResolveScenarioPath(cli.scenario);
  return std::make_unique<Simulator>(LoadScenario(path, cli.duration), cli.run);
}

std::string SweepsLeftOutWarning(const Simulator& sim, const std::string& rate_setting,
                                 bool left_out_here) {
  const int lost = sim.NumSweepsInRun() - sim.NumScans();
  if (lost <= 0) return "";
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "warning: %d of the scenario's %d sweeps %s after its last pose (%.3f s into the "
                "run at %g Hz), and the tracker needs a pose after a sweep to place its returns; "
                "a higher %s (at most 1000 Hz) keeps them",
                lost, sim.NumSweepsInRun(),
                left_out_here ? "are left out: they end" : "cannot be tracked: they end",
                sim.PoseOffsetUs(sim.NumPoses() - 1) * 1e-6, sim.pose_rate_hz(),
                rate_setting.c_str());
  return buf;
}

bool ParseCommandLine(int argc, char** argv, const po::options_description& desc,
                      const std::string& usage, po::variables_map* vm) {
  return lcm_util::StoreCommandLine(po::command_line_parser(argc, argv).options(desc).run(), desc,
                                   vm, usage);
}

std::optional<int> ParseSimCommandLine(int argc, char** argv, const po::options_description& desc,
                                       const std::string& usage, const char* name,
                                       const std::function<void(const po::variables_map&)>& check,
                                       po::variables_map* vm, SimCli* cli) {
  try {
    if (!ParseCommandLine(argc, argv, desc, usage, vm)) return 0;
    *cli = ReadSimCli(*vm);
    if (check) check(*vm);
  } catch (const po::error& e) {
    std::fprintf(stderr, "%s: %s (see --help)\n", name, e.what());
    return 2;
  }
  return std::nullopt;
}

}  // namespace vtrack::sim
