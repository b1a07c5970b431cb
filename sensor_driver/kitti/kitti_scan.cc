#include "sensor_driver/kitti/kitti_scan.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "base/angle.h"

namespace vtrack::kitti {

std::string VelodyneParams::Validate() const {
  std::ostringstream os;
  if (sweep_duration_us <= 0) os << "sweep_duration_us must be > 0, got " << sweep_duration_us;
  else if (num_rings < 1 || num_rings > 32767) os << "num_rings must be in [1, 32767], got " << num_rings;
  else if (!(max_range > 0.0f) || !std::isfinite(max_range)) os << "max_range must be > 0 m, got " << max_range;
  else if (sensor_id.empty()) os << "sensor_id must not be empty";
  return os.str();
}


namespace {

// Azimuth atan2(y, x) of every return [rad]; NaN for a non-finite return.
std::vector<double> Azimuths(const VelodyneFrame& frame) {
  std::vector<double> az(frame.size());
  for (std::size_t i = 0; i < frame.size(); ++i) {
    az[i] = std::isfinite(frame.x[i]) && std::isfinite(frame.y[i])
                ? std::atan2(static_cast<double>(frame.y[i]), static_cast<double>(frame.x[i]))
                : std::numeric_limits<double>::quiet_NaN();
  }
  return az;
}

std::int32_t TimeOfAzimuth(double a, std::int32_t sweep_duration_us) {
  if (!std::isfinite(a)) return 0;
  const double frac = std::clamp((kPi - a) / (2.0 * kPi), 0.0, 1.0);  // [0, 1]
  return std::min(static_cast<std::int32_t>(frac * sweep_duration_us), sweep_duration_us - 1);
}

std::vector<std::int16_t> RingsOfAzimuths(const std::vector<double>& azimuth, int num_rings, int* found) {
  // A laser contributes hundreds of returns to a sweep; a "laser" of fewer returns than this is a
  // stray return just past the forward crossing (seen in real KITTI files) and joins the previous.
  constexpr std::size_t kMinReturnsPerLaser = 16;
  const std::size_t n = azimuth.size();
  std::vector<int> segment(n, -1);
  std::vector<std::size_t> segment_size;
  int seg = -1;
  double span = 0.0;       // [rad] azimuth covered by the current segment so far
  double prev_az = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double az = azimuth[i];
    if (!std::isfinite(az)) continue;
    if (seg < 0 || (prev_az < 0.0 && az >= 0.0 && span > 1.5 * kPi)) {
      ++seg;
      span = 0.0;
      segment_size.push_back(0);
    } else {
      // Signed step wrapped to (-pi, pi]: the jump from +pi to -pi behind the car is a small step.
      span += WrapToPi(az - prev_az);
    }
    segment[i] = seg;
    ++segment_size.back();
    prev_az = az;
  }
  // Segment -> laser in file order, folding stray segments into their predecessor.
  std::vector<int> laser_of_segment(segment_size.size(), 0);
  int lasers = 0;
  for (std::size_t k = 0; k < segment_size.size(); ++k) {
    if (k == 0 || segment_size[k] >= kMinReturnsPerLaser) ++lasers;
    laser_of_segment[k] = std::max(lasers - 1, 0);
  }
  if (found) *found = lasers;
  if (lasers != num_rings) return std::vector<std::int16_t>(n, -1);
  // The file runs from the highest laser to the lowest; ring 0 is the lowest.
  std::vector<std::int16_t> ring(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    if (segment[i] >= 0) {
      ring[i] = static_cast<std::int16_t>(num_rings - 1 - laser_of_segment[static_cast<std::size_t>(segment[i])]);
    }
  }
  return ring;
}

}  // namespace

std::int32_t ReturnTimeUs(float x, float y, std::int32_t sweep_duration_us) {
  if (!std::isfinite(x) || !std::isfinite(y)) return 0;
  return TimeOfAzimuth(std::atan2(static_cast<double>(y), static_cast<double>(x)), sweep_duration_us);
}

std::vector<std::int16_t> AssignRings(const VelodyneFrame& frame, int num_rings, int* found) {
  return RingsOfAzimuths(Azimuths(frame), num_rings, found);
}

vtrack::ladar_scan_t MakeScan(const VelodyneFrame& frame, std::int64_t sweep_start_utime,
                              std::int64_t seq, const VelodyneParams& params) {
  vtrack::ladar_scan_t s;
  s.utime = sweep_start_utime;
  s.seq = seq;
  s.sensor_id = params.sensor_id;
  for (int k = 0; k < 3; ++k) s.sensor_pos[k] = 0.0;
  s.sensor_orientation[0] = 1.0;
  for (int k = 1; k < 4; ++k) s.sensor_orientation[k] = 0.0;
  s.sweep_duration_us = params.sweep_duration_us;
  s.max_range = params.max_range;
  s.num_rings = static_cast<std::int16_t>(params.num_rings);
  const std::size_t n = frame.size();
  s.npoints = static_cast<std::int32_t>(n);
  s.x = frame.x;
  s.y = frame.y;
  s.z = frame.z;
  s.intensity = frame.reflectance;
  const std::vector<double> azimuth = Azimuths(frame);
  s.dt_us.resize(n);
  for (std::size_t i = 0; i < n; ++i) s.dt_us[i] = TimeOfAzimuth(azimuth[i], params.sweep_duration_us);
  s.ring = RingsOfAzimuths(azimuth, params.num_rings, nullptr);
  return s;
}

}  // namespace vtrack::kitti
