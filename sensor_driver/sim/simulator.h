// A scenario turned into messages: LADAR_SCAN (ladar_scan_t), GROUND_TRUTH (object_list_t) and
// EGO_POSE (pose_t), laid out on the timeline of one run. vtrack-ladar-driver, vtrack-ego-pose
// and vtrack-sim-log all build their messages here, so that the same scenario, options and seed
// give the same messages whether published live or written to a log.
//
// Time. A run starts at run_start_utime (scenario time t = 0) and lasts duration. Scenario time t
// is utime = run_start_utime + round(t * 1e6). Scan i starts at i / rate_hz (its utime; point
// times are utime + dt_us) and is complete, i.e. publishable, sweep_duration_us later. Pose k
// describes k / pose_rate_hz. A run holds the poses in [0, duration) and the scans whose whole
// sweep lies within them, so that every return can be motion-compensated by interpolation.
//
// Ground truth. One object_list_t per scan with the scan's utime and seq: every object of the
// scene (vehicles moving or parked, and clutter with its class) in its state at the scan's utime.
// in_labelled_region: centre within truth.labelled_radius of the sensor at the scan's start AND
// at least truth.min_points returns on it in this scan. num_points counts returns (not spurious
// ones). rear_axle_offset is NaN for clutter; z = 0 (boxes stand on the ground).
//
// Randomness. Scan i draws from a generator seeded with Mix(seed, kScanStream, i) and the pose
// noise from Mix(seed, kPoseStream, 0) advanced sequentially from pose 0, so any message can be
// rebuilt alone and the two live processes draw independently of each other.
#pragma once

#include <boost/random/mersenne_twister.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sensor_driver/sim/ladar.h"
#include "sensor_driver/sim/scenario.h"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/object_list_t.hpp"
#include "vtrack/pose_t.hpp"

namespace vtrack::sim {

// Command-line overrides of what a scenario file says (unset = the file's value).
struct RunOptions {
  std::string sensor;                        // "" = the scenario's default sensor
  std::optional<std::uint64_t> seed;
  std::optional<double> range_noise;         // [m]
  std::optional<double> dropout;             // [-]
  std::optional<double> spurious;            // [-]
  std::optional<double> pose_rate_hz;        // [Hz]
  std::optional<double> pose_noise_position; // [m]
  std::optional<double> pose_noise_yaw_deg;  // [deg]
};

// A 64-bit seed from three words (SplitMix64 finaliser over a running mix).
std::uint64_t MixSeed(std::uint64_t a, std::uint64_t b, std::uint64_t c);

std::int8_t ObjectClassCode(ObjectClass c);  // object_t::CLASS_*

class Simulator {
 public:
  static constexpr std::uint64_t kScanStream = 1;
  static constexpr std::uint64_t kPoseStream = 2;

  // Throws std::invalid_argument naming the option and value if an override is out of range.
  Simulator(Scenario scenario, const RunOptions& options = {});

  const Scenario& scenario() const { return scenario_; }
  const LadarParams& sensor() const { return ladar_.params(); }
  std::uint64_t seed() const { return seed_; }
  double pose_rate_hz() const { return pose_rate_hz_; }
  const PoseNoiseParams& pose_noise() const { return pose_noise_; }

  std::int64_t RunDurationUs() const { return run_us_; }
  // Scans of the run: those that end before its last pose (the tracker places a sweep's returns
  // between the poses around them, so a sweep after the last pose could not be used).
  int NumScans() const { return num_scans_; }
  // Scans of the run at the highest pose rate (1 kHz): NumScans() when poses come often enough,
  // more when the pose rate leaves the last of them without a pose after their end.
  int NumSweepsInRun() const { return num_sweeps_in_run_; }
  std::int64_t ScanOffsetUs(int i) const;          // scan utime - run start
  std::int64_t ScanPublishOffsetUs(int i) const;   // + sweep_duration_us
  int NumPoses() const { return num_poses_; }
  std::int64_t PoseOffsetUs(int k) const;

  // Scan i of the run starting at run_start_utime, with its ground truth.
  void MakeScan(int i, std::int64_t run_start_utime, std::int64_t seq, vtrack::ladar_scan_t* scan,
                vtrack::object_list_t* truth);
  // Pose k of the run starting at run_start_utime (noise as configured).
  void MakePose(int k, std::int64_t run_start_utime, vtrack::pose_t* pose);

 private:
  void AdvanceNoiseTo(int k);

  Scenario scenario_;
  LadarSimulator ladar_;
  std::uint64_t seed_;
  double pose_rate_hz_;
  PoseNoiseParams pose_noise_;
  std::int64_t run_us_ = 0;
  int num_scans_ = 0;
  int num_sweeps_in_run_ = 0;
  int num_poses_ = 0;
  std::vector<int> hits_;
  // Gauss-Markov pose noise, advanced sequentially: state at pose noise_k_.
  boost::random::mt19937_64 noise_rng_;
  int noise_k_ = -1;
  double noise_x_ = 0.0, noise_y_ = 0.0, noise_yaw_ = 0.0;
};

}  // namespace vtrack::sim
