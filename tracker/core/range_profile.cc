#include "tracker/core/range_profile.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "base/angle.h"
#include "tracker/core/fast_atan2.h"

namespace vtrack {

double MedianBearingStepDeg(const std::vector<float>& x, const std::vector<float>& y) {
  std::vector<double> steps;
  steps.reserve(x.size());
  double prev = 0.0;
  bool have_prev = false;
  for (std::size_t i = 0; i < x.size() && i < y.size(); ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) continue;
    const double a = std::atan2(y[i], x[i]);
    if (have_prev) steps.push_back(std::abs(AngleDiff(a, prev)));
    prev = a;
    have_prev = true;
  }
  if (steps.empty()) return 0.0;
  const auto mid = steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2);
  std::nth_element(steps.begin(), mid, steps.end());
  return RadToDeg(*mid);
}

void RangeProfile::Build(const Eigen::Vector2d& sensor_xy, std::span<const double> x,
                         std::span<const double> y, double bin_deg) {
  Build(sensor_xy, x, y, {}, bin_deg);
}

void RangeProfile::Build(const Eigen::Vector2d& sensor_xy, std::span<const double> x,
                         std::span<const double> y, std::span<const std::int16_t> ring,
                         double bin_deg) {
  sensor_ = sensor_xy;
  num_bins_ = std::max(1, static_cast<int>(std::ceil(360.0 / bin_deg)));
  inv_bin_ = num_bins_ / (2.0 * kPi);
  const bool rings = ring.size() == x.size();
  auto ring_of = [&](std::size_t i) {
    return rings ? std::clamp<int>(ring[i], 0, kMaxRings - 1) : 0;
  };
  // The largest ring, clamped (clamping is monotone: the same as the largest clamped ring).
  num_rings_ = 1;
  if (rings && !ring.empty()) {
    num_rings_ = std::clamp<int>(*std::max_element(ring.begin(), ring.end()), 0, kMaxRings - 1) + 1;
  }
  nearest_.assign(static_cast<std::size_t>(num_rings_) * static_cast<std::size_t>(num_bins_),
                  std::numeric_limits<float>::infinity());
  // The bin Bin() gives, with Atan2Approx wherever its error bound (with ample slack for the
  // rounding of the sum and product) cannot change the floor; else Bin() itself. Same bins.
  const int n = num_bins_;
  const double slack = 10.0 * kAtan2ApproxMaxError * inv_bin_ + 1e-9;
  const auto keep = [&](std::size_t i, double v, double range) {
    // v is in [-slack, n + slack]: the cast is floor(v) for v >= 0, and v - b is exact. The
    // interval v +- slack inside one bin: that bin (n wraps to 0 as in Bin(), without its two
    // divisions); else Bin() itself (v < 0 included).
    int b = static_cast<int>(v);
    const double frac = v - b;
    if (frac >= slack && frac < 1.0 - slack) {
      if (b >= n) b -= n;
    } else {
      b = Bin(Eigen::Vector2d(x[i], y[i]));
    }
    float& r = nearest_[static_cast<std::size_t>(ring_of(i)) * static_cast<std::size_t>(n) +
                        static_cast<std::size_t>(b)];
    r = std::min(r, static_cast<float>(range));
  };
  // Two returns per step: the bearing and range of each lane are the doubles one return at a
  // time would give (p - sensor, Atan2Approx, the norm).
  const Double2 sx = Splat(sensor_.x()), sy = Splat(sensor_.y());
  const Double2 shift = Splat(kPi), scale = Splat(inv_bin_);
  const std::size_t size = x.size();
  std::size_t i = 0;
  for (; i + 1 < size; i += 2) {
    const Double2 dx = Load2(x.data() + i) - sx, dy = Load2(y.data() + i) - sy;
    const Double2 v = (Atan2Approx2(dy, dx) + shift) * scale;
    const Double2 r2 = dx * dx + dy * dy;
    keep(i, v[0], std::sqrt(r2[0]));
    keep(i + 1, v[1], std::sqrt(r2[1]));
  }
  if (i < size) {
    const Eigen::Vector2d d = Eigen::Vector2d(x[i], y[i]) - sensor_;
    keep(i, (Atan2Approx(d.y(), d.x()) + kPi) * inv_bin_, d.norm());
  }
}

int RangeProfile::Bin(const Eigen::Vector2d& p) const {
  const Eigen::Vector2d d = p - sensor_;
  const int n = num_bins_;
  const int b = static_cast<int>(std::floor((std::atan2(d.y(), d.x()) + kPi) * inv_bin_));
  return ((b % n) + n) % n;
}

bool RangeProfile::SeenThrough(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                               double margin) const {
  if (nearest_.empty()) return false;
  const int n = num_bins_;
  const int ba = Bin(a);
  int d = ((Bin(b) - ba) % n + n) % n;
  int step = 1;
  if (d > n / 2) {
    d = n - d;
    step = -1;
  }
  if (d < 2) return false;
  const float r = static_cast<float>(std::max((a - sensor_).norm(), (b - sensor_).norm()) + margin);
  int behind = 0;
  for (int k = 1; k < d; ++k) {
    const int bin = (((ba + step * k) % n) + n) % n;
    bool any = false;
    for (int ring = 0; ring < num_rings_; ++ring) {
      const float v = Nearest(ring, bin);
      if (v < r) return false;
      any = any || std::isfinite(v);
    }
    behind += any;
  }
  return 2 * behind >= d - 1;
}

void RangeProfile::MarkUnseen(double begin, double end) {
  const int n = num_bins_;
  if (n == 0) return;
  const int first = static_cast<int>(std::floor((WrapToPi(begin) + kPi) * inv_bin_));
  const int count = std::min(n, static_cast<int>(std::ceil((end - begin) * inv_bin_)) + 1);
  for (int k = 0; k < count; ++k) {
    const int b = (((first + k) % n) + n) % n;
    for (int r = 0; r < num_rings_; ++r) {
      nearest_[static_cast<std::size_t>(r) * static_cast<std::size_t>(n) + static_cast<std::size_t>(b)] = 0.0f;
    }
  }
}

bool RangeProfile::FreeBeyond(const Eigen::Vector2d& end, const Eigen::Vector2d& inner,
                              double margin, int bins) const {
  if (nearest_.empty()) return false;
  const Eigen::Vector2d de = end - sensor_, di = inner - sensor_;
  // Beyond = the rotation sense from inner to end.
  const int step = de.x() * di.y() - de.y() * di.x() < 0.0 ? 1 : -1;
  const int n = num_bins_;
  const double r = de.norm();
  const int b0 = Bin(end);
  const int b_in = (((b0 - step) % n) + n) % n;
  // The rings that see the face at its end; every ring if none does.
  bool any_on_face = false;
  for (int ring = 0; ring < num_rings_ && !any_on_face; ++ring) {
    any_on_face = std::abs(Nearest(ring, b0) - r) <= margin || std::abs(Nearest(ring, b_in) - r) <= margin;
  }
  for (int ring = 0; ring < num_rings_; ++ring) {
    if (any_on_face && std::abs(Nearest(ring, b0) - r) > margin &&
        std::abs(Nearest(ring, b_in) - r) > margin) {
      continue;
    }
    for (int k = 1; k <= bins; ++k) {
      const int b = (((b0 + step * k) % n) + n) % n;
      if (Nearest(ring, b) < r + margin) return false;
    }
  }
  return true;
}

}  // namespace vtrack
