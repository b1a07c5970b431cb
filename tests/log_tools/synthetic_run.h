// A small synthetic run with known truth and tracks whose errors are set by construction, for the
// evaluator's tests (and the fake simulator/tracker that vtrack-compare's test drives).
//
// Truth, 10 Hz, kScans scans from kUtime0:
//   id 1 "A": a car whose rear axle drives a circle of radius kRadius at kSpeed (counter-clockwise,
//             starting at the origin heading +x), L = kRearAxle (axle behind the centre);
//   id 2 "B": a parked car at (10, -5), yaw 0.3;
//   id 3:     a pedestrian at (-10, 5)            (not a vehicle: ignored);
//   id 4:     a car at (30, 30) outside the labelled region (ignored).
// Plus one ground-truth scan at kUtime0 - 1 s with no track list (not scored).
// Ego pose: at the origin, yaw 0, every scan. One LADAR_SCAN (no points, sweep 100 ms, sensor at
// the body origin) for the mounting.
//
// Tracks (mode given), per scan:
//   1: on A, centre + (offset_m, 0), theta + 2 deg, speed + 0.5 m/s, yaw rate + 0.01 rad/s,
//      L + 0.1 m, cov diag(offset^2, 0.01, (2 deg)^2)  -> NEES 1 + 0 + 1 = 2;
//      predicted trajectory every 0.5 s to 3 s: A's true centre then + (1, 0) m;
//   2: on B exactly, theta flipped by 180 deg, ISM (L NaN), no prediction, cov diag(0.04,0.04,0.01);
//   3: CLASS_OTHER at (50, 50); 4: vehicle on the pedestrian + (0.2, 0); 5: vehicle on car 4 +
//      (0.5, 0); 6: tentative vehicle at (-30, -30); 7: confirmed vehicle at (-20, 10) (a false
//      positive in every scan).
// Plus one track list at kUtime0 + 100 s (no ground truth there).
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

#include "vtrack/object_list_t.hpp"
#include "vtrack/pose_t.hpp"
#include "vtrack/track_list_t.hpp"

namespace vtrack::testing {

inline constexpr std::int64_t kUtime0 = 1'000'000'000'000'000;  // [us]
inline constexpr int kScans = 80;
inline constexpr std::int64_t kScanPeriodUs = 100'000;
inline constexpr double kRadius = 20.0;     // [m]
inline constexpr double kSpeed = 5.0;       // [m/s] rear axle
inline constexpr double kRearAxle = -1.4;   // [m]

struct TruthState {
  Eigen::Vector2d centre, velocity;
  double yaw = 0.0, yaw_rate = 0.0;
};
// Car A's state at t seconds after kUtime0.
TruthState CarA(double t);

std::vector<vtrack::object_list_t> SyntheticTruth();
std::vector<vtrack::track_list_t> SyntheticTracks(const std::string& mode, double offset_m = 0.3);

// Writes GROUND_TRUTH, EGO_POSE and one LADAR_SCAN to run_path; TRACKS to tracks_path.
void WriteSyntheticRun(const std::string& run_path);
void WriteSyntheticTracks(const std::string& tracks_path, const std::string& mode,
                          double offset_m = 0.3);

}  // namespace vtrack::testing
