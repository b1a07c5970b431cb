// Scoring of a tracker output log against the ground truth of a simulation log, for the
// tracker's integration tests and for the figures in tracker/README.md. Independent of the
// tracker's code: it reads only the messages (GROUND_TRUTH, EGO_POSE, TRACKS).
//
// Per scan (joined by utime): ground-truth vehicles (car, van, truck, skid-steer) inside the
// labelled region and within max_range of the ego are matched one to one with the tracks that
// are not tentative, by centre distance (gate), minimum total distance. A vehicle counts as
// "due" from in_view_delay_s after the first scan in which it had LADAR returns, as long as it
// had returns within the last occlusion_grace_s (an occluded vehicle is not due); a due vehicle
// without a match is a miss. A vehicle out of view (no returns) for longer than
// reacquire_after_s (a moving vehicle; reacquire_parked_after_s one that is not) comes into view
// anew when it has returns again: its first second in view starts over. These are the tracker's
// coast limits (vtrack-tracker deletes a mover's track after coast_max_s, 1.5 s, a parked one's
// after parked_coast_max_s, 3 s): a vehicle hidden for longer is not expected to be held. The
// car that passes behind a parked row in the tests' lap is seen at 60 m, hidden for 2.6 s, and
// seen again at 32 m by 3 returns.
// An identity switch is a change of the track id matched to a vehicle.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "vtrack/track_list_t.hpp"

namespace vtrack::testing {

struct EvalOptions {
  double max_range = 40.0;       // [m] vehicles farther from the ego are not scored
  double in_view_delay_s = 1.0;  // [s] grace period after a vehicle first has returns
  double gate = 2.0;             // [m] centre distance for a match
  double occlusion_grace_s = 0.5;  // [s] a vehicle without returns for longer is not due
  double reacquire_after_s = 1.5;  // [s] ... and one without for longer is new in view (<= 0: never)
  double reacquire_parked_after_s = 3.0;  // [s] the same for a vehicle not moving (<= 0: never)
  std::int64_t trace_vehicle = -1;  // [-] if >= 0: EvalResult::trace describes this vehicle per scan
};

struct EvalResult {
  std::int64_t scans = 0;           // scans with both truth and tracks
  std::int64_t due = 0;             // (vehicle, scan) pairs that must be tracked
  std::int64_t matched = 0;         // of those, matched
  std::int64_t id_switches = 0;
  double position_rmse = 0.0;       // [m] over matched pairs
  double heading_rmse_deg = 0.0;    // [deg] axis error, modulo 180 deg, over matched pairs
  double mover_heading_rmse_deg = 0.0;  // [deg] full heading error of moving vehicles
  // Hypothesis counts seen on tracks: max over tracks judged stationary / moving, and over
  // tracks matched to vehicles that never move.
  int max_hyps_not_moving = 0;
  int max_hyps_moving = 0;
  int max_hyps_stationary_truth = 0;
  std::vector<std::string> misses;  // first few misses, described
  std::vector<std::string> stationary_multi;  // first few parked vehicles on multi-hypothesis tracks
  // First few identity switches, described: time, vehicle (size, speed, range), due or not, the
  // old and new track (distance to the vehicle, size, whether the old one is still reported).
  std::vector<std::string> switches;
  // EvalOptions::trace_vehicle per scan: its state and every track within 5 m.
  std::vector<std::string> trace;
  std::map<std::int64_t, std::vector<std::int64_t>> ids;  // vehicle -> track ids in order
  std::map<std::int64_t, double> vehicle_pos_rmse;        // [m] per vehicle
  std::map<std::int64_t, double> vehicle_heading_rmse_deg;  // [deg] axis error per vehicle
  std::map<std::int64_t, std::int64_t> vehicle_due, vehicle_missed;  // due pairs, and those missed
};

// The TRACKS messages of the log at path, by utime (those that do not decode are left out).
std::map<std::int64_t, track_list_t> TracksByUtime(const std::string& path);

// truth_log: a log with GROUND_TRUTH and EGO_POSE (vtrack-sim-log). tracks_log: TRACKS.
// Throws std::runtime_error if a log cannot be read.
EvalResult EvaluateTracks(const std::string& truth_log, const std::string& tracks_log,
                          const EvalOptions& options = EvalOptions());

// "due 123, matched 120 (97.6%), id switches 0, pos RMSE 0.21 m, heading RMSE 1.2 deg".
std::string Summary(const EvalResult& r);

}  // namespace vtrack::testing
