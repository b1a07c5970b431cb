// Scenario files (config/scenarios/*.yaml): the scene, its sensors, the ego's path, and how
// ground truth is labelled. The format is documented key by key in sensor_driver/README.md.
//
// Loading is strict: an unknown key, a missing required key, a value of the wrong type or out of
// range, or malformed YAML gives a ScenarioError whose message names the file, the line and
// column, and the key path, e.g.
//   config/scenarios/x.yaml:12:14: vehicles[1].profile[2].steer_deg = 95: must be in (-60, 60) deg
// `extends: <name or path>` loads another scenario first and overrides it key by key (maps merge
// recursively; lists and scalars replace).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "sensor_driver/sim/ladar.h"
#include "sensor_driver/sim/scene.h"

namespace vtrack::sim {

class ScenarioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// First-order Gauss-Markov error added to the published ego pose (vtrack-ego-pose). Each of x, y
// and yaw is an independent stationary process with the given 1-sigma and correlation time.
struct PoseNoiseParams {
  double position = 0.0;          // [m] 1-sigma per horizontal axis, >= 0 (0 = exact)
  double yaw_deg = 0.0;           // [deg] 1-sigma of yaw, >= 0
  double correlation_time = 2.0;  // [s] > 0; the noise decorrelates as exp(-dt / this)
};

// Which ground-truth objects are "in the labelled region" (object_t.in_labelled_region): those
// whose centre is within labelled_radius of the sensor at the scan's start and that have at
// least min_points returns in that scan. Only these are scored by the evaluator.
struct TruthParams {
  double labelled_radius = 50.0;  // [m] > 0
  int min_points = 3;             // [-] >= 0
};

struct Scenario {
  std::string name;         // file stem unless `name:` is given
  std::string description;
  std::string path;         // file it was loaded from
  double duration = 20.0;   // [s] length of one run, (0, 3600]
  std::int64_t start_utime = 1'700'000'000'000'000;  // [us] utime of t = 0 in vtrack-sim-log
  std::uint64_t seed = 1;   // default seed of every random draw
  Scene scene;
  std::map<std::string, LadarParams> sensors;  // the scenario's own sensors, by name
  std::string default_sensor;                  // a key of sensors or a preset name
  double pose_rate_hz = 100.0;                 // [Hz] EGO_POSE rate, [1, 1000]
  PoseNoiseParams pose_noise;
  TruthParams truth;

  // The sensor called name ("" = default_sensor): the scenario's own, else a built-in preset.
  // Throws std::invalid_argument listing the available names if there is none.
  LadarParams Sensor(const std::string& name = "") const;
};

// Loads and validates a scenario file. duration_override (if set) replaces `duration` before the
// trajectories are built. Throws ScenarioError.
Scenario LoadScenario(const std::string& path,
                      std::optional<double> duration_override = std::nullopt);

// NAME -> the file: an existing path as given; otherwise NAME.yaml (or NAME) in, in order,
// $VTRACK_SCENARIO_DIR, ./config/scenarios, the source tree's config/scenarios, and the installed
// share/vtrack/config/scenarios next to the executable. Throws ScenarioError listing the places
// searched.
std::string ResolveScenarioPath(const std::string& name_or_path);

}  // namespace vtrack::sim
