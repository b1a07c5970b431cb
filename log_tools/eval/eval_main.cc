// vtrack-eval LOG... : scores a tracker run against ground truth (docs/design.md, section 7).
// See log_tools/README.md for the metrics and the outputs.
#include <boost/program_options.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "lcmtypes/util/command_line.h"
#include "log_tools/eval/cli_common.h"
#include "log_tools/eval/evaluator.h"
#include "log_tools/eval/kitti_export.h"
#include "log_tools/eval/progress.h"
#include "log_tools/eval/report.h"

namespace po = boost::program_options;
using namespace vtrack::eval;

int main(int argc, char** argv) {
  std::vector<std::string> logs;
  std::string json_path, csv_path, plots_dir, kitti_out, labels_path;
  bool quiet = false;
  EvalCliOptions eval_opts;

  po::options_description desc(
      "vtrack-eval LOG... [options]\n"
      "Scores the tracks in LCM logs against their ground truth: CLEAR MOT, HOTA, state errors,\n"
      "prediction error and NEES. Logs are merged by time (e.g. run.lcm tracks.lcm).\n\nOptions");
  desc.add_options()
    ("help,h", "print this help")
    ("json", po::value(&json_path), "write the JSON summary here")
    ("csv", po::value(&csv_path), "write the per-track CSV here")
    ("plots", po::value(&plots_dir), "write PNG plots into this directory")
    ("track-labels", po::value(&labels_path),
     "write every track of every scored frame (any status, any class) with its label against "
     "the truth here (CSV: 1 vehicle, 0 not a vehicle, -1 ignore)")
    ("kitti-out", po::value(&kitti_out), "export tracks in the KITTI tracking result format "
                                         "(needs --kitti-calib)")
    ("quiet,q", po::bool_switch(&quiet), "no progress output");
  AddEvalOptions(&desc, &eval_opts);
  po::options_description hidden;
  hidden.add_options()("log", po::value(&logs));
  po::options_description all;
  all.add(desc).add(hidden);
  po::positional_options_description pos;
  pos.add("log", -1);

  try {
    po::variables_map vm;
    if (!vtrack::lcm_util::StoreCommandLine(
            po::command_line_parser(argc, argv).options(all).positional(pos).run(), desc, &vm)) {
      return 0;
    }
    if (logs.empty()) throw std::invalid_argument("no LOG given (see --help)");
    if (!kitti_out.empty() && eval_opts.kitti_calib.empty()) {
      throw std::invalid_argument("--kitti-out needs --kitti-calib FILE");
    }
    std::vector<vtrack::lcm_util::PathArgument> inputs{{"--kitti-calib", eval_opts.kitti_calib},
                                                       {"--kitti-dontcare", eval_opts.kitti_dont_care}};
    for (const std::string& log : logs) inputs.push_back({"", log});
    vtrack::lcm_util::RefuseOverwritingInputs(
        inputs, {{"--json", json_path}, {"--csv", csv_path}, {"--track-labels", labels_path},
                 {"--kitti-out", kitti_out}});
  } catch (const std::exception& e) {
    std::cerr << "vtrack-eval: " << e.what() << "\n";
    return 2;
  }

  EvalParams params;
  std::optional<KittiExportParams> kitti_params;
  try {
    params = MakeEvalParams(eval_opts);
    if (!kitti_out.empty()) kitti_params = MakeKittiExportParams(eval_opts);
  } catch (const std::exception& e) {
    std::cerr << "vtrack-eval: " << e.what() << "\n";
    return 2;
  }

  try {
    Progress progress(!quiet);
    const LogData data = LoadLogs(logs, params, [&](const std::string& path, double f) {
      if (WorthProgress(path)) {
        progress.Update("reading " + std::filesystem::path(path).filename().string(), f);
      }
    });
    progress.Finish();
    std::vector<TrackLabel> labels;
    const EvalSummary summary = Evaluate(data, params, labels_path.empty() ? nullptr : &labels);
    std::cout << SummaryText(summary);
    if (!json_path.empty()) {
      WriteTextFile(json_path, SummaryJson(summary));
      std::cout << "wrote " << json_path << "\n";
    }
    if (!csv_path.empty()) {
      WriteTextFile(csv_path, TrackCsv(summary));
      std::cout << "wrote " << csv_path << "\n";
    }
    if (!labels_path.empty()) {
      WriteTextFile(labels_path, TrackLabelCsv(labels));
      std::cout << "wrote " << labels_path << "\n";
    }
    if (!plots_dir.empty()) {
      for (const auto& p : WriteEvalPlots(summary, plots_dir)) std::cout << "wrote " << p << "\n";
    }
    if (kitti_params) {
      const KittiExportStats st = ExportKittiTracking(data, summary.mode, *kitti_params, kitti_out);
      std::cout << "wrote " << kitti_out << ": " << st.lines << " boxes over " << st.frames
                << " frames (states advanced " << st.time_offset_s << " s; " << st.outside_image
                << " tracks outside the image, " << st.frames_without_pose
                << " frames without pose)\n";
    }
    for (const std::string& d : data.damaged_logs) std::cerr << "vtrack-eval: " << d << "\n";
    if (!data.damaged_logs.empty()) return 3;
  } catch (const std::exception& e) {
    std::cerr << "vtrack-eval: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
