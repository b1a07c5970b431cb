#include "log_tools/eval/kitti_mot.h"
#include "log_tools/eval/overlap.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace vtrack::eval::kitti_mot {

namespace {

using Point = std::array<double, 2>;  // (x, z)

double Cross(const Point& o, const Point& a, const Point& b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

double SignedArea(const std::vector<Point>& poly) {
  double s = 0.0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Point& a = poly[i];
    const Point& b = poly[(i + 1) % poly.size()];
    s += a[0] * b[1] - a[1] * b[0];
  }
  return 0.5 * s;
}

// The footprint's corners in the (x, z) plane, counter-clockwise (positive signed area).
std::vector<Point> Footprint(const Box3d& b) {
  const double c = std::cos(b.ry), s = std::sin(b.ry);
  std::vector<Point> p;
  for (const auto& [dx, dz] : {std::pair{0.5 * b.l, 0.5 * b.w}, std::pair{0.5 * b.l, -0.5 * b.w},
                              std::pair{-0.5 * b.l, -0.5 * b.w}, std::pair{-0.5 * b.l, 0.5 * b.w}}) {
    // Rotation about the camera's y axis: x' = c dx + s dz, z' = -s dx + c dz.
    p.push_back({b.x + c * dx + s * dz, b.z - s * dx + c * dz});
  }
  if (SignedArea(p) < 0.0) std::reverse(p.begin(), p.end());
  return p;
}

// Sutherland-Hodgman: the part of `subject` inside the convex counter-clockwise `clip`.
std::vector<Point> ClipConvex(std::vector<Point> subject, const std::vector<Point>& clip) {
  for (std::size_t k = 0; k < clip.size() && !subject.empty(); ++k) {
    const Point& a = clip[k];
    const Point& b = clip[(k + 1) % clip.size()];
    std::vector<Point> out;
    for (std::size_t i = 0; i < subject.size(); ++i) {
      const Point& s = subject[i];
      const Point& e = subject[(i + 1) % subject.size()];
      const double ds = Cross(a, b, s);
      const double de = Cross(a, b, e);
      if (ds >= 0.0) out.push_back(s);
      if ((ds >= 0.0) != (de >= 0.0)) {
        const double t = ds / (ds - de);
        out.push_back({s[0] + t * (e[0] - s[0]), s[1] + t * (e[1] - s[1])});
      }
    }
    subject = std::move(out);
  }
  return subject;
}

bool ValidBox(const Box3d& b) {
  for (const double v : {b.h, b.w, b.l}) {
    if (!(v > 0.0) || !std::isfinite(v)) return false;
  }
  return std::isfinite(b.x) && std::isfinite(b.y) && std::isfinite(b.z) && std::isfinite(b.ry);
}

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

double ParseNumber(const std::string& field, const std::string& where, const char* name) {
  const char* begin = field.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(begin, &end);
  if (end == begin || *end != '\0' || errno == ERANGE || !std::isfinite(v)) {
    throw std::runtime_error(where + ": " + name + " '" + field + "' is not a finite number");
  }
  return v;
}

std::int64_t ParseInteger(const std::string& field, const std::string& where, const char* name) {
  const double v = ParseNumber(field, where, name);
  if (v != std::trunc(v) || std::abs(v) > 1e15) {
    throw std::runtime_error(where + ": " + name + " '" + field + "' is not an integer");
  }
  return static_cast<std::int64_t>(v);
}

// 2-D overlap of a tracker box with a DontCare box, over the tracker box's area (devkit's
// boxoverlap(..., "a")).
double OverlapOverFirst(const KittiObject& a, const KittiObject& b) {
  return OverlapOfFirst({a.x1, a.y1, a.x2, a.y2}, {b.x1, b.y1, b.x2, b.y2});
}

// Rule 9 for one ground-truth trajectory: (matched tracker id or -1, ignored) per appearance.
// The devkit's loop, literally.
void CountTrajectory(const std::vector<std::pair<std::int64_t, bool>>& entries, Counts* c) {
  const std::size_t n = entries.size();
  auto id = [&](std::size_t k) { return entries[k].first; };
  auto ign = [&](std::size_t k) { return entries[k].second; };
  std::size_t n_ignored = 0;
  for (std::size_t k = 0; k < n; ++k) n_ignored += ign(k) ? 1 : 0;
  if (n == 0 || n_ignored == n) return;  // ignored throughout
  ++c->gt_trajectories;
  bool any = false;
  for (std::size_t k = 0; k < n; ++k) any = any || id(k) != -1;
  if (!any) {
    ++c->mostly_lost;
    return;
  }
  std::int64_t last = id(0);
  std::int64_t tracked = id(0) >= 0 ? 1 : 0;
  for (std::size_t f = 1; f < n; ++f) {
    if (ign(f)) {
      last = -1;
      continue;
    }
    if (last != id(f) && last != -1 && id(f) != -1 && id(f - 1) != -1) ++c->ids;
    if (f < n - 1 && id(f - 1) != id(f) && last != -1 && id(f) != -1 && id(f + 1) != -1) {
      ++c->frag;
    }
    if (id(f) != -1) {
      ++tracked;
      last = id(f);
    }
  }
  // The last appearance (the loop above leaves it to this test).
  if (n > 1 && id(n - 2) != id(n - 1) && last != -1 && id(n - 1) != -1 && !ign(n - 1)) ++c->frag;
  const double ratio = static_cast<double>(tracked) / static_cast<double>(n - n_ignored);
  if (ratio > 0.8) {
    ++c->mostly_tracked;
  } else if (ratio < 0.2) {
    ++c->mostly_lost;
  } else {
    ++c->partly_tracked;
  }
}

}  // namespace

double FootprintIntersection(const Box3d& a, const Box3d& b) {
  const std::vector<Point> inter = ClipConvex(Footprint(a), Footprint(b));
  if (inter.size() < 3) return 0.0;
  return std::max(0.0, SignedArea(inter));
}

double Iou3d(const Box3d& a, const Box3d& b) {
  if (!ValidBox(a) || !ValidBox(b)) return 0.0;
  // Height intervals [y - h, y] (y down: the box extends upwards from its bottom centre).
  const double overlap_h = std::min(a.y, b.y) - std::max(a.y - a.h, b.y - b.h);
  if (overlap_h <= 0.0) return 0.0;
  const double inter = FootprintIntersection(a, b) * overlap_h;
  if (inter <= 0.0) return 0.0;
  const double uni = a.l * a.w * a.h + b.l * b.w * b.h - inter;
  return uni > 0.0 ? std::min(1.0, inter / uni) : 0.0;
}

std::vector<KittiObject> ReadTrackingFile(const std::string& path, bool is_result,
                                          std::int64_t* last_frame) {
  if (last_frame != nullptr) *last_frame = -1;
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::vector<KittiObject> out;
  std::set<std::pair<std::int64_t, std::int64_t>> seen;  // (frame, id) of a result
  std::string text;
  int line_no = 0;
  while (std::getline(in, text)) {
    ++line_no;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    std::istringstream ss(text);
    std::vector<std::string> f;
    for (std::string tok; ss >> tok;) f.push_back(tok);
    if (f.empty()) continue;  // blank line
    const std::string where = path + ":" + std::to_string(line_no);
    if (f.size() != 17 && f.size() != 18) {
      throw std::runtime_error(where + ": " + std::to_string(f.size()) +
                               " fields, expected 17 (label) or 18 (with score): frame track_id "
                               "type truncated occluded alpha x1 y1 x2 y2 h w l x y z "
                               "rotation_y [score]");
    }
    const std::string type = Lower(f[2]);
    // Numbers are checked on every line, also of the types that are skipped.
    KittiObject o;
    o.line = line_no;
    o.frame = ParseInteger(f[0], where, "frame");
    o.track_id = ParseInteger(f[1], where, "track_id");
    o.truncation = static_cast<int>(std::trunc(ParseNumber(f[3], where, "truncated")));
    o.occlusion = static_cast<int>(std::trunc(ParseNumber(f[4], where, "occluded")));
    ParseNumber(f[5], where, "alpha");
    o.x1 = ParseNumber(f[6], where, "x1");
    o.y1 = ParseNumber(f[7], where, "y1");
    o.x2 = ParseNumber(f[8], where, "x2");
    o.y2 = ParseNumber(f[9], where, "y2");
    o.box.h = ParseNumber(f[10], where, "h");
    o.box.w = ParseNumber(f[11], where, "w");
    o.box.l = ParseNumber(f[12], where, "l");
    o.box.x = ParseNumber(f[13], where, "x");
    o.box.y = ParseNumber(f[14], where, "y");
    o.box.z = ParseNumber(f[15], where, "z");
    o.box.ry = ParseNumber(f[16], where, "rotation_y");
    o.score = f.size() == 18 ? ParseNumber(f[17], where, "score") : -1.0;
    if (o.frame < 0) throw std::runtime_error(where + ": negative frame " + f[0]);
    if (last_frame != nullptr) *last_frame = std::max(*last_frame, o.frame);

    if (type == "car") {
      o.type = ObjectType::kCar;
    } else if (type == "van") {
      o.type = ObjectType::kVan;
    } else if (type == "dontcare") {
      if (is_result) continue;
      o.type = ObjectType::kDontCare;
    } else {
      continue;
    }
    if (o.track_id == -1 && o.type != ObjectType::kDontCare) continue;
    if (o.type != ObjectType::kDontCare && !(o.box.h > 0.0 && o.box.w > 0.0 && o.box.l > 0.0)) {
      throw std::runtime_error(where + ": a " + f[2] + "'s box needs h, w and l > 0, got " + f[10] +
                               " " + f[11] + " " + f[12]);
    }
    if (is_result && !seen.emplace(o.frame, o.track_id).second) {
      throw std::runtime_error(where + ": track id " + std::to_string(o.track_id) +
                               " occurs twice in frame " + std::to_string(o.frame));
    }
    out.push_back(o);
  }
  if (in.bad()) throw std::runtime_error(path + ": read error");
  return out;
}

std::string Params::Validate() const {
  std::ostringstream os;
  if (!(min_iou > 0.0 && min_iou <= 1.0)) {
    os << "min_iou must be in (0, 1], got " << min_iou;
  } else if (!std::isfinite(min_height_px)) {
    os << "min_height_px must be finite, got " << min_height_px;
  } else if (!(dontcare_overlap >= 0.0 && dontcare_overlap <= 1.0)) {
    os << "dontcare_overlap must be in [0, 1], got " << dontcare_overlap;
  } else if (sample_points < 2) {
    os << "sample_points must be >= 2, got " << sample_points;
  }
  return os.str();
}

double Counts::Mota() const {
  return gt > 0 ? 1.0 - static_cast<double>(fn + fp + ids) / static_cast<double>(gt)
                : std::numeric_limits<double>::quiet_NaN();
}

double Counts::Moda() const {
  return gt > 0 ? 1.0 - static_cast<double>(fn + fp) / static_cast<double>(gt)
                : std::numeric_limits<double>::quiet_NaN();
}

double Counts::Motp() const {
  return Matches() > 0 ? iou_sum / static_cast<double>(Matches()) : 0.0;
}

double Counts::Recall() const {
  const std::int64_t d = Matches() + fn;
  return d > 0 && Matches() + fp > 0 ? static_cast<double>(Matches()) / static_cast<double>(d)
                                     : 0.0;
}

double Counts::Precision() const {
  const std::int64_t d = Matches() + fp;
  return d > 0 && Matches() + fn > 0 ? static_cast<double>(Matches()) / static_cast<double>(d)
                                     : 0.0;
}

double Counts::SMota(double recall) const {
  if (gt <= 0 || !(recall > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  const double g = static_cast<double>(gt);
  const double v =
      1.0 - (static_cast<double>(fn + fp + ids) - (1.0 - recall) * g) / (recall * g);
  return std::min(1.0, std::max(0.0, v));
}

Counts& Counts::operator+=(const Counts& o) {
  frames += o.frames;
  gt += o.gt;
  tp += o.tp;
  ignored_tp += o.ignored_tp;
  fn += o.fn;
  ignored_fn += o.ignored_fn;
  fp += o.fp;
  ignored_tracker += o.ignored_tracker;
  tracker_boxes += o.tracker_boxes;
  ids += o.ids;
  frag += o.frag;
  gt_trajectories += o.gt_trajectories;
  mostly_tracked += o.mostly_tracked;
  partly_tracked += o.partly_tracked;
  mostly_lost += o.mostly_lost;
  iou_sum += o.iou_sum;
  return *this;
}

std::vector<int> MatchMostPairsMinCost(const std::vector<double>& cost,
                                       const std::vector<bool>& allowed, int rows, int cols) {
  std::vector<int> result(static_cast<std::size_t>(std::max(rows, 0)), -1);
  if (rows <= 0 || cols <= 0) return result;
  // Hungarian method (shortest augmenting paths with potentials) on n <= m, the smaller side
  // as rows. A forbidden pair costs more than any set of allowed pairs can (n + 1 > n * 1),
  // so the optimum has the most allowed pairs, then the least cost; forbidden pairs in it are
  // dropped (the devkit's max_cost gating).
  const bool transpose = rows > cols;
  const int n = transpose ? cols : rows;
  const int m = transpose ? rows : cols;
  const double forbidden = static_cast<double>(n) + 1.0;
  auto c = [&](int i, int j) {  // 0-based, in the (n x m) orientation
    const std::size_t k = transpose ? static_cast<std::size_t>(j) * cols + i
                                    : static_cast<std::size_t>(i) * cols + j;
    return allowed[k] ? cost[k] : forbidden;
  };
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0);
  std::vector<int> p(m + 1, 0), way(m + 1, 0);
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::vector<double> minv(m + 1, inf);
    std::vector<bool> used(m + 1, false);
    do {
      used[j0] = true;
      const int i0 = p[j0];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double cur = c(i0 - 1, j - 1) - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      for (int j = 0; j <= m; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  for (int j = 1; j <= m; ++j) {
    if (p[j] == 0) continue;
    const int i = p[j] - 1, jj = j - 1;
    const int row = transpose ? jj : i;
    const int col = transpose ? i : jj;
    if (allowed[static_cast<std::size_t>(row) * cols + col]) result[row] = col;
  }
  return result;
}

RowsAfter RowsAfterFrame(const std::vector<KittiObject>& result, std::int64_t last_label_frame) {
  RowsAfter a;
  for (const KittiObject& o : result) {
    if (o.frame <= last_label_frame) continue;
    a.first_frame = a.count == 0 ? o.frame : std::min(a.first_frame, o.frame);
    a.last_frame = std::max(a.last_frame, o.frame);
    ++a.count;
  }
  return a;
}

PreparedSequence::PreparedSequence(std::string name, const std::vector<KittiObject>& gt,
                                   const std::vector<KittiObject>& result, const Params& params)
    : name_(std::move(name)), params_(params) {
  if (const std::string err = params.Validate(); !err.empty()) {
    throw std::runtime_error("invalid KITTI MOT parameter: " + err);
  }
  std::int64_t last = -1;
  for (const auto& o : gt) last = std::max(last, o.frame);
  for (const auto& o : result) last = std::max(last, o.frame);
  frames_.resize(static_cast<std::size_t>(last + 1));

  // Rule 3: a track's score is the mean of its rows' scores.
  std::map<std::int64_t, std::pair<double, int>> sums;
  for (const auto& o : result) {
    auto& s = sums[o.track_id];
    s.first += o.score;
    ++s.second;
  }
  std::vector<std::vector<const KittiObject*>> gt_of(frames_.size()), dc_of(frames_.size()),
      tr_of(frames_.size());
  for (const auto& o : gt) {
    (o.type == ObjectType::kDontCare ? dc_of : gt_of)[static_cast<std::size_t>(o.frame)].push_back(&o);
  }
  for (const auto& o : result) tr_of[static_cast<std::size_t>(o.frame)].push_back(&o);
  result_boxes_ = static_cast<std::int64_t>(result.size());

  for (std::size_t f = 0; f < frames_.size(); ++f) {
    Frame& fr = frames_[f];
    for (const KittiObject* g : gt_of[f]) {
      const bool ignored = g->occlusion > params.max_occlusion ||
                           g->truncation > params.max_truncation || g->type == ObjectType::kVan;
      fr.gt.push_back({g->track_id, ignored});
    }
    for (const KittiObject* t : tr_of[f]) {
      bool ignorable = t->type == ObjectType::kVan || std::abs(t->y1 - t->y2) <= params.min_height_px;
      for (const KittiObject* d : dc_of[f]) {
        if (ignorable) break;
        ignorable = OverlapOverFirst(*t, *d) > params.dontcare_overlap;
      }
      const auto& s = sums.at(t->track_id);
      fr.tracker.push_back({t->track_id, s.first / s.second, ignorable});
    }
    fr.iou.resize(fr.gt.size() * fr.tracker.size());
    for (std::size_t i = 0; i < gt_of[f].size(); ++i) {
      for (std::size_t j = 0; j < tr_of[f].size(); ++j) {
        fr.iou[i * tr_of[f].size() + j] = Iou3d(gt_of[f][i]->box, tr_of[f][j]->box);
      }
    }
  }
}

Counts PreparedSequence::Evaluate(double threshold, std::vector<double>* matched_scores) const {
  Counts c;
  c.frames = frames();
  // Per ground-truth trajectory, in order of appearance: (matched tracker id or -1, ignored).
  std::map<std::int64_t, std::vector<std::pair<std::int64_t, bool>>> traj;
  std::vector<double> cost;
  std::vector<bool> allowed;
  std::vector<int> active;
  for (const Frame& fr : frames_) {
    active.clear();
    for (std::size_t j = 0; j < fr.tracker.size(); ++j) {
      if (!(fr.tracker[j].mean_score < threshold)) active.push_back(static_cast<int>(j));
    }
    const int rows = static_cast<int>(fr.gt.size());
    const int cols = static_cast<int>(active.size());
    c.tracker_boxes += cols;
    cost.assign(static_cast<std::size_t>(rows) * cols, 0.0);
    allowed.assign(static_cast<std::size_t>(rows) * cols, false);
    for (int i = 0; i < rows; ++i) {
      for (int j = 0; j < cols; ++j) {
        const double d = 1.0 - fr.iou[static_cast<std::size_t>(i) * fr.tracker.size() + active[j]];
        cost[static_cast<std::size_t>(i) * cols + j] = d;
        allowed[static_cast<std::size_t>(i) * cols + j] = d <= 1.0 - params_.min_iou;
      }
    }
    const std::vector<int> match = MatchMostPairsMinCost(cost, allowed, rows, cols);
    std::vector<bool> col_matched(static_cast<std::size_t>(cols), false);
    for (int i = 0; i < rows; ++i) {
      const GtBox& g = fr.gt[i];
      std::int64_t tid = -1;
      if (match[i] >= 0) {
        const TrackerBox& t = fr.tracker[active[match[i]]];
        col_matched[match[i]] = true;
        tid = t.id;
        c.iou_sum += 1.0 - cost[static_cast<std::size_t>(i) * cols + match[i]];
        (g.ignored ? c.ignored_tp : c.tp) += 1;
        if (matched_scores) matched_scores->push_back(t.mean_score);
      } else {
        (g.ignored ? c.ignored_fn : c.fn) += 1;
      }
      traj[g.id].emplace_back(tid, g.ignored);
    }
    for (int j = 0; j < cols; ++j) {
      if (col_matched[j]) continue;
      (fr.tracker[active[j]].ignorable ? c.ignored_tracker : c.fp) += 1;
    }
  }
  c.gt = c.tp + c.fn;

  for (const auto& [gt_id, entries] : traj) CountTrajectory(entries, &c);
  return c;
}

void SampleThresholds(std::vector<double> scores, std::int64_t num_gt, int sample_points,
                      std::vector<double>* thresholds, std::vector<double>* recalls) {
  thresholds->clear();
  recalls->clear();
  if (scores.empty() || num_gt <= 0) return;
  std::sort(scores.begin(), scores.end(), std::greater<>());
  const double n = static_cast<double>(num_gt);
  const double step = 1.0 / (static_cast<double>(sample_points) - 1.0);
  double current = 0.0;
  std::vector<double> t, r;
  for (std::size_t i = 0; i < scores.size(); ++i) {
    const bool last = i + 1 == scores.size();
    const double l_recall = static_cast<double>(i + 1) / n;
    const double r_recall = last ? l_recall : static_cast<double>(i + 2) / n;
    if ((r_recall - current) < (current - l_recall) && !last) continue;
    t.push_back(scores[i]);
    r.push_back(current);
    current += step;
  }
  // The first one (recall 0) is dropped.
  thresholds->assign(t.begin() + 1, t.end());
  recalls->assign(r.begin() + 1, r.end());
}

Result Score(const std::vector<const PreparedSequence*>& sequences, const Params& params,
             const std::function<void(std::size_t, std::size_t)>& progress) {
  if (const std::string err = params.Validate(); !err.empty()) {
    throw std::runtime_error("invalid KITTI MOT parameter: " + err);
  }
  const double no_threshold = -std::numeric_limits<double>::infinity();
  auto evaluate = [&](double threshold, std::vector<double>* scores) {
    Counts sum;
    for (const PreparedSequence* s : sequences) sum += s->Evaluate(threshold, scores);
    return sum;
  };
  Result res;
  std::vector<double> scores;
  res.all_tracks = evaluate(no_threshold, &scores);
  std::vector<double> thresholds, recalls;
  SampleThresholds(scores, res.all_tracks.Matches() + res.all_tracks.fn, params.sample_points,
                   &thresholds, &recalls);
  const std::size_t passes = thresholds.size() + 2;
  if (progress) progress(1, passes);
  double best_mota = 0.0;
  double sum_mota = 0.0, sum_motp = 0.0, sum_smota = 0.0;
  for (std::size_t k = 0; k < thresholds.size(); ++k) {
    const Counts c = evaluate(thresholds[k], nullptr);
    SweepPoint p{thresholds[k], recalls[k], c.Mota(), c.Motp(), c.SMota(recalls[k])};
    res.sweep.push_back(p);
    // An undefined value (no ground truth) adds nothing.
    if (std::isfinite(p.mota)) sum_mota += p.mota;
    if (std::isfinite(p.motp)) sum_motp += p.motp;
    if (std::isfinite(p.smota)) sum_smota += p.smota;
    if (p.mota > best_mota) {
      best_mota = p.mota;
      res.best_threshold = p.threshold;
      res.thresholded = true;
    }
    if (progress) progress(k + 2, passes);
  }
  const double points = static_cast<double>(params.sample_points) - 1.0;
  res.samota = sum_smota / points;
  res.amota = sum_mota / points;
  res.amotp = sum_motp / points;
  res.best = res.thresholded ? evaluate(res.best_threshold, nullptr) : res.all_tracks;
  if (progress) progress(passes, passes);
  return res;
}

}  // namespace vtrack::eval::kitti_mot
