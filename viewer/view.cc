#include "viewer/view.h"

#include <algorithm>

namespace vtrack::viewer {

Eigen::Vector2d View::WorldToImage(const Eigen::Vector2d& world_xy) const {
  return {0.5 * width + px_per_m * (world_xy.x() - center.x()),
          0.5 * height - px_per_m * (world_xy.y() - center.y())};
}

Eigen::Vector2d View::ImageToWorld(const Eigen::Vector2d& pixel_uv) const {
  return {center.x() + (pixel_uv.x() - 0.5 * width) / px_per_m,
          center.y() - (pixel_uv.y() - 0.5 * height) / px_per_m};
}

Eigen::AlignedBox2d View::WorldBounds() const {
  const Eigen::Vector2d a = ImageToWorld({0.0, static_cast<double>(height)});
  const Eigen::Vector2d b = ImageToWorld({static_cast<double>(width), 0.0});
  return Eigen::AlignedBox2d(a.cwiseMin(b), a.cwiseMax(b));
}

View CenteredView(const Eigen::Vector2d& center, double px_per_m, int width, int height) {
  View v;
  v.center = center;
  v.px_per_m = px_per_m;
  v.width = width;
  v.height = height;
  return v;
}

View FitView(const Eigen::AlignedBox2d& world_window, int width, int height) {
  const Eigen::Vector2d size = world_window.sizes();
  const double sx = size.x() > 0.0 ? width / size.x() : 1.0;
  const double sy = size.y() > 0.0 ? height / size.y() : 1.0;
  return CenteredView(world_window.center(), std::min(sx, sy), width, height);
}

}  // namespace vtrack::viewer
