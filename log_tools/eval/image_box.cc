#include "log_tools/eval/image_box.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

namespace vtrack::eval {

std::string ImageProjection::Validate() const {
  std::ostringstream os;
  if (image_width <= 0 || image_height <= 0) {
    os << "image size must be positive, got " << image_width << "x" << image_height;
  } else if (!(sensor_height_m > 0.0 && std::isfinite(sensor_height_m))) {
    os << "sensor_height_m must be > 0, got " << sensor_height_m;
  } else if (!(box_height_m > 0.0 && std::isfinite(box_height_m))) {
    os << "box_height_m must be > 0, got " << box_height_m;
  } else if (!P.allFinite() || P.row(2).head<3>().norm() == 0.0) {
    os << "P is not a projection matrix";
  }
  return os.str();
}

SensorBox TrackBoxInSensor(const vtrack::track_t& tr, double x, double y, double theta,
                           const Eigen::Isometry3d& sensor_from_world, const ImageProjection& cam) {
  // A detector's boxes give the track its bottom and height; otherwise the road and the default
  // height.
  const bool has_z = std::isfinite(tr.z) && std::isfinite(tr.height) && tr.height > 0.0;
  SensorBox b;
  b.height = has_z ? tr.height : cam.box_height_m;
  b.bottom = sensor_from_world * Eigen::Vector3d(x, y, has_z ? tr.z : 0.0);
  if (!has_z) b.bottom.z() = -cam.sensor_height_m;
  b.heading = sensor_from_world.linear() * Eigen::Vector3d(std::cos(theta), std::sin(theta), 0.0);
  b.heading.z() = 0.0;
  b.heading.normalize();
  return b;
}

std::optional<ImageBox> ProjectToImage(const SensorBox& b, double length, double width,
                                       const ImageProjection& cam) {
  const Eigen::Vector3d n(-b.heading.y(), b.heading.x(), 0.0);
  const Eigen::Vector3d up(0.0, 0.0, 1.0);
  double u0 = std::numeric_limits<double>::infinity(), v0 = u0, u1 = -u0, v1 = -u0;
  for (const double a : {0.5, -0.5}) {
    for (const double c : {0.5, -0.5}) {
      for (const double z : {0.0, b.height}) {
        const Eigen::Vector3d corner = b.bottom + a * length * b.heading + c * width * n + z * up;
        const Eigen::Vector3d r = cam.rect_from_sensor * corner;
        const Eigen::Vector3d img = cam.P * r.homogeneous();
        if (r.z() < 0.1 || img.z() <= 0.0) return std::nullopt;
        u0 = std::min(u0, img.x() / img.z());
        u1 = std::max(u1, img.x() / img.z());
        v0 = std::min(v0, img.y() / img.z());
        v1 = std::max(v1, img.y() / img.z());
      }
    }
  }
  ImageBox box{std::max(u0, 0.0), std::max(v0, 0.0), std::min(u1, cam.image_width - 1.0),
               std::min(v1, cam.image_height - 1.0)};
  if (!(box.u1 > box.u0) || !(box.v1 > box.v0)) return std::nullopt;
  return box;
}

}  // namespace vtrack::eval
