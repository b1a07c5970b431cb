// The world-to-image projection of a top-down frame: the one function through which everything
// is drawn (and through which tests compute where things must appear).
//
// The image looks straight down on the world xy plane with world +x to the right and world +y
// up. The world point `center` lands on pixel (width / 2, height / 2); one metre is px_per_m
// pixels. Pixel coordinates (u right, v down) have pixel centres at integers, as in OpenCV:
//
//   u = width / 2  + px_per_m * (x - center.x)
//   v = height / 2 - px_per_m * (y - center.y)
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace vtrack::viewer {

struct View {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();  // [m] world point at the image centre
  double px_per_m = 10.0;                            // [px/m] scale
  int width = 1280;                                  // [px]
  int height = 960;                                  // [px]

  Eigen::Vector2d WorldToImage(const Eigen::Vector2d& world_xy) const;
  Eigen::Vector2d ImageToWorld(const Eigen::Vector2d& pixel_uv) const;
  // The world rectangle the image covers [m].
  Eigen::AlignedBox2d WorldBounds() const;
};

// A view of the given size centred on center at px_per_m.
View CenteredView(const Eigen::Vector2d& center, double px_per_m, int width, int height);

// The largest-scale view of the given size that shows the whole world rectangle (centred on it).
View FitView(const Eigen::AlignedBox2d& world_window, int width, int height);

}  // namespace vtrack::viewer
