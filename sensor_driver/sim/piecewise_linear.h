// A control input over time (speed, steering angle, yaw rate) given by keyframes.
#pragma once

#include <vector>

namespace vtrack::sim {

// y(t) from keyframes (t_i, y_i): linear between consecutive keyframes, held constant before the
// first and after the last. Two keyframes at the same time make a step: the later one applies
// from that time on. An empty profile is zero everywhere.
class PiecewiseLinear {
 public:
  struct Key {
    double t = 0.0;      // [s] scenario time
    double value = 0.0;  // [unit of the profile]
  };

  PiecewiseLinear() = default;
  // Throws std::invalid_argument naming the keyframe if times decrease or a number is not finite.
  explicit PiecewiseLinear(std::vector<Key> keys);

  double At(double t) const;
  // dy/dt on the segment that contains t (the right derivative at a keyframe); 0 outside.
  double Derivative(double t) const;
  // True if the profile is zero at every time.
  bool IsZero() const;
  const std::vector<Key>& keys() const { return keys_; }

 private:
  // Index of the first keyframe later than t (keys_.size() if none).
  std::size_t UpperIndex(double t) const;
  std::vector<Key> keys_;
};

}  // namespace vtrack::sim
