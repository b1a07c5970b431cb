#include "tests/integration/tracker_eval.h"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <limits>
#include <set>
#include <stdexcept>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/log_reader.h"
#include "base/angle.h"
#include "base/assignment.h"
#include "vtrack/object_list_t.hpp"
#include "vtrack/pose_t.hpp"
#include "vtrack/track_list_t.hpp"

namespace vtrack::testing {
namespace {

bool IsVehicle(int8_t c) {
  return c == object_t::CLASS_CAR || c == object_t::CLASS_VAN || c == object_t::CLASS_TRUCK ||
         c == object_t::CLASS_SKID_STEER;
}

}  // namespace

std::map<std::int64_t, track_list_t> TracksByUtime(const std::string& path) {
  std::map<std::int64_t, track_list_t> m;
  lcm_util::LogReader r(path);
  while (const lcm::LogEvent* ev = r.Next()) {
    if (ev->channel != "TRACKS") continue;
    track_list_t t;
    if (lcm_util::Decode(ev->data, static_cast<std::size_t>(ev->datalen), &t) ==
        lcm_util::DecodeError::kNone) {
      m[t.utime] = std::move(t);
    }
  }
  return m;
}

EvalResult EvaluateTracks(const std::string& truth_log, const std::string& tracks_log,
                          const EvalOptions& opt) {
  std::map<std::int64_t, object_list_t> truth;
  std::map<std::int64_t, Eigen::Vector2d> ego;
  {
    lcm_util::LogReader r(truth_log);
    while (const lcm::LogEvent* ev = r.Next()) {
      if (ev->channel == "GROUND_TRUTH") {
        object_list_t m;
        if (lcm_util::Decode(ev->data, static_cast<std::size_t>(ev->datalen), &m) ==
            lcm_util::DecodeError::kNone) {
          truth[m.utime] = std::move(m);
        }
      } else if (ev->channel == "EGO_POSE") {
        pose_t p;
        if (lcm_util::Decode(ev->data, static_cast<std::size_t>(ev->datalen), &p) ==
            lcm_util::DecodeError::kNone) {
          ego[p.utime] = Eigen::Vector2d(p.pos[0], p.pos[1]);
        }
      }
    }
  }
  const std::map<std::int64_t, track_list_t> tracks = TracksByUtime(tracks_log);
  EvalResult res;
  std::map<std::int64_t, std::int64_t> first_seen;  // vehicle -> utime of first returns (in view anew)
  std::map<std::int64_t, std::int64_t> last_seen;   // vehicle -> utime of latest returns
  std::map<std::int64_t, double> per_n, per_pos, per_head;
  std::int64_t pairs = 0;  // every matched (vehicle, scan), due or not: for the RMSEs
  double pos_sq = 0.0, head_sq = 0.0, mover_head_sq = 0.0;
  std::int64_t mover_n = 0;
  for (const auto& [utime, gt] : truth) {
    for (const auto& o : gt.objects) {
      if (o.num_points == 0) continue;
      const auto ls = last_seen.find(o.id);
      const double reacquire = o.moving ? opt.reacquire_after_s : opt.reacquire_parked_after_s;
      if (ls == last_seen.end() ||
          (reacquire > 0.0 && utime - ls->second > static_cast<std::int64_t>(reacquire * 1e6))) {
        first_seen[o.id] = utime;
      }
      last_seen[o.id] = utime;
    }
    const auto tl = tracks.find(utime);
    if (tl == tracks.end()) continue;
    ++res.scans;
    Eigen::Vector2d ego_xy = Eigen::Vector2d::Zero();
    if (!ego.empty()) {
      auto it = ego.lower_bound(utime);
      if (it == ego.end()) it = std::prev(it);
      ego_xy = it->second;
    }
    for (const auto& t : tl->second.tracks) {
      if (t.moving) res.max_hyps_moving = std::max(res.max_hyps_moving, t.num_hypotheses);
      else res.max_hyps_not_moving = std::max(res.max_hyps_not_moving, t.num_hypotheses);
    }
    std::vector<const object_t*> vehicles;
    for (const auto& o : gt.objects) {
      if (!IsVehicle(o.object_class) || !o.in_labelled_region) continue;
      if ((Eigen::Vector2d(o.x, o.y) - ego_xy).norm() > opt.max_range) continue;
      vehicles.push_back(&o);
    }
    std::vector<const track_t*> cands;
    for (const auto& t : tl->second.tracks) {
      if (t.status != track_t::STATUS_TENTATIVE) cands.push_back(&t);
    }
    // One-to-one assignment by centre distance (rows = vehicles, plus a "none" column each).
    const int rows = static_cast<int>(vehicles.size());
    const int cols = static_cast<int>(cands.size()) + rows;
    std::vector<double> cost(static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols), 1e6);
    for (int i = 0; i < rows; ++i) {
      cost[static_cast<std::size_t>(i * cols + static_cast<int>(cands.size()) + i)] = opt.gate;
      for (std::size_t j = 0; j < cands.size(); ++j) {
        const double d = std::hypot(cands[j]->x - vehicles[static_cast<std::size_t>(i)]->x,
                                    cands[j]->y - vehicles[static_cast<std::size_t>(i)]->y);
        if (d < opt.gate) cost[static_cast<std::size_t>(i * cols) + j] = d;
      }
    }
    const std::vector<int> assign = rows > 0 ? SolveAssignment(cost, rows, cols) : std::vector<int>{};
    for (int i = 0; i < rows; ++i) {
      const object_t& o = *vehicles[static_cast<std::size_t>(i)];
      const int j = assign[static_cast<std::size_t>(i)];
      const bool matched = j >= 0 && j < static_cast<int>(cands.size()) &&
                           cost[static_cast<std::size_t>(i * cols + j)] < opt.gate;
      if (o.id == opt.trace_vehicle) {
        char buf[300];
        std::snprintf(buf, sizeof(buf), "t=%.2f s: vehicle %lld at (%.2f, %.2f) yaw %.0f deg, %d returns, %.1f m from ego; matched %lld",
                      (utime - truth.begin()->first) * 1e-6, static_cast<long long>(o.id), o.x, o.y,
                      RadToDeg(o.yaw), o.num_points, (Eigen::Vector2d(o.x, o.y) - ego_xy).norm(),
                      j >= 0 && j < static_cast<int>(cands.size()) ? static_cast<long long>(cands[static_cast<std::size_t>(j)]->id) : -1LL);
        res.trace.push_back(buf);
        for (const auto& t : tl->second.tracks) {
          const double d = std::hypot(t.x - o.x, t.y - o.y);
          if (d > 5.0) continue;
          std::snprintf(buf, sizeof(buf), "    track %lld at %.2f m: (%.2f, %.2f) theta %.0f deg, %.1f x %.1f m, status %d, class %d, %.1f m/s, %d updates, %d hyps",
                        static_cast<long long>(t.id), d, t.x, t.y, RadToDeg(t.theta), t.length, t.width, t.status,
                        t.object_class, t.speed, t.num_updates, t.num_hypotheses);
          res.trace.push_back(buf);
        }
      }
      const auto fs = first_seen.find(o.id);
      const auto ls = last_seen.find(o.id);
      const bool due = fs != first_seen.end() &&
                       utime - fs->second >= static_cast<std::int64_t>(opt.in_view_delay_s * 1e6) &&
                       utime - ls->second <= static_cast<std::int64_t>(opt.occlusion_grace_s * 1e6);
      if (due) {
        ++res.due;
        ++res.vehicle_due[o.id];
        if (!matched) ++res.vehicle_missed[o.id];
      }
      if (!matched) {
        if (due && res.misses.size() < 20) {
          char buf[200];
          std::snprintf(buf, sizeof(buf), "t=%.2f s: vehicle %lld at (%.1f, %.1f) not tracked",
                        (utime - truth.begin()->first) * 1e-6, static_cast<long long>(o.id), o.x, o.y);
          res.misses.push_back(buf);
        }
        continue;
      }
      const track_t& t = *cands[static_cast<std::size_t>(j)];
      if (due) ++res.matched;
      auto& ids = res.ids[o.id];
      const double d = std::hypot(t.x - o.x, t.y - o.y);
      if (ids.empty() || ids.back() != t.id) {
        if (!ids.empty()) {
          ++res.id_switches;
          if (res.switches.size() < 40) {
            const std::int64_t old_id = ids.back();
            const track_t* old = nullptr;
            for (const auto& c : tl->second.tracks) {
              if (c.id == old_id) old = &c;
            }
            char old_desc[160] = "no longer reported";
            if (old) {
              std::snprintf(old_desc, sizeof(old_desc), "at %.2f m, %.1f x %.1f m, status %d, %d hyps",
                            std::hypot(old->x - o.x, old->y - o.y), old->length, old->width,
                            old->status, old->num_hypotheses);
            }
            char buf[400];
            std::snprintf(buf, sizeof(buf),
                          "t=%.2f s: vehicle %lld (%.1f x %.1f m, %.1f m/s, %.1f m from ego, %s) "
                          "track %lld -> %lld (at %.2f m, %.1f x %.1f m, age %.1f s, %d hyps); old %s",
                          (utime - truth.begin()->first) * 1e-6, static_cast<long long>(o.id),
                          o.length, o.width, o.speed, (Eigen::Vector2d(o.x, o.y) - ego_xy).norm(),
                          due ? "due" : "not yet due", static_cast<long long>(old_id),
                          static_cast<long long>(t.id), d, t.length, t.width, t.age,
                          t.num_hypotheses, old_desc);
            res.switches.push_back(buf);
          }
        }
        ids.push_back(t.id);
      }
      if (!due) continue;  // errors are scored from the first second in view on, like misses
      ++pairs;
      pos_sq += d * d;
      per_n[o.id] += 1;
      per_pos[o.id] += d * d;
      const double axis = std::abs(AngleDiff(2.0 * t.theta, 2.0 * o.yaw)) / 2.0;
      head_sq += axis * axis;
      per_head[o.id] += axis * axis;
      if (o.moving && std::abs(o.speed) > 1.0) {
        const double full = AngleDiff(t.theta, o.yaw);
        mover_head_sq += full * full;
        ++mover_n;
      }
      if (!o.moving) {
        res.max_hyps_stationary_truth = std::max(res.max_hyps_stationary_truth, t.num_hypotheses);
        if (t.num_hypotheses > 1 && res.stationary_multi.size() < 10) {
          char buf[200];
          std::snprintf(buf, sizeof(buf), "t=%.2f s: parked vehicle %lld on track %lld (%d hypotheses, speed %.2f)",
                        (utime - truth.begin()->first) * 1e-6, static_cast<long long>(o.id),
                        static_cast<long long>(t.id), t.num_hypotheses, t.speed);
          res.stationary_multi.push_back(buf);
        }
      }
    }
  }
  for (const auto& [id, c] : per_n) {
    res.vehicle_pos_rmse[id] = std::sqrt(per_pos[id] / c);
    res.vehicle_heading_rmse_deg[id] = RadToDeg(std::sqrt(per_head[id] / c));
  }
  const double n = static_cast<double>(std::max<std::int64_t>(1, pairs));
  res.position_rmse = std::sqrt(pos_sq / n);
  res.heading_rmse_deg = RadToDeg(std::sqrt(head_sq / n));
  res.mover_heading_rmse_deg =
      mover_n > 0 ? RadToDeg(std::sqrt(mover_head_sq / static_cast<double>(mover_n))) : 0.0;
  return res;
}

std::string Summary(const EvalResult& r) {
  char buf[300];
  std::snprintf(buf, sizeof(buf),
                "due %lld, matched %lld (%.1f%%), id switches %lld, pos RMSE %.3f m, heading RMSE "
                "%.2f deg (axis), mover heading RMSE %.2f deg, max hyps: not moving %d, moving %d",
                static_cast<long long>(r.due), static_cast<long long>(r.matched),
                r.due ? 100.0 * static_cast<double>(r.matched) / static_cast<double>(r.due) : 100.0,
                static_cast<long long>(r.id_switches), r.position_rmse, r.heading_rmse_deg,
                r.mover_heading_rmse_deg, r.max_hyps_not_moving, r.max_hyps_moving);
  return buf;
}

}  // namespace vtrack::testing
