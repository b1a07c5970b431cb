#include "sensor_driver/sim/scene.h"

#include <cmath>

namespace vtrack::sim {

const char* ObjectClassName(ObjectClass c) {
  switch (c) {
    case ObjectClass::kCar: return "car";
    case ObjectClass::kVan: return "van";
    case ObjectClass::kTruck: return "truck";
    case ObjectClass::kSkidSteer: return "skid_steer";
    case ObjectClass::kWall: return "wall";
    case ObjectClass::kPole: return "pole";
    case ObjectClass::kBush: return "bush";
  }
  return "unknown";
}

bool IsVehicleClass(ObjectClass c) {
  return c == ObjectClass::kCar || c == ObjectClass::kVan || c == ObjectClass::kTruck ||
         c == ObjectClass::kSkidSteer;
}

double SceneObject::BoundingRadius() const {
  if (shape == Shape::kCylinder) return 0.5 * length;
  return 0.5 * std::hypot(length, width);
}

ObjectState Scene::StateOf(const SceneObject& o, double t) const {
  ObjectState s;
  if (!o.motion) {
    s.center = o.center;
    s.yaw = o.yaw;
    return s;
  }
  const MotionState m = o.motion->At(t);
  s.center = m.center;
  s.yaw = m.yaw;
  s.velocity = m.center_velocity;
  s.speed = m.speed;
  s.yaw_rate = m.yaw_rate;
  return s;
}

Eigen::Isometry3d Scene::WorldFromBody(double t) const {
  const MotionState m = ego.motion->At(t);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(m.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(m.axis_point.x(), m.axis_point.y(), 0.0);
  return T;
}

}  // namespace vtrack::sim
