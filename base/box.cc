#include "base/box.h"

#include <cmath>

#include "base/angle.h"

namespace vtrack {

Eigen::Vector2d OrientedBox::Axis() const { return {std::cos(theta), std::sin(theta)}; }
Eigen::Vector2d OrientedBox::Normal() const { return {-std::sin(theta), std::cos(theta)}; }

std::array<Eigen::Vector2d, 4> OrientedBox::Corners() const {
  const Eigen::Vector2d a = Axis() * (0.5 * length);
  const Eigen::Vector2d n = Normal() * (0.5 * width);
  return {center + a + n, center - a + n, center - a - n, center + a - n};
}

void OrientedBox::FaceEndpoints(Face f, Eigen::Vector2d* a, Eigen::Vector2d* b) const {
  const auto c = Corners();
  switch (f) {
    case Face::kFront: *a = c[3]; *b = c[0]; break;
    case Face::kLeft:  *a = c[0]; *b = c[1]; break;
    case Face::kRear:  *a = c[1]; *b = c[2]; break;
    case Face::kRight: *a = c[2]; *b = c[3]; break;
  }
}

Eigen::Vector2d OrientedBox::FaceMidpoint(Face f) const {
  Eigen::Vector2d a, b;
  FaceEndpoints(f, &a, &b);
  return 0.5 * (a + b);
}

double OrientedBox::OutwardNormalAngle(Face f) const {
  return WrapToPi(theta + 0.5 * kPi * static_cast<int>(f));
}

Eigen::Vector2d OrientedBox::ToBoxFrame(const Eigen::Vector2d& p) const {
  const Eigen::Vector2d d = p - center;
  return {d.dot(Axis()), d.dot(Normal())};
}

Eigen::Vector2d OrientedBox::ToWorld(const Eigen::Vector2d& q) const {
  return center + q.x() * Axis() + q.y() * Normal();
}

bool OrientedBox::Contains(const Eigen::Vector2d& p, double margin) const {
  const Eigen::Vector2d q = ToBoxFrame(p);
  return std::abs(q.x()) <= 0.5 * length + margin && std::abs(q.y()) <= 0.5 * width + margin;
}

bool FaceVisible(const OrientedBox& box, Face f, const Eigen::Vector2d& sensor_xy,
                 double min_slant_rad) {
  const Eigen::Vector2d to_sensor = sensor_xy - box.FaceMidpoint(f);
  if (to_sensor.squaredNorm() == 0.0) return false;
  const double dir = std::atan2(to_sensor.y(), to_sensor.x());
  return std::abs(AngleDiff(box.OutwardNormalAngle(f), dir)) < 0.5 * kPi - min_slant_rad;
}

std::uint8_t VisibleFaces(const OrientedBox& box, const Eigen::Vector2d& sensor_xy,
                          double min_slant_rad) {
  std::uint8_t mask = 0;
  for (int i = 0; i < 4; ++i) {
    if (FaceVisible(box, static_cast<Face>(i), sensor_xy, min_slant_rad)) mask |= (1u << i);
  }
  return mask;
}

}  // namespace vtrack
