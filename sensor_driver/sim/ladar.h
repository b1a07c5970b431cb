// A scanning LADAR ray-cast against the simulated scene (docs/design.md, section 5).
//
// Model. The sensor's head (or mirror) turns at rate_hz revolutions per second and fires one
// column of rays (one per layer elevation) every resolution_deg of azimuth, starting at
// azimuth_start_deg and turning clockwise or counter-clockwise (seen from above) over fov_deg.
// Column j fires dt_j = j * resolution / (360 deg * rate) after the start of the sweep (the scan's
// utime), rounded to the microsecond; every return carries that dt_us. A single-plane scanner
// (SICK-like) has one layer; a 360 deg multi-layer one (Velodyne-like) many.
//
// Each ray is cast from the sensor's pose at its own firing time (the ego keeps driving during
// the sweep) against the objects at their poses at that time (they keep driving too), so a sweep
// is skewed exactly as a real one. Returns are in the sensor frame at the firing time:
// x forward, y left, z up; point = range * unit ray direction.
//
// Geometry. The ground is the plane z = 0; every object is a vertical prism on it (2-D
// footprints extruded to their heights): a box or a cylinder. A ray hits a prism where its
// horizontal path is inside the footprint and its height is within [0, height] (walls and roofs
// alike). Each column is cast once in 2-D against its candidate footprints and the result shared
// by all layers when the sensor is mounted level (roll = pitch = 0); a tilted mount casts every
// ray on its own. Candidates come from an angular index: the sweep is cut into sub-intervals of
// at most kSubIntervalS, and for each one every object's azimuth interval as seen from the moving
// sensor (a conservative bound: corners at both ends of the sub-interval, plus kIndexMarginM) is
// entered into kAzimuthBins bins. A naive cast of every ray against every object would cost
// 130k rays x 250 objects per sweep; this one costs a few candidates per column.
//
// Errors. Range noise is Gaussian along the ray (range_noise, 1 sigma); a return is lost with
// probability dropout; with probability spurious a ray instead returns at a range drawn uniformly
// between min_range and the first surface (or max_range) — dust, rain, a mixed pixel. Bushes let a
// ray in by an exponential depth with mean SceneObject::penetration. Returns outside
// [min_range, max_range] are not reported. Intensity = reflectance * (1 - 0.5 range / max_range).
// All randomness comes from the seed passed to Sweep(), consumed in a fixed order: the same seed
// gives the same sweep, bit for bit. Draws use Boost.Random (its ziggurat normal is several times
// faster than std::normal_distribution's polar method, and its output is specified by Boost
// rather than left to the standard library implementation).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <boost/random/mersenne_twister.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "sensor_driver/sim/scene.h"
#include "vtrack/ladar_scan_t.hpp"

namespace vtrack::sim {

struct LadarParams {
  std::string name = "ladar";         // sensor_id in ladar_scan_t
  double rate_hz = 10.0;              // [Hz] sweeps (head revolutions) per second, (0, 200]
  double azimuth_start_deg = 180.0;   // [deg] sensor-frame azimuth of the first column (0 = +x, CCW +)
  double fov_deg = 360.0;             // [deg] azimuth range swept, (0, 360]
  double resolution_deg = 0.2;        // [deg] azimuth step between columns, (0.01, 10]
  bool clockwise = true;              // sweep direction seen from above
  std::vector<double> elevations_deg{0.0};  // [deg] one per layer, strictly ascending (ring 0 lowest)
  double min_range = 0.5;             // [m] returns nearer are not reported, >= 0
  double max_range = 100.0;           // [m] returns farther are not reported, <= 1000
  double range_noise = 0.02;          // [m] 1-sigma Gaussian range noise, [0, 5]
  double dropout = 0.0;               // [-] probability a return is lost, [0, 1)
  double spurious = 0.0;              // [-] probability a ray returns early at random, [0, 1)
  Eigen::Vector3d mount_xyz{0.0, 0.0, 1.0};  // [m] sensor origin in the body frame, z in (0.05, 10]
  double mount_roll_deg = 0.0;        // [deg] sensor orientation in the body frame, |.| <= 45
  double mount_pitch_deg = 0.0;       // [deg] |.| <= 45
  double mount_yaw_deg = 0.0;         // [deg]

  // "" if valid; otherwise "<key> = <value>: <constraint>" for the first offending field.
  std::string Validate() const;
  int NumColumns() const;
  int NumLayers() const { return static_cast<int>(elevations_deg.size()); }
  // body_from_sensor: rotates/translates sensor-frame points into the body frame.
  Eigen::Isometry3d BodyFromSensor() const;
  bool IsLevel() const { return mount_roll_deg == 0.0 && mount_pitch_deg == 0.0; }
};

// Built-in sensors (names usable as --sensor and as `preset:` in scenario files):
//   "single_plane": SICK-like, 180 deg in front, 0.5 deg, 25 Hz, 80 m, front bumper at 0.5 m.
//   "velodyne64":   HDL-64E-like, 360 deg, 64 layers -24.8..+2 deg, 2048 columns, 10 Hz, 120 m,
//                   on the roof 1.73 m up (KITTI's height).
// Returns false for an unknown name.
bool LadarPreset(const std::string& name, LadarParams* out);
std::vector<std::string> LadarPresetNames();

class LadarSimulator {
 public:
  static constexpr double kSubIntervalS = 0.0125;  // [s] longest sub-interval of the angular index
  static constexpr int kAzimuthBins = 720;         // bins of the angular index (0.5 deg)
  static constexpr double kIndexMarginM = 0.05;    // [m] slack of the index's bounds
  static constexpr double kGroundReflectance = 0.15;
  static constexpr double kSpuriousReflectance = 0.05;

  // Throws std::invalid_argument with Validate()'s message if params are invalid.
  explicit LadarSimulator(const LadarParams& params);

  const LadarParams& params() const { return params_; }
  int NumColumns() const { return static_cast<int>(col_az_.size()); }
  std::int32_t SweepDurationUs() const { return col_dt_us_.empty() ? 0 : col_dt_us_.back(); }

  // One sweep starting at scenario time t0 [s] (the scan's utime). Fills every field of *scan
  // except utime and seq; hits (resized to scene.objects.size()) receives the number of returns
  // on each object (spurious returns count for none).
  void Sweep(const Scene& scene, double t0, std::uint64_t seed, vtrack::ladar_scan_t* scan,
             std::vector<int>* hits);

 private:
  struct Interval {  // a footprint's extent along a horizontal ray, in horizontal metres
    double h_in, h_out, height, penetration;
    int object;
  };
  struct Ray {  // one ray in the world: horizontal unit direction u, slope dz/dh, and 1/|d_xy|
    Eigen::Vector2d u;
    double slope;
    double inv_horizontal;  // range per horizontal metre
  };

  void BuildIndex(const Scene& scene, double t0);
  // Candidates in the bin of world azimuth `azimuth` during sub-interval s, intersected with the
  // ray from o along u at time t; appended to intervals_.
  void GatherIntervals(const Scene& scene, int s, double azimuth, const Eigen::Vector2d& o,
                       const Eigen::Vector2d& u, double t, int column);
  // First surface along a ray through intervals_ (ground included): horizontal distance and the
  // object index (-1 ground, -2 nothing).
  void FirstHit(double o_z, double slope, double* h, int* object);
  // Applies the error model to the first surface of one ray and appends the return (if any) at
  // index n_ of the scan's arrays (sized for one return per ray).
  void Emit(double range_true, int object, int layer, float dir_x, float dir_y, float dir_z,
            std::int32_t dt_us, const Scene& scene, vtrack::ladar_scan_t* scan,
            std::vector<int>* hits);
  double Uniform01();
  int SubIntervalOf(double tau) const;

  LadarParams params_;
  Eigen::Isometry3d body_from_sensor_;
  std::vector<double> col_az_;          // [rad] sensor-frame azimuth per column
  std::vector<double> col_cos_, col_sin_;
  std::vector<std::int32_t> col_dt_us_;
  std::vector<double> layer_sin_, layer_cos_, layer_tan_;
  int num_sub_ = 1;

  // Per-sweep scratch, kept to avoid allocation.
  boost::random::mt19937_64 rng_;
  std::size_t n_ = 0;                               // returns written in this sweep
  std::vector<Eigen::Vector2d> sub_sensor_xy_;     // [num_sub_ + 1]
  std::vector<ObjectState> sub_states_;             // [(num_sub_ + 1) * objects]
  std::vector<int> bin_offsets_;                    // [num_sub_ * (kAzimuthBins + 1)]
  std::vector<int> bin_items_;
  std::vector<std::pair<int, int>> spans_;          // (first bin, count) per object, one sub-interval
  std::vector<Interval> intervals_;
  std::vector<ObjectState> column_state_;           // per object, valid if stamp matches
  std::vector<int> column_stamp_;
};

}  // namespace vtrack::sim
