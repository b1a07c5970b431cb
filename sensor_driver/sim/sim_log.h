// Writing a scenario's whole run straight to an LCM log file, as fast as the machine allows, with
// what lcm-logger would have recorded from a live run of vtrack-ladar-driver + vtrack-ego-pose
// started with the same --start-utime: the same messages, in the order they are published, with
// event timestamps at the instant of publication (pose: its utime; scan, or all its slices, and
// its ground truth: when the sweep is complete, utime + sweep_duration_us). A live log differs only by the
// network and scheduling jitter in lcm-logger's receive timestamps.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "lcmtypes/util/log_reader.h"
#include "sensor_driver/sim/simulator.h"
#include "sensor_driver/sim/sweep_output.h"

namespace vtrack::sim {

struct SimLogChannels {
  SweepOutput sweep;  // whole sweeps or slices (sweep_output.h)
  std::string truth = "GROUND_TRUTH";
  std::string pose = "EGO_POSE";
};

struct SimLogStats {
  int scans = 0;
  std::int64_t slices = 0;  // slice messages (0: every sweep written whole)
  int poses = 0;
  std::int64_t points = 0;  // returns over all scans
  std::int64_t bytes = 0;   // encoded message bytes
};

// Writes one run starting at start_utime. progress (if set) is called now and then with the
// fraction done. Throws std::runtime_error if the log cannot be written.
SimLogStats WriteSimLog(Simulator& sim, std::int64_t start_utime, const SimLogChannels& channels,
                        lcm_util::LogWriter* writer,
                        const std::function<void(double)>& progress = {});

}  // namespace vtrack::sim
