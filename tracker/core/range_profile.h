// The scan's range profile: the nearest return per bearing around the sensor, per ring. The
// orientation rules ask it whether a fitted face was seen whole (track_manager.h), the fit
// whether a gap along a face is seen through (fitting.h).
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <span>
#include <vector>

namespace vtrack {

// The tracker's finest range-profile bearing bin: 7200 bins per ring.
inline constexpr double kMinRangeProfileBinDeg = 0.05;  // [deg]

// What FreeBeyond is asked for the end of a face or of a track's returns: a return this much
// nearer than the end ...
inline constexpr double kEndOccluderMargin = 0.5;  // [m]
// ... in this many bearing bins beyond it hides it: 0.6 deg at the 3-D profile's 0.2 deg bins,
// the spacing of a few azimuth steps of a 64-beam scanner.
inline constexpr int kEndBinsBeyond = 3;  // [-]

// The median bearing step [deg] between successive returns of a single-plane scan (sensor
// frame, in scan order); 0 with fewer than two returns. A profile binned coarser than this
// leaves no empty bins between the returns of one face.
double MedianBearingStepDeg(const std::vector<float>& x, const std::vector<float>& y);

// The nearest return per bearing bin around the sensor, over every return of a scan, per ring of
// a 3-D scanner. It tells whether a fitted face ends where the object ends (free space, or only
// farther returns, just beyond the end: a full view of that face) or where something nearer
// hides the rest of it. Per ring: a 3-D scanner sees over low objects near it (a car's bonnet
// 4 m away hides a face 40 m away from the downward rings only, not from the rings that hit the
// face); a profile over all rings read those as occluders beyond every end of the far face.
class RangeProfile {
 public:
  // bin_deg: bearing bin [deg], > 0. One profile over all returns (a single-plane scanner).
  void Build(const Eigen::Vector2d& sensor_xy, std::span<const double> x,
             std::span<const double> y, double bin_deg);
  // One profile per ring (ring[i] of return i; rings outside [0, kMaxRings) share the last).
  void Build(const Eigen::Vector2d& sensor_xy, std::span<const double> x,
             std::span<const double> y, std::span<const std::int16_t> ring, double bin_deg);
  // True if, in the `bins` bearing bins just beyond `end` (on the side away from `inner`, the
  // face's other end), no return lies nearer than end's range + margin, on the rings that see
  // the face at its end (a return within margin of end's range in end's bin or the one inside
  // it); on every ring if none does.
  bool FreeBeyond(const Eigen::Vector2d& end, const Eigen::Vector2d& inner, double margin,
                  int bins) const;
  // True if the sensor sees through the gap between a and b, two points of one face: every
  // bearing bin strictly between theirs holds, on every ring, no return nearer than the farther
  // of the two plus margin, and at least half of them hold a farther return (something seen
  // behind the gap, not only dropouts). False if no whole bin lies between them. Every ring
  // counts, unlike FreeBeyond: a low object near the sensor that only other rings hit keeps the
  // gap closed (the fit then bridges it, as without a profile).
  bool SeenThrough(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double margin) const;
  // Marks the bins of world bearings from begin to end [rad] (counter-clockwise) as hidden on
  // every ring (a return at range 0): where the sweep's returns were lost, a face's end is not
  // seen, and the face must not be taken for a full view.
  void MarkUnseen(double begin, double end);
  bool empty() const { return nearest_.empty(); }
  int num_bins() const { return num_bins_; }
  int num_rings() const { return num_rings_; }
  // [m] The nearest return of ring (in [0, num_rings())) in bearing bin (in [0, num_bins()),
  // bin b from -180 deg + b * bin_deg); +inf if none.
  float Nearest(int ring, int bin) const {
    return nearest_[static_cast<std::size_t>(ring) * static_cast<std::size_t>(num_bins_) +
                    static_cast<std::size_t>(bin)];
  }

  static constexpr int kMaxRings = 256;

 private:
  int Bin(const Eigen::Vector2d& p) const;
  Eigen::Vector2d sensor_ = Eigen::Vector2d::Zero();
  double inv_bin_ = 0.0;  // [1/rad]
  int num_bins_ = 0;
  int num_rings_ = 0;
  std::vector<float> nearest_;  // [m] per (ring, bin), ring-major; +inf where no return
};

}  // namespace vtrack
