// vtrack-compare: runs the tracker in its three modes over scenarios and KITTI data and prints
// one table of the evaluator's metrics (see compare.h and log_tools/README.md).
#include <boost/program_options.hpp>

#include <cstdint>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "lcmtypes/util/command_line.h"
#include "log_tools/eval/compare.h"
#include "sensor_driver/kitti/kitti_layout.h"

namespace po = boost::program_options;
using namespace vtrack::eval;

namespace {
std::vector<std::string> SplitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}
}  // namespace

int main(int argc, char** argv) {
  CompareOptions o;
  std::string scenarios, modes = "ism,vasm,mht";
  std::vector<std::string> kitti_dirs;
  std::string kitti_boxes_dir, sequences, kitti_input_modes = "scans", seeds;
  std::int64_t seed = 1;
  bool no_dont_care = false;

  po::options_description desc(
      "vtrack-compare --scenarios a,b [--kitti DIR] [options]\n"
      "Runs vtrack-tracker in each mode (ism, vasm, mht) over each scenario (simulated with\n"
      "vtrack-sim-log) and KITTI sequence (converted with vtrack-kitti2lcm), scores every run\n"
      "against ground truth and prints one table, mode by mode.\n\nOptions");
  desc.add_options()
    ("help,h", "print this help")
    ("scenarios", po::value(&scenarios), "comma-separated scenario NAMEs or YAML paths")
    ("kitti", po::value(&kitti_dirs), "KITTI tracking directory (repeatable); scored in camera 2's "
                                      "view within --kitti-range, named kitti_<sequence>")
    ("kitti-input-modes", po::value(&kitti_input_modes)->default_value(kitti_input_modes),
     "with --kitti: comma-separated vtrack-tracker input modes: scans, boxes (the sequence's\n"
     "detections/pointrcnn_Car alone) and/or fused (both); the boxes and fused items are named\n"
     "kitti_<sequence>_boxes and kitti_<sequence>_fused")
    ("kitti-sequence", po::value(&o.kitti_sequence),
     "KITTI sequence of every --kitti folder (default: each folder's only sequence with point clouds)")
    ("kitti-boxes", po::value(&kitti_boxes_dir),
     "KITTI folder of the boxes layout (label_02/, calib/, detections/pointrcnn_Car/,\n"
     "ego_pose_orbslam3/; no point clouds): every --sequences tracked from its detections\n"
     "(--input-mode boxes), named kitti_boxes_<sequence>, and their sum kitti_boxes_sum")
    ("kitti-iou", po::value(&o.kitti_iou)->default_value(o.kitti_iou),
     "with --kitti-boxes: the 3-D IoU threshold of the KITTI criterion (vtrack-eval-kitti)")
    ("sequences", po::value(&sequences),
     "with --kitti-boxes: comma-separated sequences (default: every one the folder holds)")
    ("kitti-poses", po::value(&o.kitti_poses), "ego motion file for the converter (--poses)")
    ("kitti-oxts", po::value(&o.kitti_oxts), "OXTS file for the converter (--oxts)")
    ("kitti-range", po::value(&o.kitti_range_m)->default_value(o.kitti_range_m),
     "[m] KITTI items are scored within this distance")
    ("kitti-no-dontcare", po::bool_switch(&no_dont_care),
     "count unmatched tracks in the labels' DontCare regions as false positives (by default "
     "they are not, as in the KITTI devkit)")
    ("modes", po::value(&modes)->default_value(modes), "tracker modes, comma separated")
    ("seed", po::value(&seed)->default_value(seed),
     "simulator seed, also the tracker's (its fits' random draws; passed unless 1)")
    ("seeds", po::value(&seeds),
     "comma-separated seeds (instead of --seed): each scenario, and each KITTI item measured by\n"
     "scans, run once per seed (the simulator's and the tracker's --seed), named <item>_seed<N>,\n"
     "then a row <item>_seeds of their CLEAR MOT counts summed (MOTA from the sums) and their\n"
     "mean HOTA")
    ("json", po::value(&o.json_path), "write {scenario: {mode: summary}} here")
    ("plots", po::value(&o.plots_dir), "write <scenario>_modes.png (modes side by side) here")
    ("work-dir", po::value(&o.work_dir), "keep logs here (default: a temporary directory, removed)")
    ("keep-work", po::bool_switch(&o.keep_work), "keep the temporary directory")
    ("reuse", po::bool_switch(&o.reuse), "reuse run.lcm / tracks_<mode>.lcm found in --work-dir")
    ("tracker-config", po::value(&o.tracker_config), "passed to vtrack-tracker --config")
    ("bin-dir", po::value(&o.bin_dir), "where the vtrack executables are (default: beside this one)")
    ("timeout", po::value(&o.timeout_s)->default_value(o.timeout_s), "[s] limit per child process")
    ("quiet,q", po::bool_switch(&o.quiet), "no progress output");
  po::options_description eval_desc("Scoring options (as vtrack-eval)");
  AddEvalOptions(&eval_desc, &o.eval);
  desc.add(eval_desc);

  try {
    po::variables_map vm;
    if (!vtrack::lcm_util::StoreCommandLine(po::parse_command_line(argc, argv, desc), desc, &vm)) {
      return 0;
    }
    if (!o.eval.mode.empty()) throw std::invalid_argument("--mode is not an option here: use --modes");
    if (!o.eval.kitti_dont_care.empty()) {
      throw std::invalid_argument("--kitti-dontcare is not an option here: each KITTI sequence's "
                                  "label_02 file gives its DontCare regions (--kitti-no-dontcare: "
                                  "none)");
    }
    if (o.reuse && o.work_dir.empty()) throw std::invalid_argument("--reuse needs --work-dir");
    if (vm.count("seeds") && !vm["seed"].defaulted()) {
      throw std::invalid_argument("--seed and --seeds: give one");
    }
    if (seed < 0) throw std::invalid_argument("--seed " + std::to_string(seed) + " must be >= 0");
    std::vector<std::int64_t> seed_list;
    for (const auto& s : SplitList(vm.count("seeds") ? seeds : std::to_string(seed))) {
      std::size_t used = 0;
      long long v = -1;
      try {
        v = std::stoll(s, &used);
      } catch (const std::out_of_range&) {
        throw std::invalid_argument("--seeds: '" + s + "' is out of range");
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != s.size() || s.empty()) throw std::invalid_argument("--seeds: '" + s + "' is not an integer");
      if (v < 0) throw std::invalid_argument("--seeds: " + s + " must be >= 0");
      seed_list.push_back(v);
    }
    if (seed_list.empty()) throw std::invalid_argument("--seeds is empty");
    for (const auto& s : SplitList(scenarios)) {
      for (const CompareItem& item : SeedItems(ScenarioItem(s), seed_list)) {
        o.items.push_back(item);
      }
    }
    const std::vector<std::string> input_modes = SplitList(kitti_input_modes);
    if (input_modes.empty()) throw std::invalid_argument("--kitti-input-modes is empty");
    for (const auto& m : input_modes) {
      if (m != "scans" && m != "boxes" && m != "fused") {
        throw std::invalid_argument("--kitti-input-modes: '" + m + "' is not scans, boxes or fused");
      }
    }
    for (const auto& d : kitti_dirs) {
      std::string seq;
      try {
        seq = vtrack::kitti::ResolveSequence(d, o.kitti_sequence);
      } catch (const std::exception& e) {
        throw std::invalid_argument((o.kitti_sequence.empty() ? "--kitti " + d : std::string("--kitti-sequence")) +
                                    ": " + e.what());
      }
      for (const auto& m : input_modes) {
        CompareItem item;
        item.kind = CompareItem::Kind::kKitti;
        item.source = d;
        item.sequence = seq;
        item.input_mode = m;
        item.name = "kitti_" + seq + (m == "scans" ? "" : "_" + m);
        // Boxes alone draw nothing at random: one run.
        const std::vector<std::int64_t> runs =
            m == "boxes" ? std::vector<std::int64_t>{seed_list.front()} : seed_list;
        for (const CompareItem& run : SeedItems(item, runs)) o.items.push_back(run);
      }
    }
    if (!sequences.empty() && kitti_boxes_dir.empty()) {
      throw std::invalid_argument("--sequences goes with --kitti-boxes");
    }
    if (!kitti_boxes_dir.empty()) {
      const std::vector<std::string> seqs =
          sequences.empty() ? vtrack::eval::BoxesSequences(kitti_boxes_dir) : SplitList(sequences);
      for (const auto& s : seqs) {
        CompareItem item;
        item.kind = CompareItem::Kind::kKittiBoxes;
        item.source = kitti_boxes_dir;
        try {
          item.sequence = vtrack::kitti::NormaliseSequence(s);
        } catch (const std::exception& e) {
          throw std::invalid_argument(std::string("--sequences: ") + e.what());
        }
        item.name = "kitti_boxes_" + item.sequence;
        item.sum_row = "kitti_boxes_sum";
        o.items.push_back(item);
      }
    }
    o.modes = SplitList(modes);
    o.kitti_dont_care = !no_dont_care;
    return RunCompare(o);
  } catch (const std::invalid_argument& e) {
    std::cerr << "vtrack-compare: " << e.what() << "\n";
    return 2;
  } catch (const po::error& e) {
    std::cerr << "vtrack-compare: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "vtrack-compare: " << e.what() << "\n";
    return 1;
  }
}
