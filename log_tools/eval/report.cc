#include "log_tools/eval/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include "log_tools/eval/json_writer.h"
#include "log_tools/eval/plot.h"

namespace vtrack::eval {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string Csv(double v) {
  if (!std::isfinite(v)) return "";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

// The typical time between scored scans, to break plotted lines where a series has a gap.
double TypicalScanGap(const EvalSummary& s) {
  std::vector<double> gaps;
  for (std::size_t i = 1; i < s.per_scan.size(); ++i) {
    gaps.push_back(s.per_scan[i].t_s - s.per_scan[i - 1].t_s);
  }
  if (gaps.empty()) return 1.0;
  std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
  return gaps[gaps.size() / 2];
}

// Appends (x, y), with a NaN point first if x is far from the previous x (a gap).
void AppendPoint(Series* s, double x, double y, double max_gap) {
  if (!s->x.empty() && x - s->x.back() > max_gap) {
    s->x.push_back(x);
    s->y.push_back(kNaN);
  }
  s->x.push_back(x);
  s->y.push_back(y);
}

// Mean of |f(pair)| over the matched pairs of each scan, as a series over time.
template <class F>
Series PerScanMean(const EvalSummary& s, F f, const std::string& name, cv::Scalar color) {
  Series out;
  out.name = name;
  out.color = color;
  const double gap = 1.5 * TypicalScanGap(s);
  std::size_t i = 0;
  while (i < s.pairs.size()) {
    const std::int64_t utime = s.pairs[i].utime;
    double sum = 0.0;
    int n = 0;
    const double t = s.pairs[i].t_s;
    for (; i < s.pairs.size() && s.pairs[i].utime == utime; ++i) {
      sum += std::abs(f(s.pairs[i]));
      ++n;
    }
    AppendPoint(&out, t, sum / n, gap);
  }
  return out;
}

}  // namespace

std::string HorizonKey(double horizon_s) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", horizon_s);
  return buf;
}

namespace {
std::string Fixed(double v, int decimals) {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}
}  // namespace

std::string SummaryText(const EvalSummary& s) {
  std::ostringstream os;
  const auto& c = s.clear;
  os << "mode " << s.mode << ": " << s.scans << " scans scored, " << c.gt_objects
     << " truth objects (" << c.gt_detections << " detections), " << s.scored_tracks
     << " tracks\n";
  os << "  CLEAR MOT  MOTA " << Fixed(c.mota, 3) << "  MOTP " << Fixed(c.motp_m, 3) << " m  TP "
     << c.true_positives << "  FP " << c.false_positives << "  FN " << c.false_negatives
     << "  ID switches " << c.id_switches << "  fragmentations " << c.fragmentations << "\n";
  if (s.dont_care_track_detections > 0) {
    os << "             " << s.dont_care_track_detections
       << " unmatched track detections in KITTI DontCare regions not counted as FP\n";
  }
  os << "             mostly tracked " << c.mostly_tracked << "  partially " << c.partially_tracked
     << "  mostly lost " << c.mostly_lost << "\n";
  os << "  HOTA " << Fixed(s.hota.hota, 3) << "  DetA " << Fixed(s.hota.deta, 3) << "  AssA "
     << Fixed(s.hota.assa, 3) << "  LocA " << Fixed(s.hota.loca, 3) << "\n";
  os << "  RMSE  position " << Fixed(s.position_rmse_m, 3) << " m  heading "
     << Fixed(s.heading_rmse_deg, 2) << " deg (flipped " << Fixed(100.0 * s.heading_flip_fraction, 1)
     << " %)  speed " << Fixed(s.speed_rmse_mps, 3) << " m/s  yaw rate "
     << Fixed(s.yaw_rate_rmse_dps, 2) << " deg/s  rear axle L " << Fixed(s.rear_axle_rmse_m, 3)
     << " m (" << s.rear_axle_samples << " samples)\n";
  os << "  prediction error";
  for (std::size_t h = 0; h < s.params.horizons_s.size(); ++h) {
    os << "  " << HorizonKey(s.params.horizons_s[h]) << " s: " << Fixed(s.prediction_error_m[h], 3)
       << " m (" << s.prediction_samples[h] << ")";
  }
  os << "\n";
  for (const bool turning : {true, false}) {
    const auto& err = turning ? s.prediction_error_turning_m : s.prediction_error_straight_m;
    const auto& n = turning ? s.prediction_samples_turning : s.prediction_samples_straight;
    os << (turning ? "    truth turning " : "    truth straight");
    for (std::size_t h = 0; h < s.params.horizons_s.size() && h < err.size(); ++h) {
      os << "  " << HorizonKey(s.params.horizons_s[h]) << " s: " << Fixed(err[h], 3) << " m ("
         << n[h] << ")";
    }
    os << "\n";
  }
  os << "  NEES mean " << Fixed(s.nees_mean, 2) << " (3 if consistent), within 95 % bound "
     << Fixed(100.0 * s.nees_within_95, 1) << " % (" << s.nees_samples << " samples)\n";
  if (s.scans_without_tracks > 0 || s.tracks_without_truth > 0) {
    os << "  not scored: " << s.scans_without_tracks << " ground-truth scans without tracks, "
       << s.tracks_without_truth << " track lists without ground truth\n";
  }
  for (const auto& [k, v] : s.problems) os << "  input problem: " << k << " x " << v << "\n";
  return os.str();
}

std::string ComparisonTable(const std::vector<TableRow>& rows) {
  struct Column {
    std::string head;
    std::function<std::string(const EvalSummary&)> value;
  };
  std::vector<Column> cols = {
      {"scans", [](const EvalSummary& s) { return std::to_string(s.scans); }},
      {"GT", [](const EvalSummary& s) { return std::to_string(s.clear.gt_objects); }},
      {"MOTA", [](const EvalSummary& s) { return Fixed(s.clear.mota, 3); }},
      {"MOTP[m]", [](const EvalSummary& s) { return Fixed(s.clear.motp_m, 3); }},
      {"IDSW", [](const EvalSummary& s) { return std::to_string(s.clear.id_switches); }},
      {"Frag", [](const EvalSummary& s) { return std::to_string(s.clear.fragmentations); }},
      {"MT", [](const EvalSummary& s) { return std::to_string(s.clear.mostly_tracked); }},
      {"ML", [](const EvalSummary& s) { return std::to_string(s.clear.mostly_lost); }},
      {"HOTA", [](const EvalSummary& s) { return Fixed(s.hota.hota, 3); }},
      {"pos[m]", [](const EvalSummary& s) { return Fixed(s.position_rmse_m, 3); }},
      {"head[deg]", [](const EvalSummary& s) { return Fixed(s.heading_rmse_deg, 2); }},
      {"speed[m/s]", [](const EvalSummary& s) { return Fixed(s.speed_rmse_mps, 3); }},
      {"yawr[deg/s]", [](const EvalSummary& s) { return Fixed(s.yaw_rate_rmse_dps, 2); }},
      {"L[m]", [](const EvalSummary& s) { return Fixed(s.rear_axle_rmse_m, 3); }},
  };
  // Prediction columns for the horizons of the first row.
  if (!rows.empty() && rows.front().summary) {
    const auto& hs = rows.front().summary->params.horizons_s;
    for (std::size_t h = 0; h < hs.size(); ++h) {
      cols.push_back({"pred" + HorizonKey(hs[h]) + "s[m]", [h](const EvalSummary& s) {
                        return h < s.prediction_error_m.size() ? Fixed(s.prediction_error_m[h], 3)
                                                               : std::string("-");
                      }});
    }
  }
  cols.push_back({"NEES", [](const EvalSummary& s) { return Fixed(s.nees_mean, 2); }});
  cols.push_back({"NEES<95%", [](const EvalSummary& s) { return Fixed(s.nees_within_95, 3); }});

  std::vector<std::vector<std::string>> cells;
  std::vector<std::string> head = {"scenario", "mode"};
  for (const auto& c : cols) head.push_back(c.head);
  cells.push_back(head);
  for (const auto& r : rows) {
    std::vector<std::string> line = {r.item, r.mode};
    for (std::size_t k = 0; k < cols.size(); ++k) {
      line.push_back(r.summary ? cols[k].value(*r.summary) : (k == 0 ? "failed" : "-"));
    }
    cells.push_back(line);
  }
  std::vector<std::size_t> width(head.size(), 0);
  for (const auto& line : cells) {
    for (std::size_t i = 0; i < line.size(); ++i) width[i] = std::max(width[i], line[i].size());
  }
  std::ostringstream os;
  for (std::size_t r = 0; r < cells.size(); ++r) {
    for (std::size_t i = 0; i < cells[r].size(); ++i) {
      const std::string& v = cells[r][i];
      const std::string pad(width[i] - v.size(), ' ');
      os << (i == 0 ? "" : "  ") << (i < 2 ? v + pad : pad + v);  // text left, numbers right
    }
    os << "\n";
    if (r == 0) {
      std::size_t total = 0;
      for (const auto w : width) total += w + 2;
      os << std::string(total - 2, '-') << "\n";
    }
  }
  return os.str();
}

void WriteTextFile(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot create '" + path + "'");
  out << text;
  out.close();
  if (!out) throw std::runtime_error("cannot write '" + path + "' (disk full?)");
}

std::string SummaryJson(const EvalSummary& s) {
  JsonWriter w;
  w.BeginObject();
  w.Key("mode").String(s.mode);
  w.Key("scans").Int(s.scans);
  w.Key("gt_objects").Int(s.clear.gt_objects);
  w.Key("gt_detections").Int(s.clear.gt_detections);
  w.Key("scored_tracks").Int(s.scored_tracks);
  w.Key("mota").Number(s.clear.mota);
  w.Key("motp_m").Number(s.clear.motp_m);
  w.Key("id_switches").Int(s.clear.id_switches);
  w.Key("fragmentations").Int(s.clear.fragmentations);
  w.Key("mostly_tracked").Int(s.clear.mostly_tracked);
  w.Key("partially_tracked").Int(s.clear.partially_tracked);
  w.Key("mostly_lost").Int(s.clear.mostly_lost);
  w.Key("true_positives").Int(s.clear.true_positives);
  w.Key("false_positives").Int(s.clear.false_positives);
  w.Key("false_negatives").Int(s.clear.false_negatives);
  w.Key("hota").Number(s.hota.hota);
  w.Key("deta").Number(s.hota.deta);
  w.Key("assa").Number(s.hota.assa);
  w.Key("loca").Number(s.hota.loca);
  w.Key("position_rmse_m").Number(s.position_rmse_m);
  w.Key("heading_rmse_deg").Number(s.heading_rmse_deg);
  w.Key("heading_flip_fraction").Number(s.heading_flip_fraction);
  w.Key("speed_rmse_mps").Number(s.speed_rmse_mps);
  w.Key("yaw_rate_rmse_dps").Number(s.yaw_rate_rmse_dps);
  w.Key("rear_axle_rmse_m").Number(s.rear_axle_rmse_m);
  w.Key("rear_axle_samples").Int(s.rear_axle_samples);
  w.Key("prediction_error_m").BeginObject();
  for (std::size_t h = 0; h < s.params.horizons_s.size(); ++h) {
    w.Key(HorizonKey(s.params.horizons_s[h])).Number(s.prediction_error_m[h]);
  }
  w.EndObject();
  w.Key("prediction_samples").BeginObject();
  for (std::size_t h = 0; h < s.params.horizons_s.size(); ++h) {
    w.Key(HorizonKey(s.params.horizons_s[h])).Int(s.prediction_samples[h]);
  }
  w.EndObject();
  // Split by the truth's motion over the horizon (EvalParams::turning_yaw_rate).
  const auto split = [&](const char* key, const std::vector<double>& err,
                         const std::vector<std::int64_t>& n) {
    w.Key(key).BeginObject();
    for (std::size_t h = 0; h < s.params.horizons_s.size() && h < err.size(); ++h) {
      w.Key(HorizonKey(s.params.horizons_s[h])).BeginObject();
      w.Key("error_m").Number(err[h]);
      w.Key("samples").Int(n[h]);
      w.EndObject();
    }
    w.EndObject();
  };
  split("prediction_turning", s.prediction_error_turning_m, s.prediction_samples_turning);
  split("prediction_straight", s.prediction_error_straight_m, s.prediction_samples_straight);
  w.Key("nees_mean").Number(s.nees_mean);
  w.Key("nees_within_95").Number(s.nees_within_95);
  w.Key("nees_samples").Int(s.nees_samples);
  w.Key("nees_invalid").Int(s.nees_invalid);
  w.Key("scans_without_tracks").Int(s.scans_without_tracks);
  w.Key("tracks_without_truth").Int(s.tracks_without_truth);
  w.Key("ignored_track_detections").Int(s.ignored_track_detections);
  w.Key("outside_region_track_detections").Int(s.outside_region_track_detections);
  w.Key("dont_care_track_detections").Int(s.dont_care_track_detections);
  w.Key("problems").BeginObject();
  for (const auto& [k, v] : s.problems) w.Key(k).Int(v);
  w.EndObject();
  w.Key("params").BeginObject();
  const EvalParams& p = s.params;
  w.Key("gate_m").Number(p.gate_m);
  w.Key("hota_gate_m").Number(p.hota_gate_m);
  w.Key("mostly_tracked_ratio").Number(p.mostly_tracked_ratio);
  w.Key("mostly_lost_ratio").Number(p.mostly_lost_ratio);
  w.Key("score_coasting").Bool(p.score_coasting);
  w.Key("region_range_m").Number(p.region_range_m);
  w.Key("region_fov_deg").Number(p.region_fov_deg);
  w.Key("region_camera").Bool(p.region_camera.has_value());
  w.Key("kitti_dont_care").Bool(p.dont_care.has_value());
  w.Key("truth_time_offset_s").Number(s.truth_time_offset_s);
  w.Key("max_truth_gap_s").Number(p.max_truth_gap_s);
  w.Key("moving_speed_mps").Number(p.moving_speed_mps);
  w.EndObject();
  w.Key("logs").BeginArray();
  for (const auto& l : s.logs) w.String(l);
  w.EndArray();
  w.EndObject();
  return w.str() + "\n";
}

std::string TrackCsv(const EvalSummary& s) {
  std::ostringstream os;
  os << "track_id,first_s,last_s,scans,matched,truth_id,truth_scans,id_switches,position_rmse_m,"
        "heading_rmse_deg,speed_rmse_mps,yaw_rate_rmse_dps,rear_axle_rmse_m,nees_mean";
  for (const double h : s.params.horizons_s) os << ",prediction_error_" << HorizonKey(h) << "s_m";
  os << "\n";
  for (const TrackRow& r : s.per_track) {
    os << r.track_id << ',' << Csv(r.first_s) << ',' << Csv(r.last_s) << ',' << r.scans << ','
       << r.matched << ',' << (r.truth_id >= 0 || r.truth_scans > 0 ? std::to_string(r.truth_id) : "")
       << ',' << r.truth_scans << ',' << r.id_switches << ',' << Csv(r.position_rmse_m) << ','
       << Csv(r.heading_rmse_deg) << ',' << Csv(r.speed_rmse_mps) << ','
       << Csv(r.yaw_rate_rmse_dps) << ',' << Csv(r.rear_axle_rmse_m) << ',' << Csv(r.nees_mean);
    for (const double e : r.prediction_error_m) os << ',' << Csv(e);
    os << "\n";
  }
  return os.str();
}

std::string TrackLabelCsv(const std::vector<TrackLabel>& labels) {
  std::ostringstream os;
  os << std::setprecision(12);
  const auto number = [&os](double v) -> std::ostream& {
    return std::isnan(v) ? os << "nan" : os << v;  // one spelling for every NaN ("-nan" too)
  };
  os << "utime,track_id,label,range_m,truth_id,truth_class,distance_m\n";
  for (const TrackLabel& r : labels) {
    os << r.utime << ',' << r.track_id << ',' << r.label << ',';
    number(r.range_m) << ',' << r.truth_id << ',' << r.truth_class << ',';
    number(r.distance_m) << '\n';
  }
  return os.str();
}

std::vector<std::string> WriteEvalPlots(const EvalSummary& s, const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir)) throw std::runtime_error("cannot create plot directory '" + dir + "'");
  std::vector<std::string> written;
  const double gap = 1.5 * TypicalScanGap(s);
  const std::string title = "vtrack-eval: mode " + s.mode;

  // 1. Errors over time, one line per truth object.
  {
    std::map<std::int64_t, std::array<Series, 3>> by_truth;
    for (const PairSample& p : s.pairs) {
      auto& ser = by_truth[p.truth_id];
      AppendPoint(&ser[0], p.t_s, p.position_error_m, gap);
      AppendPoint(&ser[1], p.t_s, p.heading_error_deg, gap);
      AppendPoint(&ser[2], p.t_s, p.speed_error_mps, gap);
    }
    Figure fig;
    fig.title = title + ": errors of matched tracks over time";
    fig.panel_width = 900;
    fig.panels.resize(3);
    fig.panels[0] = {"position error", "time [s]", "error [m]", {}, true};
    fig.panels[1] = {"heading error (mod 180 deg)", "time [s]", "error [deg]", {}, true};
    fig.panels[2] = {"speed error (track - truth)", "time [s]", "error [m/s]", {}, true};
    int i = 0;
    constexpr int kMaxNamed = 10;
    for (auto& [id, ser] : by_truth) {
      for (int k = 0; k < 3; ++k) {
        ser[k].color = i < kMaxNamed ? PaletteColor(i) : cv::Scalar(170, 170, 170);
        if (i < kMaxNamed && k == 0) ser[k].name = "truth " + std::to_string(id);
        if (i == kMaxNamed && k == 0) ser[k].name = "other truth";
        fig.panels[k].series.push_back(ser[k]);
      }
      ++i;
    }
    const std::string path = (fs::path(dir) / "errors_over_time.png").string();
    SaveFigure(fig, path);
    written.push_back(path);
  }
  // 2. Detection counts per scan.
  {
    Figure fig;
    fig.title = title + ": detection per scan";
    fig.panel_width = 900;
    Panel panel{"truth objects and CLEAR MOT outcomes", "time [s]", "count", {}, true};
    Series gt{"truth", {}, {}, PaletteColor(7)}, tp{"true positives", {}, {}, PaletteColor(2)},
        fp{"false positives", {}, {}, PaletteColor(3)}, fn{"false negatives", {}, {}, PaletteColor(1)},
        sw{"identity switches", {}, {}, PaletteColor(4), false, true};
    for (const ScanCounts& c : s.per_scan) {
      AppendPoint(&gt, c.t_s, c.gt, gap);
      AppendPoint(&tp, c.t_s, c.tp, gap);
      AppendPoint(&fp, c.t_s, c.fp, gap);
      AppendPoint(&fn, c.t_s, c.fn, gap);
      if (c.id_switches > 0) {
        sw.x.push_back(c.t_s);
        sw.y.push_back(c.id_switches);
      }
    }
    panel.series = {gt, tp, fp, fn, sw};
    fig.panels.push_back(panel);
    const std::string path = (fs::path(dir) / "detections_over_time.png").string();
    SaveFigure(fig, path);
    written.push_back(path);
  }
  // 3. Prediction error against the horizon.
  {
    Figure fig;
    fig.title = title + ": predicted-trajectory error";
    Panel panel{"mean error of the predicted centre", "horizon [s]", "error [m]", {}, true};
    Series ser{"mode " + s.mode, {}, {}, PaletteColor(0), true, true};
    for (std::size_t h = 0; h < s.params.horizons_s.size(); ++h) {
      ser.x.push_back(s.params.horizons_s[h]);
      ser.y.push_back(s.prediction_error_m[h]);
    }
    panel.series.push_back(ser);
    fig.panels.push_back(panel);
    const std::string path = (fs::path(dir) / "prediction_error.png").string();
    SaveFigure(fig, path);
    written.push_back(path);
  }
  return written;
}

void WriteModePlot(const std::string& title, const std::map<std::string, EvalSummary>& by_mode,
                   const std::string& path) {
  Figure fig;
  fig.title = title;
  fig.columns = 3;
  fig.panel_width = 520;
  fig.panel_height = 360;
  Panel pos{"position error (mean per scan)", "time [s]", "error [m]", {}, true};
  Panel head{"heading error (mean |err| per scan)", "time [s]", "error [deg]", {}, true};
  Panel pred{"predicted-trajectory error", "horizon [s]", "mean error [m]", {}, true};
  // A fixed colour per mode, the same in every figure.
  auto color = [](const std::string& mode) {
    if (mode == "ism") return PaletteColor(0);
    if (mode == "vasm") return PaletteColor(1);
    if (mode == "mht") return PaletteColor(2);
    if (mode == "cv") return PaletteColor(3);
    return PaletteColor(static_cast<int>(std::hash<std::string>{}(mode) % 6) + 4);
  };
  for (const auto& [mode, s] : by_mode) {
    pos.series.push_back(PerScanMean(s, [](const PairSample& p) { return p.position_error_m; },
                                     mode, color(mode)));
    head.series.push_back(PerScanMean(s, [](const PairSample& p) { return p.heading_error_deg; },
                                      mode, color(mode)));
    Series ps{mode, {}, {}, color(mode), true, true};
    for (std::size_t h = 0; h < s.params.horizons_s.size(); ++h) {
      ps.x.push_back(s.params.horizons_s[h]);
      ps.y.push_back(s.prediction_error_m[h]);
    }
    pred.series.push_back(ps);
  }
  fig.panels = {pos, head, pred};
  SaveFigure(fig, path);
}

}  // namespace vtrack::eval
