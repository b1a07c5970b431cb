#include "viewer/frame_assembler.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "viewer/msg_convert.h"

namespace vtrack::viewer {
namespace {

constexpr std::int64_t kJumpBackUs = 2'000'000;   // [us] a stream going back this far restarted
constexpr std::int64_t kKeepExtraUs = 1'500'000;  // [us] messages kept beyond lag + scan_match
constexpr std::int64_t kEgoTrailStepUs = 50'000;  // [us] ego path sampled at most at 20 Hz
constexpr std::size_t kMaxScans = 1024;           // bounds on buffered scans whatever the times
constexpr std::int64_t kMaxScanPoints = 16'000'000; // say: ~350 MB of points at most
constexpr std::size_t kMaxMessages = 4096;        // same for tracks / debug / truth messages

std::int64_t Seconds(double s) { return static_cast<std::int64_t>(std::llround(s * 1e6)); }

template <class Map>
void EraseBefore(Map* m, std::int64_t utime, std::size_t cap) {
  m->erase(m->begin(), m->lower_bound(utime));
  while (m->size() > cap) m->erase(m->begin());
}

void AppendIncreasing(TimedPath* path, std::int64_t utime, const Eigen::Vector2d& xy,
                      std::int64_t min_step_us = 1) {
  if (!xy.allFinite()) return;
  if (!path->empty() && utime - path->back().first < min_step_us) return;
  path->emplace_back(utime, xy);
}

void PruneTrail(TimedPath* path, std::int64_t from) {
  const auto it = std::lower_bound(path->begin(), path->end(), from,
                                   [](const auto& e, std::int64_t t) { return e.first < t; });
  path->erase(path->begin(), it);
}

}  // namespace

std::string AssemblerParams::FirstProblem() const {
  std::ostringstream os;
  auto bad = [&](const char* key, double v, const char* what) {
    os << "assembler." << key << " = " << v << ": " << what;
    return os.str();
  };
  if (lag_us < 0 || lag_us > 10'000'000) return bad("lag_us", lag_us, "must be in [0, 10 s]");
  if (scan_match_us < 0 || scan_match_us > 10'000'000)
    return bad("scan_match_us", scan_match_us, "must be in [0, 10 s]");
  if (auto_idle_us <= 0) return bad("auto_idle_us", auto_idle_us, "must be > 0");
  if (!(trail_s >= 0.0) || trail_s > 3600.0) return bad("trail_s", trail_s, "must be in [0, 3600] s");
  if (!(truth_ahead_s >= 0.0) || truth_ahead_s > 3600.0)
    return bad("truth_ahead_s", truth_ahead_s, "must be in [0, 3600] s");
  if (pose_span_us < 1'000'000) return bad("pose_span_us", pose_span_us, "must be >= 1 s");
  return {};
}

FrameAssembler::FrameAssembler(const AssemblerParams& params)
    : params_(params), poses_(params.pose_span_us) {
  if (const std::string err = params_.FirstProblem(); !err.empty()) throw std::invalid_argument(err);
}

void FrameAssembler::Advance(std::int64_t utime) { clock_ = std::max(clock_, utime); }

void FrameAssembler::CheckJumpBack(std::int64_t utime, std::int64_t* last_of_stream) {
  if (*last_of_stream != 0 && utime + kJumpBackUs < *last_of_stream) Reset();
  *last_of_stream = std::max(*last_of_stream, utime);
}

void FrameAssembler::Reset() {
  for (auto& f : Flush()) ready_.push_back(std::move(f));
  ++stats_.resets;
  clock_ = 0;
  last_scan_utime_ = 0;
  last_pose_utime_ = 0;
  last_tracks_clock_ = -1;
  last_emitted_ = -1;
  has_origin_ = false;
  scans_.clear();
  scan_points_ = 0;
  tracks_.clear();
  debug_.clear();
  truth_.clear();
  poses_.Clear();
  ego_trail_.clear();
  track_trails_.clear();
  truth_trails_.clear();
}

void FrameAssembler::Trigger(std::int64_t utime, bool by_tracks) {
  if (last_emitted_ >= 0 && utime <= last_emitted_) {
    // Equal utimes are one frame: a scan is then already in it, but a TRACKS message that came
    // after that frame went out without it has no frame, and is counted as such.
    if (utime < last_emitted_ || (by_tracks && !last_emitted_had_tracks_)) {
      ++stats_.late_dropped;
      if (by_tracks) ++stats_.late_tracks;
    }
    return;
  }
  const auto [it, inserted] = pending_.try_emplace(utime);
  if (inserted) it->second.deadline = std::max(utime, clock_) + params_.lag_us;
  if (!has_origin_ || utime < origin_) {
    origin_ = utime;
    has_origin_ = true;
  }
}

void FrameAssembler::SetTimeOrigin(std::int64_t utime) {
  origin_ = utime;
  has_origin_ = true;
}

void FrameAssembler::SetTruthPaths(std::map<std::int64_t, TimedPath> paths) {
  for (auto& [id, path] : paths) {
    std::stable_sort(path.begin(), path.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
  }
  known_truth_ = std::move(paths);
}

void FrameAssembler::AddScan(std::shared_ptr<const vtrack::ladar_scan_t> scan) {
  if (!scan) return;
  CheckJumpBack(scan->utime, &last_scan_utime_);
  Advance(scan->utime);
  scan_points_ += scan->npoints;
  scans_.push_back(scan);
  const bool tracks_quiet =
      last_tracks_clock_ < 0 || clock_ - last_tracks_clock_ > params_.auto_idle_us;
  if (params_.trigger == AssemblerParams::Trigger::kScans ||
      (params_.trigger == AssemblerParams::Trigger::kAuto && tracks_quiet)) {
    Trigger(scan->utime, false);
  }
  Prune();
}

void FrameAssembler::AddPose(const vtrack::pose_t& pose) {
  CheckJumpBack(pose.utime, &last_pose_utime_);
  const auto world_from_body = PoseFromMsg(pose);
  if (!world_from_body) {
    ++stats_.poses_refused;
    return;
  }
  Advance(pose.utime);
  if (poses_.Add(pose.utime, *world_from_body) != PoseHistory::AddResult::kOk) {
    ++stats_.poses_refused;
    return;
  }
  AppendIncreasing(&ego_trail_, pose.utime, world_from_body->translation().head<2>(),
                   kEgoTrailStepUs);
}

void FrameAssembler::AddTracks(std::shared_ptr<const vtrack::track_list_t> tracks) {
  if (!tracks) return;
  Advance(tracks->utime);
  tracks_[tracks->utime] = tracks;
  last_tracks_clock_ = clock_;
  for (const auto& t : tracks->tracks) {
    AppendIncreasing(&track_trails_[t.id], tracks->utime, Eigen::Vector2d(t.x, t.y));
  }
  if (params_.trigger != AssemblerParams::Trigger::kScans) Trigger(tracks->utime, true);
  Prune();
}

void FrameAssembler::AddDebug(std::shared_ptr<const vtrack::track_debug_t> debug) {
  if (!debug) return;
  Advance(debug->utime);
  debug_[debug->utime] = std::move(debug);
  Prune();
}

void FrameAssembler::AddTruth(std::shared_ptr<const vtrack::object_list_t> truth) {
  if (!truth) return;
  Advance(truth->utime);
  for (const auto& o : truth->objects) {
    AppendIncreasing(&truth_trails_[o.id], truth->utime, Eigen::Vector2d(o.x, o.y));
  }
  truth_[truth->utime] = std::move(truth);
  Prune();
}

void FrameAssembler::Prune() {
  // Keep what pending frames and the recent paths still need.
  std::int64_t oldest_needed = clock_;
  if (!pending_.empty()) oldest_needed = std::min(oldest_needed, pending_.begin()->first);
  const std::int64_t keep_from =
      std::min(clock_ - params_.lag_us - params_.scan_match_us - kKeepExtraUs,
               oldest_needed - params_.scan_match_us);
  while (!scans_.empty() && (scans_.front()->utime < keep_from || scans_.size() > kMaxScans ||
                              scan_points_ > kMaxScanPoints)) {
    scan_points_ -= scans_.front()->npoints;
    scans_.pop_front();
  }
  EraseBefore(&tracks_, keep_from, kMaxMessages);
  EraseBefore(&debug_, keep_from, kMaxMessages);
  EraseBefore(&truth_, keep_from, kMaxMessages);

  const std::int64_t trail_from = oldest_needed - Seconds(params_.trail_s) - params_.lag_us;
  PruneTrail(&ego_trail_, trail_from);
  for (auto* trails : {&track_trails_, &truth_trails_}) {
    for (auto it = trails->begin(); it != trails->end();) {
      PruneTrail(&it->second, trail_from);
      it = it->second.empty() ? trails->erase(it) : std::next(it);
    }
  }
}

std::vector<Eigen::Vector2d> FrameAssembler::Window(const TimedPath& path, std::int64_t from,
                                                    std::int64_t to) {
  std::vector<Eigen::Vector2d> out;
  auto it = std::lower_bound(path.begin(), path.end(), from,
                             [](const auto& e, std::int64_t t) { return e.first < t; });
  for (; it != path.end() && it->first <= to; ++it) out.push_back(it->second);
  return out;
}

FrameInputs FrameAssembler::Make(std::int64_t utime) const {
  FrameInputs f;
  f.utime = utime;
  f.time_origin_utime = has_origin_ ? origin_ : utime;
  const std::int64_t match_from = utime - params_.scan_match_us;

  std::map<std::string, std::shared_ptr<const vtrack::ladar_scan_t>> newest;
  for (const auto& s : scans_) {
    if (s->utime > utime || s->utime < match_from) continue;
    auto& n = newest[s->sensor_id];
    if (!n || s->utime >= n->utime) n = s;
  }
  for (auto& [id, s] : newest) f.scans.push_back(std::move(s));

  if (auto it = tracks_.upper_bound(utime); it != tracks_.begin()) {
    --it;
    if (it->first >= match_from) f.tracks = it->second;
  }
  if (const auto it = debug_.find(utime); it != debug_.end()) f.debug = it->second;
  {
    std::int64_t best = params_.scan_match_us + 1;
    for (auto it = truth_.lower_bound(match_from);
         it != truth_.end() && it->first <= utime + params_.scan_match_us; ++it) {
      const std::int64_t d = std::abs(it->first - utime);
      if (d < best) {
        best = d;
        f.truth = it->second;
      }
    }
  }
  f.poses = poses_;

  const std::int64_t trail_from = utime - Seconds(params_.trail_s);
  for (const auto& [id, path] : track_trails_) {
    auto w = Window(path, trail_from, utime - 1);  // the current centre is the track's own
    if (!w.empty()) f.track_trails[id] = std::move(w);
  }
  f.ego_trail = Window(ego_trail_, trail_from, utime);
  const bool known = !known_truth_.empty();
  const std::int64_t truth_to = known ? utime + Seconds(params_.truth_ahead_s) : utime;
  for (const auto& [id, path] : known ? known_truth_ : truth_trails_) {
    auto w = Window(path, trail_from, truth_to);
    if (!w.empty()) f.truth_paths[id] = std::move(w);
  }
  return f;
}

FrameInputs FrameAssembler::Emit(std::int64_t utime) {
  FrameInputs f = Make(utime);
  last_emitted_ = utime;
  last_emitted_had_tracks_ = f.tracks && f.tracks->utime == utime;
  ++stats_.frames;
  return f;
}

std::vector<FrameInputs> FrameAssembler::TakeReady() {
  std::vector<FrameInputs> out = std::move(ready_);
  ready_.clear();
  while (!pending_.empty() && pending_.begin()->second.deadline <= clock_) {
    out.push_back(Emit(pending_.begin()->first));
    pending_.erase(pending_.begin());
  }
  return out;
}

std::vector<FrameInputs> FrameAssembler::Flush() {
  std::vector<FrameInputs> out = std::move(ready_);
  ready_.clear();
  for (const auto& [t, p] : pending_) out.push_back(Emit(t));
  pending_.clear();
  return out;
}

}  // namespace vtrack::viewer
