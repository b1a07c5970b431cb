// Stands in for vtrack-sim-log, vtrack-tracker and vtrack-kitti2lcm (chosen by the name it is
// called by) in vtrack-compare's test, so that the orchestration is tested with known results:
// the "simulator" and "converter" write the synthetic run, the "tracker" writes the synthetic
// tracks with a centre offset per mode (ism 0.5 m, vasm 0.3 m, mht 0.1 m; 0.02 m more per --seed
// above 1).
// FAKE_TOOL_LOG: append each command line to this file. FAKE_TRACKER_FAIL_MODE: the tracker
// fails (exit 4) for this mode.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "tests/log_tools/synthetic_run.h"

int main(int argc, char** argv) {
  const std::string tool = std::filesystem::path(argv[0]).filename().string();
  std::map<std::string, std::string> opt;
  for (int i = 1; i + 1 < argc; i += 2) opt[argv[i]] = argv[i + 1];
  if (const char* log = std::getenv("FAKE_TOOL_LOG")) {
    std::ofstream out(log, std::ios::app);
    // Absolute paths (the work directory) by their last component, the rest as given.
    for (int i = 0; i < argc; ++i) {
      const std::string a = argv[i];
      out << (i ? " " : "") << (a.rfind('/', 0) == 0 ? std::filesystem::path(a).filename().string() : a);
    }
    out << "\n";
  }
  if (tool == "vtrack-sim-log" || tool == "vtrack-kitti2lcm") {
    if (!opt.count("--out")) return 2;
    if (opt["--scenario"] == "fail_sim") {
      std::fprintf(stderr, "fake simulator: scenario fail_sim fails\n");
      return 3;
    }
    vtrack::testing::WriteSyntheticRun(opt["--out"]);
    return 0;
  }
  if (tool == "vtrack-tracker") {
    const std::string mode = opt["--mode"];
    if (!std::filesystem::exists(opt["--input"]) || opt["--output"].empty()) return 2;
    const char* fail = std::getenv("FAKE_TRACKER_FAIL_MODE");
    if (fail && mode == fail) {
      std::fprintf(stderr, "fake tracker: mode %s fails\n", mode.c_str());
      return 4;
    }
    // --seed N (vtrack-compare passes it unless 1): 0.02 m more per seed above 1.
    const double seed = opt.count("--seed") ? std::stod(opt["--seed"]) : 1.0;
    const double offset = (mode == "ism" ? 0.5 : mode == "vasm" ? 0.3 : 0.1) + 0.02 * (seed - 1.0);
    vtrack::testing::WriteSyntheticTracks(opt["--output"], mode, offset);
    return 0;
  }
  std::fprintf(stderr, "fake tool: unknown name %s\n", tool.c_str());
  return 2;
}
