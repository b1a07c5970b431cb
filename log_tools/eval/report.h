// What vtrack-eval and vtrack-compare write: the JSON summary, the per-track CSV and the plots.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "log_tools/eval/evaluator.h"

namespace vtrack::eval {

// The JSON summary of one evaluation (keys in log_tools/README.md). Undefined metrics are null.
std::string SummaryJson(const EvalSummary& s);
// Writes text to path; throws std::runtime_error naming the path on failure.
void WriteTextFile(const std::string& path, const std::string& text);

// One row per scored track: its span, matches, dominant truth object and errors.
std::string TrackCsv(const EvalSummary& s);

// The labelled set of Evaluate's labels: header
// utime,track_id,label,range_m,truth_id,truth_class,distance_m, one row per TrackLabel; NaN
// prints as "nan".
std::string TrackLabelCsv(const std::vector<TrackLabel>& labels);

// Writes errors_over_time.png, detections_over_time.png and prediction_error.png into dir
// (created if missing). Returns the paths written.
std::vector<std::string> WriteEvalPlots(const EvalSummary& s, const std::string& dir);

// One figure with the modes side by side: mean position and heading error per scan over time,
// and the prediction error against the horizon, one line per mode. Writes it to path.
void WriteModePlot(const std::string& title, const std::map<std::string, EvalSummary>& by_mode,
                   const std::string& path);

// The summary as text for a terminal: one metric per line.
std::string SummaryText(const EvalSummary& s);

// One table of several evaluations, a row per (item, mode), in the given order: the columns are
// the metrics of the JSON summary. Undefined values print as "-".
struct TableRow {
  std::string item, mode;
  const EvalSummary* summary = nullptr;
};
std::string ComparisonTable(const std::vector<TableRow>& rows);

// Key of a prediction horizon in the JSON ("1" for 1 s, "1.5" for 1.5 s).
std::string HorizonKey(double horizon_s);

}  // namespace vtrack::eval
