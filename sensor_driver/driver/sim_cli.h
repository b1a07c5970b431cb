// Command-line options shared by vtrack-ladar-driver, vtrack-ego-pose and vtrack-sim-log, so the
// three spell and check them the same way (and agree on a scenario's messages).
#pragma once

#include <boost/program_options.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "sensor_driver/driver/realtime.h"
#include "sensor_driver/sim/simulator.h"

namespace vtrack::sim {

struct SimCli {
  std::string scenario;          // NAME or path
  std::optional<double> duration;
  std::optional<std::int64_t> start_utime;
  RunOptions run;
};

// --scenario, --seed, --duration, --start-utime.
void AddScenarioOptions(boost::program_options::options_description* desc, bool start_utime_is_live);
// --sensor, --range-noise, --dropout, --spurious.
void AddSensorOptions(boost::program_options::options_description* desc);
// --pose-rate, --pose-noise-pos, --pose-noise-yaw-deg.
void AddPoseOptions(boost::program_options::options_description* desc);

// --laps, --stop-after, --rate: the schedule of the two live processes (realtime.h).
void AddRealtimeOptions(boost::program_options::options_description* desc);
// Fills options->laps, stop_after_s, rate and start_utime from vm and cli; the rest is left.
// Throws po::error if --stop-after, --rate or --laps is out of range (non-finite, negative).
void CheckRealtimeOptions(const boost::program_options::variables_map& vm);
void ReadRealtimeOptions(const boost::program_options::variables_map& vm, const SimCli& cli,
                         RealtimeOptions* options);

// Reads the options above that were defined and given. Throws boost::program_options::error for
// a value no scenario could accept (e.g. a negative --start-utime).
SimCli ReadSimCli(const boost::program_options::variables_map& vm);

// Resolves and loads the scenario and applies the overrides. Throws (ScenarioError,
// std::invalid_argument) with a message fit for the user.
std::unique_ptr<Simulator> MakeSimulator(const SimCli& cli);

// Empty, or a warning that the pose rate leaves the last sweeps of the run out (no pose follows
// them), with how many and what rate would keep them; rate_setting names where the user sets
// that rate for this program ("--pose-rate", or the scenario's key). left_out_here: the program
// leaves those sweeps out itself (a log, the driver's lap), rather than publishing poses that
// end before them (vtrack-ego-pose).
std::string SweepsLeftOutWarning(const Simulator& sim, const std::string& rate_setting,
                                 bool left_out_here);

// Parses argv against desc; prints help (with usage) and returns false if --help was given.
// Throws boost::program_options::error on bad options.
bool ParseCommandLine(int argc, char** argv, const boost::program_options::options_description& desc,
                      const std::string& usage, boost::program_options::variables_map* vm);

// Parses argv (ParseCommandLine) into *vm and *cli (ReadSimCli), then calls check (if set),
// which throws boost::program_options::error for options that do not go together. Returns the
// exit status if the process should stop here: 0 after the help for --help, 2 after printing
// "name: MESSAGE (see --help)" for a bad command line; nullopt to go on.
std::optional<int> ParseSimCommandLine(
    int argc, char** argv, const boost::program_options::options_description& desc,
    const std::string& usage, const char* name,
    const std::function<void(const boost::program_options::variables_map&)>& check,
    boost::program_options::variables_map* vm, SimCli* cli);

}  // namespace vtrack::sim
