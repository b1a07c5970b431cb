#include "tracker/core/track.h"

#include <limits>
#include <numeric>

namespace vtrack {

double TrackHypothesis::Score() const {
  if (score_terms.empty()) return std::numeric_limits<double>::infinity();
  return std::accumulate(score_terms.begin(), score_terms.end(), 0.0) /
         static_cast<double>(score_terms.size());
}

OrientedBox BoxOf(const Eigen::Vector3d& pose, double length, double width) {
  OrientedBox b;
  b.center = pose.head<2>();
  b.theta = pose(2);
  b.length = length;
  b.width = width;
  return b;
}

Eigen::Vector3d PoseOf(const MotionModel& m, const Vector6d& x) {
  const auto idx = m.PoseIndices();
  return {x(idx[0]), x(idx[1]), x(idx[2])};
}

}  // namespace vtrack
