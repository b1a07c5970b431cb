// tracker-eval-scores [--max-range M] TRUTH_LOG TRACKS_LOG [TRACE_VEHICLE_ID]: prints the integration
// tests' scores of a tracker output (tracker_eval.h); how the figures in tracker/README.md were made.
// --max-range: vehicles within M metres of the ego are scored (default: EvalOptions, 40 m).
// --reacquire S: a vehicle without returns for more than S seconds is new in view when seen
// again, twice that for a vehicle not moving (default: EvalOptions, 1.5 s and 3 s; 0: never, a
// vehicle is due from its first second on).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "tests/integration/tracker_eval.h"

int main(int argc, char** argv) {
  vtrack::testing::EvalOptions opt;
  while (argc >= 3 && (std::string(argv[1]) == "--max-range" || std::string(argv[1]) == "--reacquire")) {
    const bool range = std::string(argv[1]) == "--max-range";
    char* end = nullptr;
    const double v = std::strtod(argv[2], &end);
    if (end == argv[2] || *end != '\0' || !std::isfinite(v) || (range && !(v > 0.0))) {
      std::fprintf(stderr, "%s: %s %s: not %s\n", argv[0], argv[1], argv[2],
                   range ? "a positive number of metres" : "a number of seconds");
      return 2;
    }
    if (range) {
      opt.max_range = v;
    } else {
      opt.reacquire_after_s = v;
      opt.reacquire_parked_after_s = v > 0.0 ? 2.0 * v : v;
    }
    argv += 2;
    argc -= 2;
  }
  if (argc != 3 && argc != 4) {
    std::fprintf(stderr, "usage: %s [--max-range M] [--reacquire S] TRUTH_LOG TRACKS_LOG [TRACE_VEHICLE_ID]\n", argv[0]);
    return 2;
  }
  try {
    if (argc == 4) opt.trace_vehicle = std::stoll(argv[3]);
    const auto r = vtrack::testing::EvaluateTracks(argv[1], argv[2], opt);
    for (const auto& m : r.trace) std::printf("%s\n", m.c_str());
    std::printf("%s\n", vtrack::testing::Summary(r).c_str());
    for (const auto& m : r.misses) std::printf("  %s\n", m.c_str());
    for (const auto& m : r.stationary_multi) std::printf("  %s\n", m.c_str());
    for (const auto& m : r.switches) std::printf("  switch %s\n", m.c_str());
    for (const auto& [id, ids] : r.ids) {
      std::printf("  vehicle %lld: tracks", static_cast<long long>(id));
      for (auto t : ids) std::printf(" %lld", static_cast<long long>(t));
      if (r.vehicle_due.count(id)) {
        std::printf("  (missed %lld of %lld due)",
                    static_cast<long long>(r.vehicle_missed.count(id) ? r.vehicle_missed.at(id) : 0),
                    static_cast<long long>(r.vehicle_due.at(id)));
      }
      if (r.vehicle_pos_rmse.count(id)) {
        std::printf("  (pos RMSE %.2f m, heading RMSE %.1f deg)", r.vehicle_pos_rmse.at(id),
                    r.vehicle_heading_rmse_deg.at(id));
      }
      std::printf("\n");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
