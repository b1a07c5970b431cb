// Pixel inspection for the renderer tests: is a pixel (mostly) a given colour drawn with
// anti-aliasing over the white background, and where are such pixels.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

namespace vtrack::viewer::testing {

// True if p looks like colour c blended over white with coverage >= min_alpha: every channel
// where c differs clearly from white gives the same coverage (255 - p) / (255 - c) within 0.1,
// and every channel matches that blend within tol.
inline bool IsColor(const cv::Vec3b& p, const cv::Scalar& c, double min_alpha = 0.5,
                    double tol = 20.0) {
  double alphas[3];
  double sum = 0.0;
  int n = 0;
  for (int k = 0; k < 3; ++k) {
    const double d = 255.0 - c[k];
    if (d >= 60.0) {
      alphas[n] = (255.0 - p[k]) / d;
      sum += alphas[n++];
    }
  }
  if (n == 0) return false;
  const double alpha = sum / n;
  if (alpha < min_alpha) return false;
  for (int i = 0; i < n; ++i) {
    if (std::abs(alphas[i] - alpha) > 0.1) return false;
  }
  for (int k = 0; k < 3; ++k) {
    const double expected = 255.0 - std::min(alpha, 1.0) * (255.0 - c[k]);
    if (std::abs(p[k] - expected) > tol) return false;
  }
  return true;
}

// Pixel centres (u, v) of every pixel of the colour.
inline std::vector<Eigen::Vector2d> PixelsOf(const cv::Mat& img, const cv::Scalar& c,
                                             double min_alpha = 0.5) {
  std::vector<Eigen::Vector2d> out;
  for (int v = 0; v < img.rows; ++v) {
    for (int u = 0; u < img.cols; ++u) {
      if (IsColor(img.at<cv::Vec3b>(v, u), c, min_alpha)) out.emplace_back(u, v);
    }
  }
  return out;
}

// True if a pixel of the colour lies within radius px of (u, v).
inline bool ColorNear(const cv::Mat& img, const cv::Scalar& c, const Eigen::Vector2d& uv,
                      double radius) {
  const int r = static_cast<int>(std::ceil(radius));
  for (int dv = -r; dv <= r; ++dv) {
    for (int du = -r; du <= r; ++du) {
      const int u = static_cast<int>(std::lround(uv.x())) + du;
      const int v = static_cast<int>(std::lround(uv.y())) + dv;
      if (u < 0 || v < 0 || u >= img.cols || v >= img.rows) continue;
      if (std::hypot(u - uv.x(), v - uv.y()) > radius) continue;
      if (IsColor(img.at<cv::Vec3b>(v, u), c)) return true;
    }
  }
  return false;
}

// Writes the image to $VTRACK_VIEWER_TEST_PNG/<name>.png when that variable is set, so that a
// person can look at what a test rendered.
inline void SaveIfRequested(const std::string& name, const cv::Mat& img) {
  const char* dir = std::getenv("VTRACK_VIEWER_TEST_PNG");
  if (dir && *dir) cv::imwrite(std::string(dir) + "/" + name + ".png", img);
}

// Distance from p to the segment a-b.
inline double DistanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                                const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = b - a;
  const double t = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
  return (a + t * d - p).norm();
}

}  // namespace vtrack::viewer::testing
