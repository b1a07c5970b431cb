// What vtrack-ladar-driver and vtrack-ego-pose share beyond the simulator's options (sim_cli.h):
// the choice of source (a scenario or a KITTI sequence), the bus, and the run itself.
#pragma once

#include <boost/program_options.hpp>
#include <lcm/lcm-cpp.hpp>

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "sensor_driver/driver/realtime.h"
#include "sensor_driver/driver/sim_cli.h"
#include "sensor_driver/sim/simulator.h"

namespace vtrack::sim {

// --help, the scenario options, those of add_model_options (AddSensorOptions, AddPoseOptions),
// --kitti (described by kitti_help), --sequence, --poses, --oxts, --cache-dir and --lcm-url.
void AddLiveSourceOptions(boost::program_options::options_description* desc,
                          void (*add_model_options)(boost::program_options::options_description*),
                          const char* kitti_help);
// --quiet and the schedule (AddRealtimeOptions).
void AddLiveRunOptions(boost::program_options::options_description* desc);

// ParseSimCommandLine for a live process: refuses anything but exactly one of --scenario and
// --kitti, and both --poses and --oxts.
std::optional<int> ParseLiveCommandLine(int argc, char** argv,
                                        const boost::program_options::options_description& desc,
                                        const std::string& usage, const char* name,
                                        boost::program_options::variables_map* vm, SimCli* cli);

// Builds what a live process publishes on lcm, from one of the two sources; each prints what it
// will publish and throws for a source that cannot be read.
struct LiveSource {
  // --kitti; unset in a build without the KITTI readers (sensor_driver/kitti).
  std::function<std::unique_ptr<Timeline>(lcm::LCM* lcm)> kitti;
  // The scenario, simulated by sim (which outlives the timeline).
  std::function<std::unique_ptr<Timeline>(Simulator* sim, lcm::LCM* lcm)> scenario;
};

// Runs a live process until its laps are done or it is stopped: installs the stop handlers, opens
// the bus of --lcm-url, builds the timeline of --kitti or --scenario and publishes it on the wall
// clock (RunRealtime, with --laps, --stop-after, --rate, --quiet). Progress lines, prefixed
// "name: ", count `what`; the last says how many were published and skipped. Returns the exit
// status: 0, or 1 after printing "name: error: MESSAGE" for an exception.
int RunLive(const boost::program_options::variables_map& vm, const SimCli& cli, const char* name,
            const char* what, const LiveSource& source);

}  // namespace vtrack::sim
