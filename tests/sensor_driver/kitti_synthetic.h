// A small KITTI sequence in the standard layout, written by the test with known truth: objects
// defined in the world frame, the ego vehicle on a known path, and a calibration whose camera
// frame is an exact axis permutation of the Velodyne frame (so that the README's rule
// yaw_velo = -rotation_y - pi/2 holds exactly and every transform can be written by hand).
#pragma once

#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace vtrack::testing {

struct SyntheticObject {
  int id = 0;
  std::string type = "Car";
  double length = 4.0, width = 1.8, height = 1.5;  // [m]
  double x0 = 0.0, y0 = 0.0, yaw0 = 0.0;           // [m, m, rad] world, at t = 0 (frame 0)
  double vx = 0.0, vy = 0.0, yaw_rate = 0.0;       // [m/s, m/s, rad/s]
  double bottom_z = -1.7;                          // [m] world
  int first_frame = 0, last_frame = 1 << 30;       // labelled frames
  int points_inside = 20;                          // returns put inside the box each frame

  double X(double t) const { return x0 + vx * t; }
  double Y(double t) const { return y0 + vy * t; }
  double Yaw(double t) const { return yaw0 + yaw_rate * t; }
};

struct SyntheticSequence {
  std::string dir;
  int num_frames = 5;
  // Camera-from-Velodyne translation [m] (camera frame) of the exact-permutation calibration.
  Eigen::Vector3d t_cam{0.1, -0.2, 0.3};
  double fx = 721.5377, cx = 609.5593, cy = 172.854;  // P2 intrinsics [px]
  std::vector<SyntheticObject> objects;

  // Ego: world_from_velo of frame i = translation (1.0 i, 0.2 i, 0) and yaw 0.05 i.
  Eigen::Isometry3d WorldFromVelo(int i) const {
    Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
    p.linear() = Eigen::AngleAxisd(0.05 * i, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    p.translation() = Eigen::Vector3d(1.0 * i, 0.2 * i, 0.0);
    return p;
  }
  // Camera (= rect) coordinates of a Velodyne point, by hand: cam = (-y, -z, x) + t_cam.
  Eigen::Vector3d RectOfVelo(const Eigen::Vector3d& v) const {
    return Eigen::Vector3d(-v.y(), -v.z(), v.x()) + t_cam;
  }

  std::string CalibText() const {
    char buf[2048];
    std::snprintf(buf, sizeof(buf),
                  "P0: %.10g 0 %.10g 0 0 %.10g %.10g 0 0 0 1 0\n"
                  "P1: %.10g 0 %.10g 0 0 %.10g %.10g 0 0 0 1 0\n"
                  "P2: %.10g 0 %.10g 0 0 %.10g %.10g 0 0 0 1 0\n"
                  "P3: %.10g 0 %.10g 0 0 %.10g %.10g 0 0 0 1 0\n"
                  "R0_rect: 1 0 0 0 1 0 0 0 1\n"
                  "Tr_velo_to_cam: 0 -1 0 %.17g 0 0 -1 %.17g 1 0 0 %.17g\n"
                  "Tr_imu_to_velo: 1 0 0 -0.8 0 1 0 0.3 0 0 1 -0.8\n",
                  fx, cx, fx, cy, fx, cx, fx, cy, fx, cx, fx, cy, fx, cx, fx, cy, t_cam.x(),
                  t_cam.y(), t_cam.z());
    return buf;
  }

  // Writes velodyne/0000/*.bin, calib/0000.txt, label_02/0000.txt and poses.txt under dir.
  void Write() const {
    namespace fs = std::filesystem;
    fs::create_directories(dir + "/velodyne/0000");
    fs::create_directories(dir + "/calib");
    fs::create_directories(dir + "/label_02");
    std::ofstream(dir + "/calib/0000.txt") << CalibText();
    std::ofstream poses(dir + "/poses.txt");
    std::ofstream labels(dir + "/label_02/0000.txt");
    for (int i = 0; i < num_frames; ++i) {
      const Eigen::Isometry3d w = WorldFromVelo(i);
      const Eigen::Matrix<double, 3, 4> m = w.matrix().topRows<3>();
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) poses << (r || c ? " " : "") << FormatG(m(r, c));
      }
      poses << "\n";
      labels << i << " -1 DontCare -1 -1 -10 100 100 200 200 -1000 -1000 -1000 -10 -1 -1 -1\n";
      std::vector<float> pts;
      const double t = 0.1 * i;
      const double ego_yaw = 0.05 * i;
      for (const auto& o : objects) {
        if (i < o.first_frame || i > o.last_frame) continue;
        const Eigen::Vector3d bottom_world(o.X(t), o.Y(t), o.bottom_z);
        const Eigen::Vector3d bottom_velo = w.inverse() * bottom_world;
        const Eigen::Vector3d bottom_rect = RectOfVelo(bottom_velo);
        // README rule, exact for this calibration: yaw_velo = -rotation_y - pi/2.
        const double yaw_velo = o.Yaw(t) - ego_yaw;
        const double ry = std::remainder(-yaw_velo - M_PI / 2, 2 * M_PI);
        labels << i << " " << o.id << " " << o.type << " 0 0 0 100 100 200 200 " << FormatG(o.height)
               << " " << FormatG(o.width) << " " << FormatG(o.length) << " " << FormatG(bottom_rect.x())
               << " " << FormatG(bottom_rect.y()) << " " << FormatG(bottom_rect.z()) << " " << FormatG(ry)
               << "\n";
        // Returns inside the box (80% of its extent) and as many just outside it (130%).
        const Eigen::Vector2d ax(std::cos(o.Yaw(t)), std::sin(o.Yaw(t)));
        const Eigen::Vector2d nx(-ax.y(), ax.x());
        for (int k = 0; k < o.points_inside; ++k) {
          const double u = -0.4 + 0.8 * (k % 5) / 4.0;   // along, fraction of length
          const double v = -0.4 + 0.8 * (k / 5 % 4) / 3.0;  // across, fraction of width
          for (double scale : {1.0, 3.25}) {                 // 3.25 * 0.4 = 1.3 half-extents: outside
            const Eigen::Vector2d xy = Eigen::Vector2d(o.X(t), o.Y(t)) + scale * u * o.length * ax +
                                       scale * v * o.width * nx;
            const double z = o.bottom_z + 0.5 * o.height;
            const Eigen::Vector3d pv = w.inverse() * Eigen::Vector3d(xy.x(), xy.y(), z);
            if (scale != 1.0 && std::abs(u) < 0.3 && std::abs(v) < 0.3) continue;  // would be inside
            for (double c : {pv.x(), pv.y(), pv.z(), 0.5}) pts.push_back(static_cast<float>(c));
          }
        }
      }
      char name[64];
      std::snprintf(name, sizeof(name), "/velodyne/0000/%06d.bin", i);
      std::ofstream bin(dir + name, std::ios::binary);
      bin.write(reinterpret_cast<const char*>(pts.data()), static_cast<std::streamsize>(pts.size() * 4));
    }
  }

  static std::string FormatG(double v) {
    char b[64];
    std::snprintf(b, sizeof(b), "%.17g", v);
    return b;
  }
};

}  // namespace vtrack::testing
