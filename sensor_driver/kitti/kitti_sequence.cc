#include "sensor_driver/kitti/kitti_sequence.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "base/angle.h"
#include "base/pose.h"

namespace vtrack::kitti {
namespace fs = std::filesystem;
namespace {

constexpr std::int64_t kFramePeriodUs = 100'000;  // KITTI tracking: 10 Hz, frame i at i * 0.1 s
constexpr double kFramePeriodS = 1e-6 * kFramePeriodUs;

std::string BinName(int i) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%06d.bin", i);
  return buf;
}

// Counts 000000.bin, 000001.bin, ... and checks that they are contiguous from 0.
int CountFrames(const std::string& dir) {
  std::set<int> indices;
  std::error_code ec;
  fs::directory_iterator it(dir, ec);
  if (ec) {
    throw KittiError("cannot read the Velodyne frames folder '" + dir + "': " + ec.message() +
                     " (--poses and --oxts need the raw layout's point clouds; a folder of the "
                     "boxes layout takes its ego motion from ego_pose_orbslam3/ without them)");
  }
  for (const auto& e : it) {
    const std::string name = e.path().filename().string();
    if (name.size() != 10 || name.substr(6) != ".bin") continue;
    if (!std::all_of(name.begin(), name.begin() + 6, [](char c) { return c >= '0' && c <= '9'; })) continue;
    indices.insert(std::stoi(name.substr(0, 6)));
  }
  if (indices.empty()) throw KittiError("no Velodyne frames (NNNNNN.bin) in " + dir);
  int expected = 0;
  for (int i : indices) {
    if (i != expected) {
      throw KittiError("Velodyne frames in " + dir + " are not contiguous: " + BinName(expected) +
                       " is missing (found " + BinName(i) + ")");
    }
    ++expected;
  }
  return expected;
}

// Rotation vector of a rotation matrix (log map).
Eigen::Vector3d LogSo3(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

// Least-squares slope dy/dt of (t_k, y_k); requires >= 2 distinct t.
double Slope(const std::vector<double>& t, const std::vector<double>& y) {
  double tm = 0.0, ym = 0.0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    tm += t[k];
    ym += y[k];
  }
  tm /= static_cast<double>(t.size());
  ym /= static_cast<double>(t.size());
  double num = 0.0, den = 0.0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    num += (t[k] - tm) * (y[k] - ym);
    den += (t[k] - tm) * (t[k] - tm);
  }
  return num / den;
}

// The length axis of a KITTI box in the rect frame (y down): R_y(rotation_y) * x
// = (cos ry, 0, -sin ry).
Eigen::Vector3d LengthAxisRect(double rotation_y) {
  return Eigen::Vector3d(std::cos(rotation_y), 0.0, -std::sin(rotation_y));
}

// Sets the box of an object_t or detection_t: x and y of xy, z, the heading of axis (the length
// axis) in the x-y plane, and the size of row (a Label or DetectionRow).
template <class Box, class Row>
void SetBox(const Eigen::Vector3d& xy, double z, const Eigen::Vector3d& axis, const Row& row,
            Box* o) {
  o->x = xy.x();
  o->y = xy.y();
  o->z = z;
  o->yaw = WrapToPi(std::atan2(axis.y(), axis.x()));
  o->length = row.length;
  o->width = row.width;
  o->height = row.height;
}

}  // namespace

std::string SequenceOptions::Validate() const {
  std::ostringstream os;
  if (const std::string v = velodyne.Validate(); !v.empty()) os << "velodyne." << v;
  else if (start_utime <= velodyne.sweep_duration_us / 2)
    os << "start_utime must be > half a sweep (" << velodyne.sweep_duration_us / 2 << " us), got " << start_utime;
  else if (start_utime > kMaxStartUtime)
    os << "start_utime must be <= " << kMaxStartUtime << " us (2^52: the year 2112), got " << start_utime;
  else if (image_width <= 0) os << "image_width must be > 0 px, got " << image_width;
  else if (image_height <= 0) os << "image_height must be > 0 px, got " << image_height;
  else if (!(moving_threshold_m > 0.0) || !std::isfinite(moving_threshold_m))
    os << "moving_threshold_m must be > 0 m, got " << moving_threshold_m;
  else if (velocity_half_window < 1) os << "velocity_half_window must be >= 1 frame, got " << velocity_half_window;
  return os.str();
}

Sequence::Sequence(SequenceOptions options) : options_(std::move(options)) {
  if (const std::string err = options_.Validate(); !err.empty()) throw KittiError("bad option: " + err);
  sequence_ = ResolveSequence(options_.dir, options_.sequence);
  paths_ = LocateSequence(options_.dir, sequence_, options_.poses_file, options_.oxts_file,
                          options_.cache_dir, options_.sink);
  calib_ = ReadCalibration(paths_.calib_file);
  if (!paths_.camera_poses_file.empty()) {
    // Boxes layout: the frames are the camera poses' lines; velo0_from_velo_i =
    // velo_from_rect * rect0_from_rect_i * rect_from_velo.
    const std::vector<Eigen::Isometry3d> cam = ReadPoses(paths_.camera_poses_file);
    const Eigen::Affine3d rect_from_velo = calib_.RectFromVelo(), velo_from_rect = calib_.VeloFromRect();
    for (const Eigen::Isometry3d& c : cam) {
      const Eigen::Affine3d v = velo_from_rect * c * rect_from_velo;
      Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
      // Re-orthonormalised: the calibration's blocks are orthonormal only to ~1e-6.
      iso.linear() = Eigen::Quaterniond(v.linear()).normalized().toRotationMatrix();
      iso.translation() = v.translation();
      world_from_body_.push_back(iso);
    }
    num_frames_ = static_cast<int>(world_from_body_.size());
    if (num_frames_ == 0) throw KittiError("poses file " + paths_.camera_poses_file + " has no pose");
  } else {
    num_frames_ = CountFrames(paths_.velodyne_dir);
  }

  if (!paths_.camera_poses_file.empty()) {
    // read above
  } else if (!paths_.poses_file.empty()) {
    world_from_body_ = ReadPoses(paths_.poses_file);
    if (static_cast<int>(world_from_body_.size()) < num_frames_) {
      throw KittiError("poses file " + paths_.poses_file + " has " + std::to_string(world_from_body_.size()) +
                       " poses but the sequence has " + std::to_string(num_frames_) + " frames");
    }
  } else {
    const auto records = ReadOxts(paths_.oxts_file);
    if (static_cast<int>(records.size()) < num_frames_) {
      throw KittiError("OXTS file " + paths_.oxts_file + " has " + std::to_string(records.size()) +
                       " records but the sequence has " + std::to_string(num_frames_) + " frames");
    }
    if (!calib_.velo_from_imu) {
      throw KittiError("calibration file " + paths_.calib_file +
                       " has no Tr_imu_to_velo, needed to use the OXTS poses");
    }
    world_from_body_ = ImuPosesToVeloPoses(OxtsToImuPoses(records), *calib_.velo_from_imu);
    // Express them relative to Velodyne frame 0 (exactly identity already; guard against drift).
    const Eigen::Isometry3d inv0 = world_from_body_.front().inverse();
    for (auto& p : world_from_body_) p = inv0 * p;
  }
  world_from_body_.resize(static_cast<std::size_t>(num_frames_));
  if (options_.no_scans) paths_.velodyne_dir.clear();  // frames counted: read as the boxes layout
  BuildPoseRates();
  detections_.assign(static_cast<std::size_t>(num_frames_), {});
  if (has_detections()) {
    for (const DetectionRow& d : ReadDetections(paths_.detections_file)) {
      if (d.frame >= num_frames_) {
        throw KittiError(paths_.detections_file + ":" + std::to_string(d.line) + ": detection for frame " +
                         std::to_string(d.frame) + " but the sequence has " + std::to_string(num_frames_) +
                         " frames");
      }
      detections_[static_cast<std::size_t>(d.frame)].push_back(d);
    }
  }
  if (has_labels()) {
    labels_ = ReadLabels(paths_.label_file);
    BuildGroundTruth();
  } else {
    objects_.assign(static_cast<std::size_t>(num_frames_), {});
  }
}

void Sequence::CheckFrame(int i) const {
  if (i < 0 || i >= num_frames_) {
    throw KittiError("frame " + std::to_string(i) + " is out of range: sequence " + sequence_ + " has " +
                     std::to_string(num_frames_) + " frames");
  }
}

std::int64_t Sequence::FrameUtime(int i) const { return options_.start_utime + kFramePeriodUs * i; }

std::int64_t Sequence::ScanUtime(int i) const {
  return FrameUtime(i) - options_.velodyne.sweep_duration_us / 2;
}

VelodyneFrame Sequence::ReadFrame(int i) const {
  CheckFrame(i);
  return ReadVelodyneBin((fs::path(paths_.velodyne_dir) / BinName(i)).string());
}

vtrack::ladar_scan_t Sequence::Scan(int i) const { return Scan(i, ReadFrame(i)); }

vtrack::ladar_scan_t Sequence::Scan(int i, const VelodyneFrame& frame) const {
  CheckFrame(i);
  return MakeScan(frame, ScanUtime(i), i, options_.velodyne);
}

const Eigen::Isometry3d& Sequence::WorldFromBody(int i) const {
  CheckFrame(i);
  return world_from_body_[static_cast<std::size_t>(i)];
}

void Sequence::BuildPoseRates() {
  const std::size_t n = world_from_body_.size();
  vel_world_.assign(n, Eigen::Vector3d::Zero());
  rate_body_.assign(n, Eigen::Vector3d::Zero());
  accel_body_.assign(n, Eigen::Vector3d::Zero());
  if (n < 2) return;
  // Central differences inside, one-sided at the ends.
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t a = i == 0 ? 0 : i - 1;
    const std::size_t b = i + 1 == n ? n - 1 : i + 1;
    const double dt = kFramePeriodS * static_cast<double>(b - a);
    vel_world_[i] = (world_from_body_[b].translation() - world_from_body_[a].translation()) / dt;
    // Body-frame angular velocity: R_a^T R_b = exp([w] dt).
    rate_body_[i] = LogSo3(world_from_body_[a].linear().transpose() * world_from_body_[b].linear()) / dt;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t a = i == 0 ? 0 : i - 1;
    const std::size_t b = i + 1 == n ? n - 1 : i + 1;
    const double dt = kFramePeriodS * static_cast<double>(b - a);
    accel_body_[i] = world_from_body_[i].linear().transpose() * (vel_world_[b] - vel_world_[a]) / dt;
  }
}

Eigen::Isometry3d Sequence::WorldFromBodyAt(std::int64_t utime) const {
  if (utime < FirstPoseUtime() || utime > LastPoseUtime()) {
    throw KittiError("pose time " + std::to_string(utime) + " us is outside the sequence's [" +
                     std::to_string(FirstPoseUtime()) + ", " + std::to_string(LastPoseUtime()) + "] us");
  }
  if (num_frames_ == 1) return world_from_body_[0];
  const double f = static_cast<double>(utime - FrameUtime(0)) / static_cast<double>(kFramePeriodUs);
  const int i = std::clamp(static_cast<int>(std::floor(f)), 0, num_frames_ - 2);
  const double s = f - i;  // outside [0, 1] only before frame 0 / after the last frame: extrapolates
  return InterpolatePose(world_from_body_[static_cast<std::size_t>(i)],
                         world_from_body_[static_cast<std::size_t>(i) + 1], s);
}

vtrack::pose_t Sequence::PoseAt(std::int64_t utime) const {
  const Eigen::Isometry3d pose = WorldFromBodyAt(utime);
  Eigen::Vector3d vel, rate, accel;
  if (num_frames_ == 1) {
    vel = vel_world_[0];
    rate = rate_body_[0];
    accel = accel_body_[0];
  } else {
    const double f = static_cast<double>(utime - FrameUtime(0)) / static_cast<double>(kFramePeriodUs);
    const int i = std::clamp(static_cast<int>(std::floor(f)), 0, num_frames_ - 2);
    const double s = std::clamp(f - i, 0.0, 1.0);  // rates are held beyond the ends
    const auto k = static_cast<std::size_t>(i);
    vel = (1.0 - s) * vel_world_[k] + s * vel_world_[k + 1];
    rate = (1.0 - s) * rate_body_[k] + s * rate_body_[k + 1];
    accel = (1.0 - s) * accel_body_[k] + s * accel_body_[k + 1];
  }
  vtrack::pose_t p;
  p.utime = utime;
  Eigen::Quaterniond q(pose.linear());
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  for (int k = 0; k < 3; ++k) {
    p.pos[k] = pose.translation()[k];
    p.vel[k] = vel[k];
    p.rotation_rate[k] = rate[k];
    p.accel[k] = accel[k];
    p.pos_std[k] = -1.0;
  }
  p.orientation[0] = q.w();
  p.orientation[1] = q.x();
  p.orientation[2] = q.y();
  p.orientation[3] = q.z();
  p.yaw_std = -1.0;
  return p;
}

vtrack::pose_t Sequence::EgoPose(int i) const {
  CheckFrame(i);
  return PoseAt(FrameUtime(i));
}

bool Sequence::InLabelledRegionVelo(const Eigen::Vector3d& p_velo) const {
  const Eigen::Vector3d rect = calib_.RectFromVelo() * p_velo;
  const Eigen::Vector3d uvw = (*calib_.P[2]) * rect.homogeneous();
  if (!(uvw.z() > 0.0)) return false;
  const double u = uvw.x() / uvw.z();
  const double v = uvw.y() / uvw.z();
  return u >= 0.0 && u < options_.image_width && v >= 0.0 && v < options_.image_height;
}

bool Sequence::InLabelledRegionWorld(int frame, const Eigen::Vector3d& p_world) const {
  return InLabelledRegionVelo(WorldFromBody(frame).inverse() * p_world);
}

void Sequence::BuildGroundTruth() {
  objects_.assign(static_cast<std::size_t>(num_frames_), {});
  const Eigen::Affine3d velo_from_rect = calib_.VeloFromRect();
  // Per track: indices into (frame, slot) in frame order, for the differences across frames.
  std::map<int, std::vector<std::pair<int, std::size_t>>> tracks;
  for (std::size_t li = 0; li < labels_.size(); ++li) {
    const Label& l = labels_[li];
    if (l.frame >= num_frames_) {
      throw KittiError(paths_.label_file + ":" + std::to_string(l.line) + ": label for frame " +
                       std::to_string(l.frame) + " but the sequence has " + std::to_string(num_frames_) +
                       " frames");
    }
    if (l.IsDontCare()) continue;
    const Eigen::Isometry3d& world_from_velo = world_from_body_[static_cast<std::size_t>(l.frame)];
    // The label's box in the rect frame (y down): bottom centre, centre h/2 above it, and the
    // length axis.
    const Eigen::Vector3d bottom_rect = l.bottom_center_rect;
    const Eigen::Vector3d centre_rect = bottom_rect - Eigen::Vector3d(0.0, 0.5 * l.height, 0.0);
    const Eigen::Vector3d axis_rect = LengthAxisRect(l.rotation_y);
    const Eigen::Vector3d centre_world = world_from_velo * (velo_from_rect * centre_rect);
    const Eigen::Vector3d bottom_world = world_from_velo * (velo_from_rect * bottom_rect);
    const Eigen::Vector3d axis_world = world_from_velo.linear() * (velo_from_rect.linear() * axis_rect);

    vtrack::object_t o;
    o.id = l.track_id;
    o.object_class = ClassOfType(l.type);
    SetBox(centre_world, bottom_world.z(), axis_world, l, &o);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    o.vx = o.vy = o.speed = o.yaw_rate = nan;  // filled below where the track has other frames
    o.rear_axle_offset = nan;                  // unknown for real data
    o.moving = false;
    o.in_labelled_region = InLabelledRegionVelo(velo_from_rect * centre_rect);
    o.num_points = -1;
    auto& slot = objects_[static_cast<std::size_t>(l.frame)];
    for (const auto& other : slot) {
      if (other.object.id == o.id) {
        throw KittiError(paths_.label_file + ":" + std::to_string(l.line) + ": track_id " +
                         std::to_string(l.track_id) + " appears twice in frame " + std::to_string(l.frame));
      }
    }
    tracks[l.track_id].push_back({l.frame, slot.size()});
    slot.push_back({li, o});
  }

  const int w = options_.velocity_half_window;
  for (auto& track : tracks) {
    auto& members = track.second;  // not a structured binding: clang 14 cannot capture those
    std::sort(members.begin(), members.end());
    auto obj = [&](std::size_t k) -> vtrack::object_t& {
      return objects_[static_cast<std::size_t>(members[k].first)][members[k].second].object;
    };
    // Moving: the track leaves a disc of moving_threshold_m about its mean position.
    double mx = 0.0, my = 0.0;
    for (std::size_t k = 0; k < members.size(); ++k) {
      mx += obj(k).x;
      my += obj(k).y;
    }
    mx /= static_cast<double>(members.size());
    my /= static_cast<double>(members.size());
    double max_dev = 0.0;
    for (std::size_t k = 0; k < members.size(); ++k) {
      max_dev = std::max(max_dev, std::hypot(obj(k).x - mx, obj(k).y - my));
    }
    const bool moving = max_dev > options_.moving_threshold_m;
    for (std::size_t k = 0; k < members.size(); ++k) {
      vtrack::object_t& o = obj(k);
      o.moving = moving;
      std::vector<double> t, xs, ys, yaws;
      for (std::size_t j = 0; j < members.size(); ++j) {
        if (std::abs(members[j].first - members[k].first) > w) continue;
        const vtrack::object_t& oj = obj(j);
        t.push_back(kFramePeriodS * (members[j].first - members[k].first));
        xs.push_back(oj.x);
        ys.push_back(oj.y);
        yaws.push_back(o.yaw + AngleDiff(oj.yaw, o.yaw));  // unwrapped about this frame's yaw
      }
      if (t.size() < 2) continue;  // a lone label: velocities stay NaN (unknown)
      o.vx = Slope(t, xs);
      o.vy = Slope(t, ys);
      o.yaw_rate = Slope(t, yaws);
      // The rotation axis lies on the centreline, so its velocity along the heading equals the
      // centre's: speed = v_centre . heading (rigid body; the yaw-rate term is lateral).
      o.speed = o.vx * std::cos(o.yaw) + o.vy * std::sin(o.yaw);
    }
  }
}

vtrack::detection_list_t Sequence::Detections(int i) const {
  CheckFrame(i);
  vtrack::detection_list_t list;
  list.utime = FrameUtime(i);
  list.seq = i;
  list.source = "pointrcnn";
  const Eigen::Affine3d velo_from_rect = calib_.VeloFromRect();
  for (const DetectionRow& d : detections_[static_cast<std::size_t>(i)]) {
    const Eigen::Vector3d bottom = velo_from_rect * d.bottom_center_rect;
    const Eigen::Vector3d axis = velo_from_rect.linear() * LengthAxisRect(d.rotation_y);
    vtrack::detection_t o;
    o.object_class = d.type == 2 ? vtrack::object_t::CLASS_CAR
                     : d.type == 1 ? vtrack::object_t::CLASS_PEDESTRIAN
                     : d.type == 3 ? vtrack::object_t::CLASS_CYCLIST
                                   : vtrack::object_t::CLASS_UNKNOWN;
    o.score = static_cast<float>(d.score);
    SetBox(bottom, bottom.z(), axis, d, &o);
    list.detections.push_back(o);
  }
  list.num_detections = static_cast<std::int32_t>(list.detections.size());
  return list;
}

vtrack::object_list_t Sequence::GroundTruth(int i) const {
  CheckFrame(i);
  if (!has_labels() || objects_[static_cast<std::size_t>(i)].empty() || !has_scans()) {
    return GroundTruth(i, VelodyneFrame{});
  }
  return GroundTruth(i, ReadFrame(i));
}

vtrack::object_list_t Sequence::GroundTruth(int i, const VelodyneFrame& frame) const {
  CheckFrame(i);
  vtrack::object_list_t list;
  list.utime = has_scans() ? ScanUtime(i) : FrameUtime(i);
  list.scan_seq = i;
  list.source = "kitti:" + sequence_;
  const auto& objs = objects_[static_cast<std::size_t>(i)];
  list.num_objects = static_cast<std::int32_t>(objs.size());
  list.objects.reserve(objs.size());
  // Count the returns inside each labelled 3-D box, in the box's own frame in rect coordinates:
  // q = R_y(ry)^T (p - bottom centre); inside iff |q_x| <= l/2, -h <= q_y <= 0, |q_z| <= w/2.
  const Eigen::Affine3d rect_from_velo = calib_.RectFromVelo();
  struct Box {
    Eigen::Vector3d bottom;
    double c, s, half_l, half_w, h, radius2;
    int count = 0;
  };
  std::vector<Box> boxes;
  for (const auto& lo : objs) {
    const Label& l = labels_[lo.label_index];
    Box b;
    b.bottom = l.bottom_center_rect;
    b.c = std::cos(l.rotation_y);
    b.s = std::sin(l.rotation_y);
    b.half_l = 0.5 * l.length;
    b.half_w = 0.5 * l.width;
    b.h = l.height;
    b.radius2 = b.half_l * b.half_l + b.half_w * b.half_w;
    boxes.push_back(b);
  }
  if (!boxes.empty()) {
    const Eigen::Matrix3d a = rect_from_velo.linear();
    const Eigen::Vector3d t = rect_from_velo.translation();
    for (std::size_t k = 0; k < frame.size(); ++k) {
      const Eigen::Vector3d p = a * Eigen::Vector3d(frame.x[k], frame.y[k], frame.z[k]) + t;
      if (!p.allFinite()) continue;
      for (auto& b : boxes) {
        const double dx = p.x() - b.bottom.x();
        const double dz = p.z() - b.bottom.z();
        if (dx * dx + dz * dz > b.radius2) continue;
        const double qx = b.c * dx - b.s * dz;
        const double qz = b.s * dx + b.c * dz;
        const double qy = p.y() - b.bottom.y();
        if (std::abs(qx) <= b.half_l && std::abs(qz) <= b.half_w && qy <= 0.0 && qy >= -b.h) ++b.count;
      }
    }
  }
  for (std::size_t k = 0; k < objs.size(); ++k) {
    vtrack::object_t o = objs[k].object;
    o.num_points = has_scans() ? boxes[k].count : -1;  // no point clouds: unknown
    list.objects.push_back(o);
  }
  return list;
}

}  // namespace vtrack::kitti
