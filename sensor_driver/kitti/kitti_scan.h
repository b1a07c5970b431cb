// A KITTI Velodyne frame as a vtrack::ladar_scan_t: per-return time from the azimuth and the
// laser index (ring) from the order of the returns in the file.
//
// Timing. KITTI triggers its cameras when the Velodyne faces forward, between the start and the
// end of the revolution that a .bin file holds, so the revolution is taken to be cut behind the
// car and the frame's time (the labels' time, the camera image) to be the middle of the sweep.
// The sensor is taken to spin clockwise seen from above (Velodyne's convention; KITTI documents
// no direction and a look at the data did not settle it; inside the camera's view, +-41 deg,
// either direction gives 50 +- 11 ms). With azimuth a = atan2(y, x) in the velo frame
// (counter-clockwise from forward) a return was measured
//     dt = ((pi - a) mod 2 pi) / (2 pi) * sweep_duration      after the sweep's start,
// i.e. 0 behind, 1/4 sweep to the left, 1/2 sweep ahead, 3/4 to the right. The scan's utime is the
// sweep's start: frame time - sweep_duration / 2. KITTI gives no per-return times: this is a
// nominal model. The returns are taken as not motion-compensated (as in KITTI raw data).
//
// Rings. A KITTI .bin stores the returns laser by laser, from the highest laser to the lowest,
// each laser's returns in increasing azimuth from just left of forward round to just right of it.
// A new laser starts where the azimuth crosses from negative to non-negative after the current
// laser has covered more than 270 deg; a "laser" of fewer than 16 returns (a stray return just
// past the crossing, seen in real files) belongs to the one before. If the count is not
// num_rings, the rings are unknown and every ring is -1 (the scan is still valid): e.g. frame 153
// of sequence 0000 is cut short after 53 lasers. ring 0 is the lowest laser, as ladar_scan_t wants.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sensor_driver/kitti/kitti_io.h"
#include "vtrack/ladar_scan_t.hpp"

namespace vtrack::kitti {

struct VelodyneParams {
  std::int32_t sweep_duration_us = 100000;  // [us] one revolution (10 Hz); > 0
  int num_rings = 64;                       // [-] lasers of the HDL-64E; 1..32767
  float max_range = 120.0f;                 // [m] HDL-64E maximum range; > 0
  std::string sensor_id = "velodyne";       // [-] ladar_scan_t.sensor_id; not empty

  // Empty if valid, else a message naming the key and its value.
  std::string Validate() const;
};

// Time of a return after the sweep's start [us], from its azimuth (see the top of this file).
// In [0, sweep_duration_us); 0 for a non-finite point.
std::int32_t ReturnTimeUs(float x, float y, std::int32_t sweep_duration_us);

// Ring of every return (0 = lowest laser), or all -1 if the file does not split into num_rings
// lasers. *found (optional) receives the number of lasers found.
std::vector<std::int16_t> AssignRings(const VelodyneFrame& frame, int num_rings, int* found = nullptr);

// The scan message of one frame. Sensor frame = body frame = velo frame (the sensor sits at the
// body origin): sensor_pos = 0, sensor_orientation = identity. intensity = KITTI reflectance.
vtrack::ladar_scan_t MakeScan(const VelodyneFrame& frame, std::int64_t sweep_start_utime,
                              std::int64_t seq, const VelodyneParams& params);

}  // namespace vtrack::kitti
