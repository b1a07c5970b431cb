#include "viewer/msg_convert.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "tracker/lcm_convert.h"

namespace vtrack::viewer {
namespace {

// True if the message's quaternion q is one the tracker's converters accept (within 1e-3 of unit
// length: they normalise it; any other is passed on unchanged, and a zero quaternion would even
// come out as the identity) and the converted transform m is finite.
bool Rigid(const Eigen::Isometry3d& m, const char* what, const double q[4], std::string* why) {
  const double norm = Eigen::Vector4d(q[0], q[1], q[2], q[3]).norm();
  const bool ok = std::isfinite(norm) && std::abs(norm - 1.0) < 1e-3 && m.matrix().allFinite();
  if (!ok && why) {
    std::ostringstream os;
    os << what << " (" << q[0] << ", " << q[1] << ", " << q[2] << ", " << q[3]
       << ") or position is not a rigid transform (quaternion not of unit length, or not finite)";
    *why = os.str();
  }
  return ok;
}

Eigen::Matrix3d RowMajor3(const double m[9]) {
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(m);
}

OrientedBox MakeBox(double x, double y, double theta, double length, double width) {
  OrientedBox b;
  b.center = {x, y};
  b.theta = theta;
  b.length = length;
  b.width = width;
  return b;
}

bool PositiveFinite(double v) { return std::isfinite(v) && v > 0.0; }

// track_t.MODEL_* (also the hypotheses' model) to the scene's model.
MotionModel ModelOf(std::int8_t model) {
  return model == vtrack::track_t::MODEL_VASM ? MotionModel::kVasm
         : model == vtrack::track_t::MODEL_CV ? MotionModel::kCv
                                              : MotionModel::kIsm;
}

}  // namespace

std::optional<Eigen::Isometry3d> PoseFromMsg(const vtrack::pose_t& msg, std::string* why) {
  const EgoPose pose = PoseFromLcm(msg);
  if (!Rigid(pose.world_from_body, "pose orientation", msg.orientation, why)) return std::nullopt;
  return pose.world_from_body;
}

std::optional<LadarScan> ScanFromMsg(const vtrack::ladar_scan_t& msg, std::string* why) {
  // The tracker's conversion moves the arrays out of its argument: give it a copy, since the
  // message may be shared with other frames.
  LadarScan scan = ScanFromLcm(vtrack::ladar_scan_t(msg));
  if (!Rigid(scan.body_from_sensor, "scan sensor_orientation", msg.sensor_orientation, why)) {
    return std::nullopt;
  }
  return scan;
}

SceneTrack TrackFromMsg(const vtrack::track_t& msg) {
  SceneTrack t;
  t.id = msg.id;
  t.status = msg.status == vtrack::track_t::STATUS_TENTATIVE ? TrackStatus::kTentative
             : msg.status == vtrack::track_t::STATUS_COASTING ? TrackStatus::kCoasting
                                                              : TrackStatus::kConfirmed;
  t.model = ModelOf(msg.model);
  t.moving = msg.moving;
  t.object_class = msg.object_class == vtrack::track_t::CLASS_VEHICLE ? TrackClass::kVehicle
                   : msg.object_class == vtrack::track_t::CLASS_OTHER ? TrackClass::kOther
                                                                      : TrackClass::kUnknown;
  t.box = MakeBox(msg.x, msg.y, msg.theta, msg.length, msg.width);
  t.cov = RowMajor3(msg.cov);
  t.speed = msg.speed;
  t.velocity_heading = msg.velocity_heading;
  t.yaw_rate = msg.yaw_rate;
  t.rear_axle_offset = msg.rear_axle_offset;
  t.num_hypotheses = msg.num_hypotheses;
  t.vehicle_probability = msg.vehicle_probability;
  const std::size_t n = std::min(msg.pred_x.size(), msg.pred_y.size());
  t.predicted.reserve(n);
  for (std::size_t i = 0; i < n; ++i) t.predicted.emplace_back(msg.pred_x[i], msg.pred_y[i]);
  return t;
}

SceneMeasurement MeasurementFromMsg(const vtrack::track_debug_entry_t& msg,
                                    const SceneTrack* track) {
  SceneMeasurement m;
  m.track_id = msg.track_id;
  m.fit_kind = msg.fit_kind == vtrack::track_debug_entry_t::FIT_CORNER ? FitKind::kCorner
               : msg.fit_kind == vtrack::track_debug_entry_t::FIT_EDGE ? FitKind::kEdge
                                                                        : FitKind::kNone;
  double length = msg.predicted[3], width = msg.predicted[4];
  if (!PositiveFinite(length) || !PositiveFinite(width)) {
    length = msg.updated[3];
    width = msg.updated[4];
  }
  if ((!PositiveFinite(length) || !PositiveFinite(width)) && track) {
    length = track->box.length;
    width = track->box.width;
  }
  m.z_box = MakeBox(msg.z[0], msg.z[1], msg.z[2], length, width);
  m.R = RowMajor3(msg.R);
  m.visible_faces = static_cast<std::uint8_t>(msg.visible_faces);
  const std::size_t ne = std::min({msg.edge_x0.size(), msg.edge_y0.size(), msg.edge_x1.size(),
                                   msg.edge_y1.size()});
  for (std::size_t i = 0; i < ne; ++i) {
    m.edges.emplace_back(Eigen::Vector2d(msg.edge_x0[i], msg.edge_y0[i]),
                         Eigen::Vector2d(msg.edge_x1[i], msg.edge_y1[i]));
  }
  const Eigen::Vector4d axle(msg.rear_axle[0], msg.rear_axle[1], msg.rear_axle[2], msg.rear_axle[3]);
  if (axle.allFinite()) m.rear_axle = Segment({axle(0), axle(1)}, {axle(2), axle(3)});
  const std::size_t np = std::min(msg.point_x.size(), msg.point_y.size());
  m.points.reserve(np);
  for (std::size_t i = 0; i < np; ++i) m.points.emplace_back(msg.point_x[i], msg.point_y[i]);
  m.point_edge.assign(msg.point_edge.begin(), msg.point_edge.begin() +
                                                  static_cast<std::ptrdiff_t>(
                                                      std::min(np, msg.point_edge.size())));
  for (const auto& h : msg.hypotheses) {
    SceneHypothesis sh;
    sh.index = h.index;
    sh.model = ModelOf(h.model);
    sh.selected = h.selected;
    sh.box = MakeBox(h.x, h.y, h.theta, length, width);
    sh.rear_axle_offset = h.rear_axle_offset;
    sh.score = h.score;
    m.hypotheses.push_back(sh);
  }
  return m;
}

SceneTruth TruthFromMsg(const vtrack::object_t& msg) {
  SceneTruth g;
  g.id = msg.id;
  g.object_class = msg.object_class;
  g.box = MakeBox(msg.x, msg.y, msg.yaw, msg.length, msg.width);
  g.rear_axle_offset = msg.rear_axle_offset;
  g.speed = msg.speed;
  g.moving = msg.moving;
  g.in_labelled_region = msg.in_labelled_region;
  g.is_clutter = msg.object_class >= vtrack::object_t::CLASS_WALL;
  return g;
}

}  // namespace vtrack::viewer
