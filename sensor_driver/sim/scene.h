// The simulated world (docs/design.md, section 5): vehicles that drive (Ackerman or skid-steer), parked
// vehicles, clutter (walls, poles, bushes) standing on a flat ground plane z = 0, and the ego
// vehicle that carries the sensor.
//
// Every object is a vertical prism standing on the ground: a box (vehicles, walls) or a cylinder
// (poles, bushes) of the given height. Frames: world x, y on the ground, z up. The ego's body
// frame has its origin at the centre of the ego's rear axle on the ground (x forward, y left,
// z up); that is the point EGO_POSE reports.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sensor_driver/sim/vehicle_motion.h"

namespace vtrack::sim {

enum class ObjectClass { kCar, kVan, kTruck, kSkidSteer, kWall, kPole, kBush };
enum class Shape { kBox, kCylinder };

const char* ObjectClassName(ObjectClass c);
bool IsVehicleClass(ObjectClass c);

struct SceneObject {
  std::int64_t id = 0;               // persistent identity (ground truth id)
  ObjectClass object_class = ObjectClass::kCar;
  Shape shape = Shape::kBox;
  double length = 4.5;               // [m] box extent along yaw; cylinder: diameter
  double width = 1.8;                // [m] box extent across yaw; cylinder: diameter
  double height = 1.5;               // [m] top of the prism above the ground
  double reflectance = 0.5;          // [0, 1] intensity of a return at zero range
  double penetration = 0.0;          // [m] mean depth a ray travels inside before returning
                                     //     (exponential; bushes), 0 = solid surface
  double rotation_axis_offset = 0.0;  // [m] L (vehicles); NaN for clutter
  // Pose when motion is null (parked vehicles, clutter).
  Eigen::Vector2d center = Eigen::Vector2d::Zero();  // [m]
  double yaw = 0.0;                                  // [rad]
  // Driving vehicles: the trajectory. Shared so that scenes copy cheaply.
  std::shared_ptr<const VehicleMotion> motion;

  bool moving() const { return motion && !motion->IsStatic(); }
  // Radius of the smallest circle about the centre that holds the footprint [m].
  double BoundingRadius() const;
};

// Pose and velocity of an object at one time (static objects: zero velocity).
struct ObjectState {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();    // [m]
  double yaw = 0.0;                                    // [rad]
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  // [m/s] of the centre
  double speed = 0.0;                                  // [m/s] signed speed of the rotation axis
  double yaw_rate = 0.0;                               // [rad/s]
};

struct EgoVehicle {
  std::shared_ptr<const VehicleMotion> motion;  // rotation_axis_offset = rear axle, see header
  double length = 4.6;                          // [m] for display only (never hit by rays)
  double width = 1.9;                           // [m]
};

class Scene {
 public:
  std::vector<SceneObject> objects;
  EgoVehicle ego;

  ObjectState StateOf(const SceneObject& o, double t) const;
  // Ego body pose in the world at scenario time t: origin = rear-axle centre on the ground.
  Eigen::Isometry3d WorldFromBody(double t) const;
  // Ego state: axis_point is the body origin.
  MotionState EgoAt(double t) const { return ego.motion->At(t); }
};

}  // namespace vtrack::sim
