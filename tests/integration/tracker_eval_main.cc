// tracker-eval-scores TRUTH_LOG TRACKS_LOG: prints the integration tests' scores of a tracker
// output (tracker_eval.h); how the figures in tracker/README.md were made.
#include <cstdio>
#include <exception>

#include "tests/integration/tracker_eval.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s TRUTH_LOG TRACKS_LOG\n", argv[0]);
    return 2;
  }
  try {
    const auto r = vtrack::testing::EvaluateTracks(argv[1], argv[2]);
    std::printf("%s\n", vtrack::testing::Summary(r).c_str());
    for (const auto& m : r.misses) std::printf("  %s\n", m.c_str());
    for (const auto& m : r.stationary_multi) std::printf("  %s\n", m.c_str());
    for (const auto& [id, ids] : r.ids) {
      std::printf("  vehicle %lld: tracks", static_cast<long long>(id));
      for (auto t : ids) std::printf(" %lld", static_cast<long long>(t));
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
