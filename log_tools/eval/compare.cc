#include "log_tools/eval/compare.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "lcmtypes/util/command_line.h"
#include "lcmtypes/util/process.h"
#include "log_tools/eval/json_writer.h"
#include "log_tools/eval/progress.h"
#include "log_tools/eval/report.h"
#include "sensor_driver/kitti/kitti_layout.h"

extern char** environ;

namespace vtrack::eval {
namespace fs = std::filesystem;

namespace {

std::string Join(const std::vector<std::string>& argv) {
  std::string s;
  for (const auto& a : argv) s += (s.empty() ? "" : " ") + a;
  return s;
}

// Last lines of a child's log, for the error message.
std::string Tail(const std::string& path, int lines) {
  std::ifstream in(path);
  std::vector<std::string> all;
  for (std::string l; std::getline(in, l);) all.push_back(l);
  std::string out;
  for (std::size_t i = all.size() > static_cast<std::size_t>(lines) ? all.size() - lines : 0;
       i < all.size(); ++i) {
    out += "    " + all[i] + "\n";
  }
  return out;
}

// Runs argv to completion with stdout and stderr in log_path. Throws std::runtime_error with the
// command, the reason and the end of its output if it cannot start, fails, or times out.
void RunProcess(const std::vector<std::string>& argv, const std::string& log_path, double timeout_s) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) {
    throw std::runtime_error("cannot start '" + argv[0] + "': " + std::strerror(rc));
  }
  const auto start = std::chrono::steady_clock::now();
  int status = 0;
  std::string failure;
  while (true) {
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (lcm_util::StopRequested() || elapsed > timeout_s) {
      failure = lcm_util::StopRequested() ? "interrupted" : "timed out after " + std::to_string(timeout_s) + " s";
      kill(pid, SIGTERM);
      for (int i = 0; i < 50 && waitpid(pid, &status, WNOHANG) != pid; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        if (i == 49) {
          kill(pid, SIGKILL);
          waitpid(pid, &status, 0);
        }
      }
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (failure.empty()) {
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
    failure = WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                                : "killed by signal " + std::to_string(WTERMSIG(status));
  }
  throw std::runtime_error("'" + Join(argv) + "' failed (" + failure + "); its output (" + log_path +
                           ") ends:\n" + Tail(log_path, 15));
}

std::string JoinComma(const std::vector<std::string>& v) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : ", ") + s;
  return out;
}

std::string DefaultBinDir() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string(".") : self.parent_path().string();
}

std::string FindKittiCalib(const CompareOptions& o, const CompareItem& item) {
  if (!o.kitti_calib.empty() && item.kind == CompareItem::Kind::kKitti) return o.kitti_calib;
  const std::string& seq = item.sequence;
  for (const fs::path& p : {fs::path(item.source) / "calib" / (seq + ".txt"),
                            fs::path(item.source) / "training" / "calib" / (seq + ".txt")}) {
    if (fs::is_regular_file(p)) return p.string();
  }
  throw std::runtime_error("no calibration calib/" + seq + ".txt under '" + item.source +
                           "' (needed to score KITTI inside the camera view): pass --kitti-calib");
}

// The sequence's label file, for its DontCare regions ("" if there is none: then none apply).
std::string FindKittiLabels(const CompareItem& item) {
  const std::string& seq = item.sequence;
  for (const fs::path& p : {fs::path(item.source) / "label_02" / (seq + ".txt"),
                            fs::path(item.source) / "training" / "label_02" / (seq + ".txt")}) {
    if (fs::is_regular_file(p)) return p.string();
  }
  return "";
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// Means weighted by their samples: *err and *n from the parts' (error, samples) per horizon.
void PoolMeans(const std::vector<std::pair<const std::vector<double>*, const std::vector<std::int64_t>*>>& parts,
               std::vector<double>* err, std::vector<std::int64_t>* n) {
  std::vector<double> sum;
  for (const auto& [e, c] : parts) {
    if (sum.size() < e->size()) {
      sum.resize(e->size(), 0.0);
      n->resize(e->size(), 0);
    }
    for (std::size_t h = 0; h < e->size() && h < c->size(); ++h) {
      if ((*c)[h] > 0) {
        sum[h] += (*e)[h] * static_cast<double>((*c)[h]);
        (*n)[h] += (*c)[h];
      }
    }
  }
  err->assign(sum.size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t h = 0; h < sum.size(); ++h) {
    if ((*n)[h] > 0) (*err)[h] = sum[h] / static_cast<double>((*n)[h]);
  }
}

// The CLEAR MOT counts of every sequence summed (MOTA recomputed from them, MOTP weighted by
// the matches), and the prediction errors (all, turning, straight) weighted by their samples;
// mean_hota: HOTA and its parts the mean over the parts (runs of one item with several seeds),
// else NaN (the boxes sequences: their sum is not a HOTA); the rest is not summed.
EvalSummary SumOf(const std::vector<const EvalSummary*>& parts, bool mean_hota) {
  EvalSummary s;
  double motp_sum = 0.0;
  std::vector<double> pred_sum;
  for (const EvalSummary* p : parts) {
    s.mode = p->mode;
    const ClearMotResult& c = p->clear;
    s.clear.gt_detections += c.gt_detections;
    s.clear.true_positives += c.true_positives;
    s.clear.false_positives += c.false_positives;
    s.clear.false_negatives += c.false_negatives;
    s.clear.id_switches += c.id_switches;
    s.clear.fragmentations += c.fragmentations;
    s.clear.gt_objects += c.gt_objects;
    s.clear.mostly_tracked += c.mostly_tracked;
    s.clear.partially_tracked += c.partially_tracked;
    s.clear.mostly_lost += c.mostly_lost;
    if (c.true_positives > 0) motp_sum += c.motp_m * static_cast<double>(c.true_positives);
    s.scans += p->scans;
    s.scored_tracks += p->scored_tracks;
    if (s.prediction_error_m.size() < p->prediction_error_m.size()) {
      s.prediction_error_m.resize(p->prediction_error_m.size(), 0.0);
      s.prediction_samples.resize(p->prediction_error_m.size(), 0);
      pred_sum.resize(p->prediction_error_m.size(), 0.0);
    }
    for (std::size_t h = 0; h < p->prediction_error_m.size(); ++h) {
      if (p->prediction_samples[h] > 0) {
        pred_sum[h] += p->prediction_error_m[h] * static_cast<double>(p->prediction_samples[h]);
        s.prediction_samples[h] += p->prediction_samples[h];
      }
    }
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto& c = s.clear;
  s.clear.mota = c.gt_detections > 0
                     ? 1.0 - static_cast<double>(c.false_negatives + c.false_positives + c.id_switches) /
                                 static_cast<double>(c.gt_detections)
                     : nan;
  s.clear.motp_m = c.true_positives > 0 ? motp_sum / static_cast<double>(c.true_positives) : nan;
  for (std::size_t h = 0; h < pred_sum.size(); ++h) {
    s.prediction_error_m[h] = s.prediction_samples[h] > 0
                                  ? pred_sum[h] / static_cast<double>(s.prediction_samples[h])
                                  : nan;
  }
  std::vector<std::pair<const std::vector<double>*, const std::vector<std::int64_t>*>> turning, straight;
  for (const EvalSummary* p : parts) {
    turning.push_back({&p->prediction_error_turning_m, &p->prediction_samples_turning});
    straight.push_back({&p->prediction_error_straight_m, &p->prediction_samples_straight});
  }
  PoolMeans(turning, &s.prediction_error_turning_m, &s.prediction_samples_turning);
  PoolMeans(straight, &s.prediction_error_straight_m, &s.prediction_samples_straight);
  if (!parts.empty()) s.params = parts.front()->params;  // the horizons, for the JSON
  s.hota.hota = s.hota.deta = s.hota.assa = s.hota.loca = nan;
  if (mean_hota && !parts.empty()) {
    s.hota.hota = s.hota.deta = s.hota.assa = s.hota.loca = 0.0;
    for (const EvalSummary* p : parts) {
      s.hota.hota += p->hota.hota / static_cast<double>(parts.size());
      s.hota.deta += p->hota.deta / static_cast<double>(parts.size());
      s.hota.assa += p->hota.assa / static_cast<double>(parts.size());
      s.hota.loca += p->hota.loca / static_cast<double>(parts.size());
    }
  }
  s.position_rmse_m = s.heading_rmse_deg = s.heading_flip_fraction = nan;
  s.speed_rmse_mps = s.yaw_rate_rmse_dps = s.rear_axle_rmse_m = nan;
  s.nees_mean = s.nees_within_95 = nan;
  return s;
}

}  // namespace

std::vector<std::string> BoxesSequences(const std::string& dir) {
  std::vector<std::string> out;
  const fs::path labels = fs::path(dir) / "label_02";
  std::error_code ec;
  if (fs::is_directory(labels, ec)) {
    for (const auto& e : fs::directory_iterator(labels, ec)) {
      if (e.path().extension() != ".txt") continue;
      const std::string seq = e.path().stem().string();
      if (fs::is_regular_file(fs::path(dir) / "ego_pose_orbslam3" / (seq + ".txt"))) out.push_back(seq);
    }
  }
  std::sort(out.begin(), out.end());
  if (out.empty()) {
    throw std::invalid_argument("no sequence in '" + dir +
                                "': expected label_02/NNNN.txt with ego_pose_orbslam3/NNNN.txt");
  }
  return out;
}

CompareItem ScenarioItem(const std::string& name_or_path) {
  CompareItem item;
  item.kind = CompareItem::Kind::kScenario;
  item.source = name_or_path;
  item.name = fs::path(name_or_path).stem().string();
  if (item.name.empty()) throw std::invalid_argument("empty scenario name in --scenarios");
  return item;
}

std::vector<CompareItem> SeedItems(const CompareItem& base, const std::vector<std::int64_t>& seeds) {
  if (seeds.empty()) throw std::invalid_argument("no seed");
  std::vector<CompareItem> out;
  for (const std::int64_t seed : seeds) {
    CompareItem item = base;
    item.seed = seed;
    if (seeds.size() > 1) {
      item.name = base.name + "_seed" + std::to_string(seed);
      item.sum_row = base.name + "_seeds";
    }
    for (const CompareItem& other : out) {
      if (other.seed == seed) {
        throw std::invalid_argument("seed " + std::to_string(seed) + " given twice");
      }
    }
    out.push_back(item);
  }
  return out;
}

int RunCompare(const CompareOptions& o) {
  if (o.items.empty()) {
    throw std::invalid_argument("nothing to compare: give --scenarios, --kitti and/or --kitti-boxes");
  }
  if (o.modes.empty()) throw std::invalid_argument("--modes is empty");
  for (const auto& m : o.modes) {
    if (m != "cv" && m != "ism" && m != "vasm" && m != "mht") {
      throw std::invalid_argument("--modes: unknown mode '" + m + "' (cv, ism, vasm, mht)");
    }
  }
  if (!(o.timeout_s > 0.0)) {
    throw std::invalid_argument("--timeout must be > 0, got " + std::to_string(o.timeout_s));
  }
  if (!(o.kitti_range_m > 0.0)) {
    throw std::invalid_argument("--kitti-range must be > 0, got " + std::to_string(o.kitti_range_m));
  }
  std::map<std::string, int> names;
  for (const auto& item : o.items) {
    if (++names[item.name] > 1) {
      throw std::invalid_argument("two items are named '" + item.name + "'; rename a scenario file");
    }
  }
  const EvalParams scenario_params = MakeEvalParams(o.eval);  // validates the eval options
  const std::string bin_dir = o.bin_dir.empty() ? DefaultBinDir() : o.bin_dir;
  auto tool = [&](const std::string& name) {
    const fs::path p = fs::path(bin_dir) / name;
    if (!fs::exists(p)) {
      throw std::runtime_error("'" + p.string() + "' does not exist (build it, or pass --bin-dir)");
    }
    return p.string();
  };

  // Work directory.
  // The outputs first: a --json or --plots that cannot be written is said before any run, not
  // after all of them.
  if (!o.json_path.empty()) {
    if (const std::string why = lcm_util::WhyNotWritable(o.json_path); !why.empty()) {
      throw std::runtime_error("cannot write --json '" + o.json_path + "': " + why);
    }
  }
  if (!o.plots_dir.empty()) {
    std::error_code ec;
    fs::create_directories(o.plots_dir, ec);
    if (!fs::is_directory(o.plots_dir)) {
      throw std::runtime_error("cannot create --plots directory '" + o.plots_dir + "'");
    }
  }
  std::string work = o.work_dir;
  bool temporary = false;
  if (work.empty()) {
    std::string tmpl = (fs::temp_directory_path() / "vtrack-compare-XXXXXX").string();
    if (!mkdtemp(tmpl.data())) throw std::runtime_error("cannot create a temporary directory");
    work = tmpl;
    temporary = true;
  } else {
    std::error_code ec;
    fs::create_directories(work, ec);
    if (!fs::is_directory(work)) throw std::runtime_error("cannot create --work-dir '" + work + "'");
  }

  lcm_util::InstallStopHandlers();
  const int total = static_cast<int>(o.items.size() * (1 + o.modes.size()));
  int step = 0;
  auto say = [&](const std::string& what) {
    if (!o.quiet) std::fprintf(stderr, "[%d/%d] %s\n", step, total, what.c_str());
  };

  // results[item][mode]; an item or mode that failed has no entry.
  std::map<std::string, std::map<std::string, EvalSummary>> results;
  std::vector<std::string> failures;
  for (const CompareItem& item : o.items) {
    if (lcm_util::StopRequested()) break;
    const fs::path dir = fs::path(work) / item.name;
    fs::create_directories(dir);
    const std::string run = (dir / "run.lcm").string();
    EvalParams params = scenario_params;
    ++step;
    try {
      std::vector<std::string> argv;
      if (item.kind == CompareItem::Kind::kScenario) {
        argv = {tool("vtrack-sim-log"), "--scenario", item.source, "--out", run, "--seed",
                std::to_string(item.seed)};
      } else if (item.kind == CompareItem::Kind::kKitti) {
        argv = {tool("vtrack-kitti2lcm"), "--kitti", item.source, "--sequence", item.sequence,
                "--out", run};
        if (!o.kitti_poses.empty()) argv.insert(argv.end(), {"--poses", o.kitti_poses});
        if (!o.kitti_oxts.empty()) argv.insert(argv.end(), {"--oxts", o.kitti_oxts});
        const bool boxes_only = item.input_mode == "boxes";
        if (boxes_only) argv.push_back("--no-scans");  // truth and boxes share the frame's time
        EvalCliOptions kopt = o.eval;
        kopt.kitti_calib = FindKittiCalib(o, item);
        kopt.region_camera = true;
        kopt.region_range_m = o.kitti_range_m;
        if (o.kitti_dont_care) kopt.kitti_dont_care = FindKittiLabels(item);
        if (o.kitti_dont_care && kopt.kitti_dont_care.empty()) {
          say(item.name + ": no label_02 file: no DontCare regions");
        }
        // With scans, the labels are half a sweep after the scan's utime.
        if (!boxes_only) kopt.truth_time_offset = "half-sweep";
        params = MakeEvalParams(kopt);
      } else {
        argv = {tool("vtrack-kitti2lcm"), "--kitti", item.source, "--sequence", item.sequence,
                "--out", run};
        EvalCliOptions kopt = o.eval;
        kopt.kitti_calib = FindKittiCalib(o, item);
        kopt.region_camera = true;
        kopt.region_range_m = o.kitti_range_m;
        if (o.kitti_dont_care) kopt.kitti_dont_care = FindKittiLabels(item);
        if (o.kitti_dont_care && kopt.kitti_dont_care.empty()) {
          say(item.name + ": no label_02 file: no DontCare regions");
        }
        params = MakeEvalParams(kopt);  // no scans: the truth and the boxes share the frame's time
      }
      if (o.reuse && fs::is_regular_file(run)) {
        say(item.name + ": reusing " + run);
      } else {
        say(item.name + ": " + Join(argv));
        const auto t = std::chrono::steady_clock::now();
        RunProcess(argv, (dir / "run.log").string(), o.timeout_s);
        say(item.name + ": log written in " + std::to_string(static_cast<int>(Seconds(t))) + " s");
      }
    } catch (const std::exception& e) {
      failures.push_back(item.name + ": " + e.what());
      std::fprintf(stderr, "vtrack-compare: %s: %s\n", item.name.c_str(), e.what());
      step += static_cast<int>(o.modes.size());
      continue;
    }

    // Ground truth and poses once; each mode's tracks added to a copy.
    LogData base;
    try {
      Progress progress(!o.quiet);
      base = LoadLogs({run}, params, [&](const std::string& path, double f) {
        if (WorthProgress(path)) progress.Update("reading " + item.name + "/run.lcm", f);
      });
    } catch (const std::exception& e) {
      failures.push_back(item.name + ": " + e.what());
      std::fprintf(stderr, "vtrack-compare: %s: %s\n", item.name.c_str(), e.what());
      step += static_cast<int>(o.modes.size());
      continue;
    }
    for (const std::string& mode : o.modes) {
      if (lcm_util::StopRequested()) break;
      ++step;
      const std::string tracks = (dir / ("tracks_" + mode + ".lcm")).string();
      try {
        if (o.reuse && fs::is_regular_file(tracks)) {
          say(item.name + " / " + mode + ": reusing " + tracks);
        } else {
          std::vector<std::string> argv = {tool("vtrack-tracker"), "--input", run, "--output",
                                           tracks, "--mode", mode};
          if (item.kind == CompareItem::Kind::kKittiBoxes) {
            argv.insert(argv.end(), {"--input-mode", "boxes"});
          } else if (item.kind == CompareItem::Kind::kKitti) {
            argv.insert(argv.end(), {"--input-mode", item.input_mode});
          }
          if (!o.tracker_config.empty()) argv.insert(argv.end(), {"--config", o.tracker_config});
          if (item.seed != 1) argv.insert(argv.end(), {"--seed", std::to_string(item.seed)});
          say(item.name + " / " + mode + ": " + Join(argv));
          const auto t = std::chrono::steady_clock::now();
          RunProcess(argv, (dir / ("tracker_" + mode + ".log")).string(), o.timeout_s);
          say(item.name + " / " + mode + ": tracked in " +
              std::to_string(static_cast<int>(Seconds(t))) + " s");
        }
        LogData data = base;
        AddLog(&data, tracks, params);
        EvalParams p = params;
        p.mode = mode;
        results[item.name][mode] = Evaluate(data, p);
        if (item.kind == CompareItem::Kind::kKittiBoxes) {
          // The tracks in the KITTI result format, for the 3-D IoU criterion (vtrack-eval-kitti).
          const fs::path kdir = fs::path(work) / ("kitti_results_" + mode);
          fs::create_directories(kdir);
          std::vector<std::string> export_argv = {
              tool("vtrack-eval"), run, tracks, "--mode", mode, "--kitti-calib",
              FindKittiCalib(o, item), "--kitti-out", (kdir / (item.sequence + ".txt")).string(),
              "--kitti-tentative", o.eval.kitti_tentative ? "1" : "0", "--kitti-coast-frames",
              std::to_string(o.eval.kitti_coast_frames)};
          if (o.eval.score_coasting) export_argv.push_back("--score-coasting");
          RunProcess(export_argv, (dir / ("kitti_export_" + mode + ".log")).string(), o.timeout_s);
        }
      } catch (const std::exception& e) {
        failures.push_back(item.name + " / " + mode + ": " + e.what());
        std::fprintf(stderr, "vtrack-compare: %s / %s: %s\n", item.name.c_str(), mode.c_str(),
                     e.what());
      }
    }
    if (!o.plots_dir.empty() && results.count(item.name)) {
      const std::string path = (fs::path(o.plots_dir) / (item.name + "_modes.png")).string();
      try {
        WriteModePlot("vtrack-compare: " + item.name + " (" + JoinComma(o.modes) + ")", results[item.name], path);
        say(item.name + ": wrote " + path);
      } catch (const std::exception& e) {
        failures.push_back(item.name + ": " + e.what());
      }
    }
  }

  // The table, in the order given; each summed row (CompareItem::sum_row) after its last item,
  // per mode.
  std::vector<TableRow> rows;
  std::vector<std::string> sum_rows;  // in order of their last item
  std::map<std::string, std::map<std::string, EvalSummary>> sums;  // [sum row][mode]
  for (std::size_t k = 0; k < o.items.size(); ++k) {
    const CompareItem& item = o.items[k];
    for (const std::string& mode : o.modes) {
      const auto it = results.find(item.name);
      const EvalSummary* s = nullptr;
      if (it != results.end() && it->second.count(mode)) s = &it->second.at(mode);
      rows.push_back({item.name, mode, s});
    }
    if (item.sum_row.empty()) continue;
    bool last = true;
    for (std::size_t l = k + 1; l < o.items.size(); ++l) last = last && o.items[l].sum_row != item.sum_row;
    if (!last) continue;
    sum_rows.push_back(item.sum_row);
    for (const std::string& mode : o.modes) {
      // Every part or none: a sum over the runs that happened to succeed would read as the whole.
      std::vector<const EvalSummary*> parts;
      bool draws = true;  // runs of one item with several seeds (not the boxes sequences)
      bool complete = true;
      for (const CompareItem& part : o.items) {
        if (part.sum_row != item.sum_row) continue;
        draws = draws && part.kind != CompareItem::Kind::kKittiBoxes;
        const auto it = results.find(part.name);
        if (it != results.end() && it->second.count(mode)) parts.push_back(&it->second.at(mode));
        else complete = false;
      }
      if (complete && !parts.empty()) sums[item.sum_row][mode] = SumOf(parts, draws);
      const auto& row_sums = sums[item.sum_row];
      rows.push_back({item.sum_row, mode, row_sums.count(mode) ? &row_sums.at(mode) : nullptr});
    }
  }
  std::cout << ComparisonTable(rows) << std::flush;

  // The boxes sequences under the criterion 3-D MOT papers publish on KITTI (vtrack-eval-kitti:
  // the devkit's rules, 3-D IoU >= kitti_iou, AB3DMOT's sAMOTA sweep), per mode.
  std::map<std::string, std::string> iou_json;
  std::string labels_dir, seq_list;
  for (const CompareItem& item : o.items) {
    if (item.kind != CompareItem::Kind::kKittiBoxes) continue;
    labels_dir = (fs::path(item.source) / "label_02").string();
    seq_list += (seq_list.empty() ? "" : ",") + item.sequence;
  }
  for (const std::string& mode : o.modes) {
    if (seq_list.empty() || lcm_util::StopRequested()) break;
    const fs::path kdir = fs::path(work) / ("kitti_results_" + mode);
    const fs::path json = fs::path(work) / ("kitti_iou_" + mode + ".json");
    const fs::path log = fs::path(work) / ("kitti_iou_" + mode + ".log");
    try {
      RunProcess({tool("vtrack-eval-kitti"), "--labels", labels_dir, "--results", kdir.string(),
                  "--sequences", seq_list, "--iou", std::to_string(o.kitti_iou), "--json",
                  json.string(), "-q"},
                 log.string(), o.timeout_s);
      std::ifstream in(log);
      std::cout << "\n3-D IoU >= " << o.kitti_iou << ", mode " << mode << " (vtrack-eval-kitti):\n"
                << in.rdbuf() << std::flush;
      std::ifstream js(json);
      std::stringstream ss;
      ss << js.rdbuf();
      iou_json[mode] = ss.str();
    } catch (const std::exception& e) {
      failures.push_back("kitti 3-D IoU / " + mode + ": " + e.what());
    }
  }

  if (!o.json_path.empty()) {
    JsonWriter w;
    w.BeginObject();
    for (const CompareItem& item : o.items) {
      w.Key(item.name).BeginObject();
      for (const std::string& mode : o.modes) {
        const auto it = results.find(item.name);
        w.Key(mode);
        if (it != results.end() && it->second.count(mode)) {
          std::string js = SummaryJson(it->second.at(mode));
          while (!js.empty() && js.back() == '\n') js.pop_back();
          w.Raw(js);
        } else {
          w.Raw("null");
        }
      }
      w.EndObject();
    }
    if (!iou_json.empty()) {
      w.Key("kitti_boxes_iou").BeginObject();
      for (const auto& [mode, js] : iou_json) {
        std::string t = js;
        while (!t.empty() && (t.back() == '\n' || t.back() == ' ')) t.pop_back();
        w.Key(mode).Raw(t);
      }
      w.EndObject();
    }
    for (const std::string& row : sum_rows) {
      const auto& row_sums = sums[row];
      w.Key(row).BeginObject();
      for (const std::string& mode : o.modes) {
        w.Key(mode);
        if (row_sums.count(mode)) {
          std::string js = SummaryJson(row_sums.at(mode));
          while (!js.empty() && js.back() == '\n') js.pop_back();
          w.Raw(js);
        } else {
          w.Raw("null");
        }
      }
      w.EndObject();
    }
    w.EndObject();
    try {
      WriteTextFile(o.json_path, w.str() + "\n");
    } catch (const std::exception&) {
      if (temporary) std::fprintf(stderr, "work directory kept: %s\n", work.c_str());
      throw;
    }
    std::fprintf(stderr, "wrote %s\n", o.json_path.c_str());
  }

  if (temporary) {
    if (o.keep_work || !failures.empty()) {
      std::fprintf(stderr, "work directory kept: %s\n", work.c_str());
    } else {
      std::error_code ec;
      fs::remove_all(work, ec);
    }
  }
  if (lcm_util::StopRequested()) failures.push_back("interrupted");
  if (!failures.empty()) {
    std::fprintf(stderr, "vtrack-compare: %zu failure(s):\n", failures.size());
    for (const auto& f : failures) std::fprintf(stderr, "  %s\n", f.c_str());
    return 1;
  }
  return 0;
}

}  // namespace vtrack::eval
