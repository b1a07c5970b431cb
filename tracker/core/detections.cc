#include "tracker/core/detections.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "base/angle.h"

namespace vtrack {
namespace {

// Not a candidate: far more than leaving a track without a box, so never chosen.
constexpr double kForbidden = 1e6;

}  // namespace

std::string DetectionParams::CrossProblem() const {
  if (!(gate_m <= max_gate_m)) return param::Problem("gate_m", gate_m, "m", "<= max_gate_m");
  return {};
}

std::vector<BoxMeasurement> BoxesInWorld(const DetectionList& list,
                                         const Eigen::Isometry3d& world_from_body,
                                         const DetectionParams& params) {
  std::vector<BoxMeasurement> out;
  out.reserve(list.boxes.size());
  const Eigen::Matrix3d R = world_from_body.linear();
  for (const Detection& d : list.boxes) {
    if (!(d.score >= params.min_score)) continue;
    const Eigen::Vector3d p = world_from_body * Eigen::Vector3d(d.x, d.y, d.z);
    // The heading's direction in the world's ground plane.
    const Eigen::Vector3d axis = R * Eigen::Vector3d(std::cos(d.yaw), std::sin(d.yaw), 0.0);
    BoxMeasurement b;
    b.box.center = p.head<2>();
    b.box.theta = std::atan2(axis.y(), axis.x());
    b.box.length = d.length;
    b.box.width = d.width;
    b.z = p.z();
    b.height = d.height;
    b.score = d.score;
    b.utime = list.utime;
    out.push_back(b);
  }
  return out;
}

CentreMeasurement BoxToMeasurement(const BoxMeasurement& b, double theta,
                                   const DetectionParams& params) {
  CentreMeasurement m;
  const double heading = std::abs(AngleDiff(b.box.theta, theta)) > 0.5 * kPi
                             ? WrapToPi(b.box.theta + kPi)
                             : b.box.theta;
  // The heading stays within pi / 2 of theta, so the filter's innovation never wraps.
  m.z << b.box.center, theta + AngleDiff(heading, theta);
  const double sp = params.position_std, sh = DegToRad(params.heading_std_deg);
  m.R = Eigen::Vector3d(sp * sp, sp * sp, sh * sh).asDiagonal();
  return m;
}

BoxAssociation AssociateBoxes(const std::vector<PredictedObject>& tracks,
                              const std::vector<BoxMeasurement>& boxes,
                              const DetectionParams& params) {
  BoxAssociation out;
  const int rows = static_cast<int>(tracks.size());
  const int nb = static_cast<int>(boxes.size());
  out.track_box.assign(tracks.size(), -1);
  std::vector<char> taken(boxes.size(), 0);
  if (rows > 0 && nb > 0) {
    // Columns: the boxes, then one "no box" column per track. Its cost is the same for every
    // track, the largest gate: a track's own gate there would let an uncertain track (a wide
    // gate, so much to lose without a box) outbid a well-known one for a box nearer to the
    // latter. At the largest gate every gated pair is worth taking, and among the assignments
    // of most pairs the one of least summed distance wins.
    const int cols = nb + rows;
    const double no_box_cost = params.max_gate_m;
    std::vector<double> cost(static_cast<std::size_t>(rows) * cols, kForbidden);
    for (int r = 0; r < rows; ++r) {
      const PredictedObject& t = tracks[static_cast<std::size_t>(r)];
      const double gate = std::min(params.max_gate_m,
                                   params.gate_m + params.gate_sigma * std::max(0.0, t.position_std));
      for (int k = 0; k < nb; ++k) {
        const double d = (boxes[static_cast<std::size_t>(k)].box.center - t.box.center).norm();
        if (d <= gate) cost[static_cast<std::size_t>(r) * cols + k] = d;
      }
      cost[static_cast<std::size_t>(r) * cols + nb + r] = no_box_cost;
    }
    const std::vector<int> assign = SolveAssignment(cost, rows, cols);
    for (int r = 0; r < rows; ++r) {
      const int k = assign[static_cast<std::size_t>(r)];
      if (k < 0 || k >= nb || cost[static_cast<std::size_t>(r) * cols + k] >= kForbidden) continue;
      out.track_box[static_cast<std::size_t>(r)] = k;
      taken[static_cast<std::size_t>(k)] = 1;
    }
  }
  for (int k = 0; k < nb; ++k) {
    if (!taken[static_cast<std::size_t>(k)]) out.new_boxes.push_back(k);
  }
  return out;
}

}  // namespace vtrack
