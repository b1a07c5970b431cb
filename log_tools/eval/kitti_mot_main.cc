// vtrack-eval-kitti --labels DIR --results DIR [--sequences 0000,0002] [--iou 0.25] [--json F]
// Scores tracking results in the KITTI format against KITTI labels with the devkit's CLEAR MOT
// rules and AB3DMOT's 3-D IoU and sAMOTA sweep (log_tools/eval/kitti_mot.h, log_tools/README.md).
#include <boost/program_options.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "lcmtypes/util/command_line.h"
#include "log_tools/eval/json_writer.h"
#include "log_tools/eval/kitti_mot.h"

namespace po = boost::program_options;
namespace fs = std::filesystem;
using namespace vtrack::eval;
using namespace vtrack::eval::kitti_mot;

namespace {

// "0,2,0011" -> {"0000", "0002", "0011"}: numbers are zero-padded to KITTI's four digits.
std::vector<std::string> ParseSequences(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    item.erase(0, item.find_first_not_of(" \t"));
    item.erase(item.find_last_not_of(" \t") + 1);
    if (item.empty()) throw std::invalid_argument("--sequences '" + text + "': empty element");
    if (item.find('/') != std::string::npos) {
      throw std::invalid_argument("--sequences: '" + item + "' is not a sequence name");
    }
    if (std::all_of(item.begin(), item.end(), [](unsigned char c) { return std::isdigit(c); }) &&
        item.size() < 4) {
      item.insert(0, 4 - item.size(), '0');
    }
    if (std::find(out.begin(), out.end(), item) == out.end()) out.push_back(item);
  }
  return out;
}

// Every NNNN.txt in dir, sorted.
std::vector<std::string> ListSequences(const std::string& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string stem = e.path().stem().string();
    if (e.is_regular_file() && e.path().extension() == ".txt" && !stem.empty() &&
        std::all_of(stem.begin(), stem.end(), [](unsigned char c) { return std::isdigit(c); })) {
      out.push_back(stem);
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string Percent(double v) {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.2f", 100.0 * v);
  return buf;
}

std::string TableRow(const std::string& name, std::int64_t frames, const Result& r) {
  const Counts& b = r.best;
  char thr[32] = "-";
  if (r.thresholded) std::snprintf(thr, sizeof(thr), "%.4g", r.best_threshold);
  char buf[512];
  std::snprintf(buf, sizeof(buf),
                "%-8s %6lld %7lld %7s %7s %7s %9s %7s %7s %6lld %6lld %6lld %6lld %5lld %5lld\n",
                name.c_str(), static_cast<long long>(frames), static_cast<long long>(b.gt),
                Percent(r.samota).c_str(), Percent(r.amota).c_str(), Percent(r.amotp).c_str(), thr,
                Percent(b.Mota()).c_str(), Percent(b.Motp()).c_str(),
                static_cast<long long>(b.tp), static_cast<long long>(b.fp),
                static_cast<long long>(b.fn), static_cast<long long>(b.ignored_tp + b.ignored_fn),
                static_cast<long long>(b.ids), static_cast<long long>(b.frag));
  return buf;
}

void CountsJson(JsonWriter& j, const Counts& c) {
  j.Key("mota").Number(c.Mota());
  j.Key("motp").Number(c.Motp());
  j.Key("moda").Number(c.Moda());
  j.Key("recall").Number(c.Recall());
  j.Key("precision").Number(c.Precision());
  j.Key("gt").Int(c.gt);
  j.Key("tp").Int(c.tp);
  j.Key("ignored_tp").Int(c.ignored_tp);
  j.Key("fp").Int(c.fp);
  j.Key("ignored_tracker").Int(c.ignored_tracker);
  j.Key("fn").Int(c.fn);
  j.Key("ignored_fn").Int(c.ignored_fn);
  j.Key("ids").Int(c.ids);
  j.Key("frag").Int(c.frag);
  j.Key("tracker_boxes").Int(c.tracker_boxes);
  j.Key("gt_trajectories").Int(c.gt_trajectories);
  j.Key("mostly_tracked").Int(c.mostly_tracked);
  j.Key("partly_tracked").Int(c.partly_tracked);
  j.Key("mostly_lost").Int(c.mostly_lost);
}

void ResultJson(JsonWriter& j, std::int64_t frames, std::int64_t result_boxes, const Result& r) {
  j.BeginObject();
  j.Key("frames").Int(frames);
  j.Key("result_boxes").Int(result_boxes);
  j.Key("samota").Number(r.samota);
  j.Key("amota").Number(r.amota);
  j.Key("amotp").Number(r.amotp);
  j.Key("recall_points").Int(static_cast<std::int64_t>(r.sweep.size()));
  j.Key("best_threshold");
  if (r.thresholded) {
    j.Number(r.best_threshold);
  } else {
    j.String("none");
  }
  CountsJson(j, r.best);
  j.Key("all_tracks").BeginObject();
  CountsJson(j, r.all_tracks);
  j.EndObject();
  j.Key("sweep").BeginArray();
  for (const auto& p : r.sweep) {
    j.BeginObject();
    j.Key("threshold").Number(p.threshold);
    j.Key("recall").Number(p.recall);
    j.Key("mota").Number(p.mota);
    j.Key("motp").Number(p.motp);
    j.Key("smota").Number(p.smota);
    j.EndObject();
  }
  j.EndArray();
  j.EndObject();
}

struct Options {
  std::string labels_dir, results_dir, json_path;
  std::vector<std::string> sequences;
  Params params;
  bool quiet = false;
};

// A scored sequence, or "all" for the pool.
struct Scored {
  std::string name;
  std::int64_t frames = 0, result_boxes = 0;
  Result result;
};

// Parses the command line into o. Returns -1 to go on, else the exit status (0 after --help,
// 2 for a bad option, with the message printed).
int ParseOptions(int argc, char** argv, Options* o) {
  std::string sequences_text;
  po::options_description desc(
      "vtrack-eval-kitti --labels DIR --results DIR [--sequences 0000,0002] [options]\n"
      "Scores tracking results in the KITTI format (frame id type truncated occluded alpha x1 y1\n"
      "x2 y2 h w l x y z rotation_y score, one file per sequence NNNN.txt, as written by\n"
      "vtrack-eval --kitti-out) against KITTI tracking labels, class car: the KITTI devkit's\n"
      "CLEAR MOT rules with 3-D IoU matching and AB3DMOT's score-threshold sweep (sAMOTA, AMOTA,\n"
      "AMOTP; MOTA, MOTP, IDS, FRAG, FP, FN at the threshold of the best MOTA).\n"
      "Table values are percentages; the JSON holds fractions.\n\nOptions");
  desc.add_options()
    ("help,h", "print this help")
    ("labels", po::value(&o->labels_dir), "folder of ground-truth label files NNNN.txt (label_02)")
    ("results", po::value(&o->results_dir), "folder of result files NNNN.txt")
    ("sequences", po::value(&sequences_text),
     "comma-separated sequences, e.g. 0000,0002 or 0,2 [every NNNN.txt in --labels]")
    ("iou", po::value(&o->params.min_iou)->default_value(0.25),
     "3-D IoU a match needs (0.25, 0.5, 0.7 are the published settings)")
    ("json", po::value(&o->json_path), "write per-sequence and summed metrics here")
    ("quiet,q", po::bool_switch(&o->quiet), "no progress output");
  try {
    po::variables_map vm;
    if (!vtrack::lcm_util::StoreCommandLine(po::parse_command_line(argc, argv, desc), desc, &vm)) {
      return 0;
    }
    if (o->labels_dir.empty()) throw std::invalid_argument("--labels DIR is required (see --help)");
    if (o->results_dir.empty()) {
      throw std::invalid_argument("--results DIR is required (see --help)");
    }
    if (!(o->params.min_iou > 0.0 && o->params.min_iou <= 1.0)) {
      throw std::invalid_argument("--iou must be in (0, 1], got " +
                                  std::to_string(o->params.min_iou));
    }
    for (const auto& [opt, dir] :
         {std::pair{"--labels", o->labels_dir}, {"--results", o->results_dir}}) {
      if (!fs::is_directory(dir)) {
        throw std::invalid_argument(std::string(opt) + " " + dir + ": not a directory");
      }
    }
    o->sequences =
        sequences_text.empty() ? ListSequences(o->labels_dir) : ParseSequences(sequences_text);
    if (o->sequences.empty()) {
      throw std::invalid_argument("no sequence to score in " + o->labels_dir);
    }
  } catch (const std::exception& e) {
    std::cerr << "vtrack-eval-kitti: " << e.what() << "\n";
    return 2;
  }
  return -1;
}

void PrintTable(const Params& params, const std::vector<Scored>& rows) {
  std::printf("KITTI 3-D MOT, class car, 3-D IoU >= %g; sweep over %d recall points; "
              "percentages\n",
              params.min_iou, params.sample_points - 1);
  std::printf("%-8s %6s %7s %7s %7s %7s %9s %7s %7s %6s %6s %6s %6s %5s %5s\n", "sequence",
              "frames", "gt", "sAMOTA", "AMOTA", "AMOTP", "threshold", "MOTA", "MOTP", "TP",
              "FP", "FN", "ignGT", "IDS", "FRAG");
  for (const Scored& r : rows) std::fputs(TableRow(r.name, r.frames, r.result).c_str(), stdout);
}

// rows: the sequences, then the pool.
void WriteJson(const Options& o, const std::vector<Scored>& rows) {
  JsonWriter j;
  j.BeginObject();
  j.Key("class").String("car");
  j.Key("labels").String(o.labels_dir);
  j.Key("results").String(o.results_dir);
  j.Key("params").BeginObject();
  j.Key("min_iou").Number(o.params.min_iou);
  j.Key("max_truncation").Int(o.params.max_truncation);
  j.Key("max_occlusion").Int(o.params.max_occlusion);
  j.Key("min_height_px").Number(o.params.min_height_px);
  j.Key("dontcare_overlap").Number(o.params.dontcare_overlap);
  j.Key("recall_points").Int(o.params.sample_points - 1);
  j.EndObject();
  j.Key("sequences").BeginObject();
  for (std::size_t k = 0; k + 1 < rows.size(); ++k) {
    j.Key(rows[k].name);
    ResultJson(j, rows[k].frames, rows[k].result_boxes, rows[k].result);
  }
  j.EndObject();
  j.Key("all");
  ResultJson(j, rows.back().frames, rows.back().result_boxes, rows.back().result);
  j.EndObject();
  std::ofstream out(o.json_path);
  out << j.str() << "\n";
  if (!out) throw std::runtime_error(o.json_path + ": cannot write");
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (const int rc = ParseOptions(argc, argv, &o); rc >= 0) return rc;
  try {
    std::vector<std::unique_ptr<PreparedSequence>> prepared;
    std::vector<Scored> rows;
    Scored all;
    all.name = "all";
    for (std::size_t k = 0; k < o.sequences.size(); ++k) {
      const std::string& name = o.sequences[k];
      const std::string labels_path = (fs::path(o.labels_dir) / (name + ".txt")).string();
      const std::string results_path = (fs::path(o.results_dir) / (name + ".txt")).string();
      std::int64_t last_label_frame = -1;
      const auto gt = ReadTrackingFile(labels_path, false, &last_label_frame);
      const auto res = ReadTrackingFile(results_path, true);
      if (const RowsAfter late = RowsAfterFrame(res, last_label_frame); late.count > 0) {
        // Printed with -q too: the score counts these rows, and the cause is usually a mix-up.
        std::fprintf(stderr,
                     "vtrack-eval-kitti: warning: %s: %lld car/van rows in frames %lld-%lld, after "
                     "frame %lld, the last with a row in %s; they are scored against no object, "
                     "each car not ignored a false positive (results of another sequence, or "
                     "frames numbered from another first frame? expected only if the sequence's "
                     "last frames hold no object)\n",
                     results_path.c_str(), static_cast<long long>(late.count),
                     static_cast<long long>(late.first_frame),
                     static_cast<long long>(late.last_frame),
                     static_cast<long long>(last_label_frame), labels_path.c_str());
      }
      prepared.push_back(std::make_unique<PreparedSequence>(name, gt, res, o.params));
      rows.push_back({name, prepared.back()->frames(), prepared.back()->result_boxes(),
                      Score({prepared.back().get()}, o.params)});
      all.frames += rows.back().frames;
      all.result_boxes += rows.back().result_boxes;
      if (!o.quiet) {
        std::fprintf(stderr,
                     "vtrack-eval-kitti: [%zu/%zu] %s: %lld frames, %zu car/van/DontCare label "
                     "rows, %zu car/van result rows, %zu thresholds\n",
                     k + 1, o.sequences.size(), name.c_str(),
                     static_cast<long long>(rows.back().frames), gt.size(), res.size(),
                     rows.back().result.sweep.size());
      }
    }
    std::vector<const PreparedSequence*> pool;
    for (const auto& p : prepared) pool.push_back(p.get());
    all.result = Score(pool, o.params);
    rows.push_back(std::move(all));
    PrintTable(o.params, rows);
    if (!o.json_path.empty()) WriteJson(o, rows);
  } catch (const std::exception& e) {
    std::cerr << "vtrack-eval-kitti: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
