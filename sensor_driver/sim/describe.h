// A readable summary of a scenario, for people writing scenario files (vtrack-sim-log --describe):
// what is in the scene, and where each driving vehicle starts and ends, how far it turns, and
// how fast it goes.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "sensor_driver/sim/simulator.h"

namespace vtrack::sim {

void Describe(const Simulator& sim, std::ostream& out);

// Two footprints that intersect at some time: a scenario that makes vehicles drive through each
// other, through clutter or through the ego. Cylinders count as their bounding squares.
struct Overlap {
  double t = 0.0;              // [s] first time found
  std::string a, b;            // "car 3", "wall 17", "ego"
  double depth = 0.0;          // [m] penetration along the separating-axis test's best axis
};
// Checks every pair that involves a moving vehicle or the ego every step seconds over [0,
// duration]; overlaps shallower than tolerance [m] are ignored. One entry per pair.
std::vector<Overlap> FindOverlaps(const Scenario& scenario, double step = 0.1,
                                  double tolerance = 0.05);

}  // namespace vtrack::sim
