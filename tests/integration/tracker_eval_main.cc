// tracker-eval-scores TRUTH_LOG TRACKS_LOG [TRACE_VEHICLE_ID]: prints the integration tests' scores of a tracker
// output (tracker_eval.h); how the figures in tracker/README.md were made.
#include <cstdio>
#include <exception>
#include <string>

#include "tests/integration/tracker_eval.h"

int main(int argc, char** argv) {
  if (argc != 3 && argc != 4) {
    std::fprintf(stderr, "usage: %s TRUTH_LOG TRACKS_LOG [TRACE_VEHICLE_ID]\n", argv[0]);
    return 2;
  }
  try {
    vtrack::testing::EvalOptions opt;
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
