// tracks-compare: compares the TRACKS of two tracker runs on the same input, message by message
// and track by track, for changes that are meant to keep the tracker's decisions (a faster
// computation that rounds differently, a trajectory computed for fewer tracks).
//
//   tracks-compare A.lcm B.lcm [--channel TRACKS] [--tolerance M] [--pred-only-vehicles]
//
// Decisions must be equal: message count and utime, track ids in order, status, model, moving,
// class, hypothesis and update counts. Real-valued fields (positions [m], angles [rad],
// speeds [m/s], sizes [m], covariances, the predicted trajectory) may differ by at most
// --tolerance (default 0: bit for bit). --pred-only-vehicles: B may report no trajectory for a
// track A predicts, if the track is not a vehicle. latency_us (wall clock) is not compared.
// Prints the largest difference per field group; where decisions differ, also the first message
// that differs and the largest differences before it. Exit 0 equal within the tolerance, 1 not,
// 2 bad usage or unreadable logs.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <map>
#include <string>
#include <vector>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/log_reader.h"
#include "vtrack/track_list_t.hpp"

namespace {

std::vector<vtrack::track_list_t> ReadTracks(const std::string& path, const std::string& channel) {
  vtrack::lcm_util::LogReader reader(path);
  std::vector<vtrack::track_list_t> out;
  while (const lcm::LogEvent* e = reader.Next()) {
    if (e->channel != channel) continue;
    vtrack::track_list_t msg;
    std::string why;
    if (vtrack::lcm_util::Decode(e->data, static_cast<std::size_t>(e->datalen), &msg, &why) !=
        vtrack::lcm_util::DecodeError::kNone) {
      throw std::runtime_error(path + ": a " + channel + " event does not decode: " + why);
    }
    out.push_back(std::move(msg));
  }
  return out;
}

struct Comparison {
  double tolerance = 0.0;
  bool pred_only_vehicles = false;
  long decisions_differ = 0;   // messages or tracks whose decisions differ
  long preds_dropped = 0;      // non-vehicle tracks B reports without a trajectory
  std::map<std::string, double> max_diff;  // per field group: the largest |a - b|

  void Real(const char* group, double a, double b) {
    const bool both_nan = std::isnan(a) && std::isnan(b);
    const double d = both_nan ? 0.0 : (a == b ? 0.0 : std::abs(a - b));
    double& m = max_diff[group];
    m = std::isnan(d) ? INFINITY : std::max(m, d);
  }
  bool Within() const {
    for (const auto& [group, d] : max_diff) {
      if (!(d <= tolerance)) return false;
    }
    return decisions_differ == 0;
  }
};

void ComparePred(const vtrack::track_t& a, const vtrack::track_t& b, Comparison* c) {
  if (a.npred != b.npred) {
    if (c->pred_only_vehicles && b.npred == 0 && a.object_class != vtrack::track_t::CLASS_VEHICLE) {
      ++c->preds_dropped;
    } else {
      ++c->decisions_differ;
    }
    return;
  }
  for (int k = 0; k < a.npred; ++k) {
    c->Real("pred_t", a.pred_t[k], b.pred_t[k]);
    c->Real("pred_xy", a.pred_x[k], b.pred_x[k]);
    c->Real("pred_xy", a.pred_y[k], b.pred_y[k]);
    c->Real("pred_theta", a.pred_theta[k], b.pred_theta[k]);
    c->Real("pred_pos_std", a.pred_pos_std[k], b.pred_pos_std[k]);
  }
}

void CompareTrack(const vtrack::track_t& a, const vtrack::track_t& b, Comparison* c) {
  if (a.id != b.id || a.status != b.status || a.model != b.model || a.moving != b.moving ||
      a.object_class != b.object_class || a.num_hypotheses != b.num_hypotheses ||
      a.num_updates != b.num_updates) {
    ++c->decisions_differ;
    return;
  }
  c->Real("x_y", a.x, b.x);
  c->Real("x_y", a.y, b.y);
  c->Real("theta", a.theta, b.theta);
  c->Real("speed", a.speed, b.speed);
  c->Real("velocity_heading", a.velocity_heading, b.velocity_heading);
  c->Real("yaw_rate", a.yaw_rate, b.yaw_rate);
  c->Real("rear_axle_offset", a.rear_axle_offset, b.rear_axle_offset);
  c->Real("length_width", a.length, b.length);
  c->Real("length_width", a.width, b.width);
  for (int k = 0; k < 9; ++k) c->Real("cov", a.cov[k], b.cov[k]);
  c->Real("age", a.age, b.age);
  ComparePred(a, b, c);
}

int Usage(FILE* f, int status) {
  std::fprintf(f,
               "usage: tracks-compare A.lcm B.lcm [--channel TRACKS] [--tolerance M] "
               "[--pred-only-vehicles]\n");
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> logs;
  std::string channel = "TRACKS";
  Comparison c;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") return Usage(stdout, 0);
    if (arg == "--channel" && i + 1 < argc) {
      channel = argv[++i];
    } else if (arg == "--tolerance" && i + 1 < argc) {
      c.tolerance = std::atof(argv[++i]);
    } else if (arg == "--pred-only-vehicles") {
      c.pred_only_vehicles = true;
    } else if (!arg.empty() && arg[0] != '-') {
      logs.push_back(arg);
    } else {
      return Usage(stderr, 2);
    }
  }
  if (logs.size() != 2 || !(c.tolerance >= 0.0)) return Usage(stderr, 2);
  try {
    const auto a = ReadTracks(logs[0], channel), b = ReadTracks(logs[1], channel);
    long tracks = 0;
    // The first message with a decision differing, and max_diff over the messages before it.
    std::size_t first_differ = std::min(a.size(), b.size());
    std::map<std::string, double> diff_before;
    for (std::size_t m = 0; m < std::min(a.size(), b.size()); ++m) {
      const long before = c.decisions_differ;
      const bool first_unset = first_differ == std::min(a.size(), b.size());
      std::map<std::string, double> diff_so_far;
      if (first_unset) diff_so_far = c.max_diff;
      if (a[m].utime != b[m].utime || a[m].scan_seq != b[m].scan_seq || a[m].mode != b[m].mode ||
          a[m].num_tracks != b[m].num_tracks) {
        ++c.decisions_differ;
      } else {
        for (int k = 0; k < a[m].num_tracks; ++k) CompareTrack(a[m].tracks[k], b[m].tracks[k], &c);
        tracks += a[m].num_tracks;
      }
      if (c.decisions_differ > before && first_unset) {
        first_differ = m;
        diff_before = diff_so_far;
      }
    }
    if (a.size() != b.size() || a.empty()) ++c.decisions_differ;
    std::printf("tracks-compare: %zu / %zu messages, %ld tracks, %ld with different decisions, "
                "%ld non-vehicle trajectories dropped\n",
                a.size(), b.size(), tracks, c.decisions_differ, c.preds_dropped);
    if (first_differ < std::min(a.size(), b.size())) {
      std::printf("  the first decision differing is in message %zu (utime %lld); "
                  "the messages before it:\n",
                  first_differ, static_cast<long long>(a[first_differ].utime));
      for (const auto& [group, d] : diff_before) {
        std::printf("    max |diff| %-17s %.3g\n", group.c_str(), d);
      }
      std::printf("  all messages:\n");
    }
    for (const auto& [group, d] : c.max_diff) std::printf("  max |diff| %-17s %.3g\n", group.c_str(), d);
    const bool ok = c.Within();
    std::printf("tracks-compare: %s (tolerance %g)\n", ok ? "equal" : "DIFFERENT", c.tolerance);
    return ok ? 0 : 1;
  } catch (const std::exception& ex) {
    std::fprintf(stderr, "tracks-compare: %s\n", ex.what());
    return 2;
  }
}
