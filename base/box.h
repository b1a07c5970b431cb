// The vehicle rectangle (paper Section 2.3): centre, orientation of the length axis, length and
// width; its corners and faces, point containment, and which faces a sensor can see (Eq. 15 in
// its per-face form, docs/design.md note 4).
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>

namespace vtrack {

// Faces in counter-clockwise order starting at the front; bit i of a visibility mask is face i.
enum class Face : int { kFront = 0, kLeft = 1, kRear = 2, kRight = 3 };

struct OrientedBox {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();  // [m] world frame
  double theta = 0.0;                                // [rad] direction of the length axis
  double length = 0.0;                               // [m] extent along theta
  double width = 0.0;                                // [m] extent across theta

  Eigen::Vector2d Axis() const;    // unit vector along theta (towards the front)
  Eigen::Vector2d Normal() const;  // unit vector 90 deg counter-clockwise of Axis (to the left)

  // Corners counter-clockwise: front-left, rear-left, rear-right, front-right.
  std::array<Eigen::Vector2d, 4> Corners() const;

  // Face i runs between corners so that its outward normal points at OutwardNormalAngle(i):
  // front (theta), left (theta + 90 deg), rear (theta + 180 deg), right (theta - 90 deg).
  void FaceEndpoints(Face f, Eigen::Vector2d* a, Eigen::Vector2d* b) const;
  Eigen::Vector2d FaceMidpoint(Face f) const;
  double OutwardNormalAngle(Face f) const;

  // Point in the box's own frame (x along the length axis, y to the left, origin at the centre).
  Eigen::Vector2d ToBoxFrame(const Eigen::Vector2d& world_point) const;
  Eigen::Vector2d ToWorld(const Eigen::Vector2d& box_point) const;

  // True if the point lies inside the rectangle grown by margin [m] on every side.
  bool Contains(const Eigen::Vector2d& world_point, double margin = 0.0) const;
};

// A face is visible from the sensor if its outward normal points back at the sensor within
// 90 deg - s (Eq. 15, per-face form; s = minimum slant angle, 10 deg in the paper). The viewing
// direction is taken from the sensor to the face midpoint. Returns a bit mask (bit i = Face i).
std::uint8_t VisibleFaces(const OrientedBox& box, const Eigen::Vector2d& sensor_xy,
                          double min_slant_rad);
bool FaceVisible(const OrientedBox& box, Face f, const Eigen::Vector2d& sensor_xy,
                 double min_slant_rad);

}  // namespace vtrack
