// Plain input structs of the tracker core: one LADAR sweep and one ego pose. They mirror
// ladar_scan_t and pose_t (lcmtypes/) without depending on LCM; the adapter in tracker/ moves
// the decoded arrays into them (no copy of the point data).
#pragma once

#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "base/angle.h"

namespace vtrack {

// An arc of the sensor's azimuth, counter-clockwise from begin to end [rad], sensor frame
// (begin in [-pi, pi), begin < end <= begin + 2 pi).
struct AzimuthWedge {
  double begin = 0.0;
  double end = 0.0;
  bool Contains(double azimuth) const {
    double d = std::fmod(azimuth - begin, 2.0 * kPi);  // turned from begin, in [0, 2 pi)
    if (d < 0.0) d += 2.0 * kPi;
    return d <= end - begin;
  }
};

// One sweep of a scanning LADAR as parallel arrays (structure of arrays). Point i is at
// (x[i], y[i], z[i]) in the sensor frame and was measured at utime + dt_us[i].
struct LadarScan {
  std::int64_t utime = 0;             // [us] start of the sweep
  std::int64_t seq = 0;               // [-] scan counter of the sensor
  std::string sensor_id;              // [-]
  Eigen::Isometry3d body_from_sensor = Eigen::Isometry3d::Identity();  // mounting pose
  std::int32_t sweep_duration_us = 0; // [us] first to last possible return
  float max_range = 0.0f;             // [m] sensor's maximum range (0 = unknown)
  std::int16_t num_rings = 1;         // [-] lasers/layers; 1 = single-plane scanner

  std::vector<float> x, y, z;         // [m] sensor frame
  std::vector<float> intensity;       // [-]
  std::vector<std::int32_t> dt_us;    // [us] time after utime
  std::vector<std::int16_t> ring;     // [-] laser/layer index

  // Wedges of the sweep whose returns were lost on the way (a sweep sent as slices, some of which
  // did not arrive; lcmtypes/util/ladar_slices.h). A track predicted inside one is not observed
  // by this sweep: it is not counted as missed. Empty for a whole sweep.
  std::vector<AzimuthWedge> lost_wedges;

  std::size_t size() const { return x.size(); }
  // Time of the last return this sweep can hold: the scan is complete in time once the pose
  // stream reaches it.
  std::int64_t end_utime() const { return utime + sweep_duration_us; }
};

// Ego pose of the vehicle carrying the sensor: world_from_body at utime.
struct EgoPose {
  std::int64_t utime = 0;                                          // [us]
  Eigen::Isometry3d world_from_body = Eigen::Isometry3d::Identity();
};

}  // namespace vtrack
