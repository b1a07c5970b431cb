#include "sensor_driver/sim/piecewise_linear.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace vtrack::sim {

PiecewiseLinear::PiecewiseLinear(std::vector<Key> keys) : keys_(std::move(keys)) {
  for (std::size_t i = 0; i < keys_.size(); ++i) {
    if (!std::isfinite(keys_[i].t) || !std::isfinite(keys_[i].value)) {
      throw std::invalid_argument("keyframe " + std::to_string(i) + ": t = " +
                                  std::to_string(keys_[i].t) + ", value = " +
                                  std::to_string(keys_[i].value) + " is not finite");
    }
    if (i > 0 && keys_[i].t < keys_[i - 1].t) {
      throw std::invalid_argument("keyframe " + std::to_string(i) + ": t = " +
                                  std::to_string(keys_[i].t) + " is earlier than the previous " +
                                  std::to_string(keys_[i - 1].t) + " (times must not decrease)");
    }
  }
}

std::size_t PiecewiseLinear::UpperIndex(double t) const {
  return static_cast<std::size_t>(
      std::upper_bound(keys_.begin(), keys_.end(), t,
                       [](double tv, const Key& k) { return tv < k.t; }) -
      keys_.begin());
}

double PiecewiseLinear::At(double t) const {
  if (keys_.empty()) return 0.0;
  const std::size_t i = UpperIndex(t);
  if (i == 0) return keys_.front().value;
  if (i == keys_.size()) return keys_.back().value;
  // keys_[i - 1].t <= t < keys_[i].t, so the segment has positive length.
  const Key& a = keys_[i - 1];
  const Key& b = keys_[i];
  const double s = (t - a.t) / (b.t - a.t);
  return a.value + s * (b.value - a.value);
}

double PiecewiseLinear::Derivative(double t) const {
  if (keys_.empty()) return 0.0;
  const std::size_t i = UpperIndex(t);
  if (i == 0 || i == keys_.size()) return 0.0;
  const Key& a = keys_[i - 1];
  const Key& b = keys_[i];
  return (b.value - a.value) / (b.t - a.t);
}

bool PiecewiseLinear::IsZero() const {
  return std::all_of(keys_.begin(), keys_.end(), [](const Key& k) { return k.value == 0.0; });
}

}  // namespace vtrack::sim
