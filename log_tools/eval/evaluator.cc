#include "log_tools/eval/evaluator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <Eigen/Cholesky>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/log_reader.h"
#include "log_tools/eval/gated_assignment.h"
#include "base/angle.h"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/ladar_slice_t.hpp"
#include "vtrack/pose_t.hpp"

namespace vtrack::eval {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

bool IsVehicleClass(std::int8_t c) {
  return c == vtrack::object_t::CLASS_CAR || c == vtrack::object_t::CLASS_VAN ||
         c == vtrack::object_t::CLASS_TRUCK || c == vtrack::object_t::CLASS_SKID_STEER;
}

std::string Encode(const auto& msg) {
  std::string buf(static_cast<std::size_t>(msg.getEncodedSize()), '\0');
  msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
  return buf;
}

// Stores msg under utime; an identical copy (the same log given twice, or a recording that
// holds the tracker's output too) is skipped, a different one is an error.
template <class Msg>
void Insert(std::map<std::int64_t, Msg>* by_time, const Msg& msg, const std::string& key,
            const std::string& what, const std::string& path,
            std::map<std::string, std::int64_t>* problems) {
  auto [it, inserted] = by_time->emplace(msg.utime, msg);
  if (inserted) return;
  if (Encode(it->second) == Encode(msg)) {
    ++(*problems)["duplicate_identical_" + key];
    return;
  }
  std::ostringstream os;
  os << path << ": two different " << what << " messages for utime " << msg.utime
     << " (tracks of two runs of one mode, or two sources of ground truth?); pass the logs of"
        " one run";
  throw std::runtime_error(os.str());
}

std::optional<Eigen::Isometry3d> PoseFromMessage(const vtrack::pose_t& p) {
  Eigen::Quaterniond q(p.orientation[0], p.orientation[1], p.orientation[2], p.orientation[3]);
  const Eigen::Vector3d t(p.pos[0], p.pos[1], p.pos[2]);
  if (!t.allFinite() || !q.coeffs().allFinite() || q.norm() < 1e-6) return std::nullopt;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = q.normalized().toRotationMatrix();
  pose.translation() = t;
  return pose;
}

struct Stats {  // running root-mean-square / mean
  double sum = 0.0, sum_sq = 0.0;
  std::int64_t n = 0;
  void Add(double v) {
    if (!std::isfinite(v)) return;
    sum += v;
    sum_sq += v * v;
    ++n;
  }
  double Rms() const { return n > 0 ? std::sqrt(sum_sq / static_cast<double>(n)) : kNaN; }
  double Mean() const { return n > 0 ? sum / static_cast<double>(n) : kNaN; }
};

// Linear interpolation of (pred_x, pred_y) at pred time h [s]; nullopt outside the prediction.
std::optional<Eigen::Vector2d> PredictedAt(const vtrack::track_t& tr, double h) {
  const int n = std::min<int>(tr.npred, static_cast<int>(tr.pred_t.size()));
  if (n <= 0) return std::nullopt;
  constexpr double kTol = 1e-3;  // [s] float pred_t against a horizon such as 1.0
  if (h < tr.pred_t[0] - kTol || h > tr.pred_t[n - 1] + kTol) return std::nullopt;
  if (n == 1) return Eigen::Vector2d(tr.pred_x[0], tr.pred_y[0]);
  int k = 0;
  while (k + 2 < n && tr.pred_t[k + 1] < h) ++k;
  const double t0 = tr.pred_t[k], t1 = tr.pred_t[k + 1];
  const double s = t1 > t0 ? std::clamp((h - t0) / (t1 - t0), 0.0, 1.0) : 0.0;
  Eigen::Vector2d p((1 - s) * tr.pred_x[k] + s * tr.pred_x[k + 1],
                    (1 - s) * tr.pred_y[k] + s * tr.pred_y[k + 1]);
  if (!p.allFinite()) return std::nullopt;
  return p;
}

// A track's centre and orientation dt seconds after its utime, at constant velocity and yaw rate.
struct TrackPose {
  double x, y, theta;
};
TrackPose Advance(const vtrack::track_t& tr, double dt) {
  if (dt == 0.0) return {tr.x, tr.y, tr.theta};
  const double speed = std::isfinite(tr.speed) ? tr.speed : 0.0;
  const double heading = std::isfinite(tr.velocity_heading) ? tr.velocity_heading : tr.theta;
  const double yaw_rate = std::isfinite(tr.yaw_rate) ? tr.yaw_rate : 0.0;
  return {tr.x + speed * std::cos(heading) * dt, tr.y + speed * std::sin(heading) * dt,
          WrapToPi(tr.theta + yaw_rate * dt)};
}

const vtrack::object_t* FindObject(const vtrack::object_list_t& list, std::int64_t id) {
  for (const auto& o : list.objects) {
    if (o.id == id) return &o;
  }
  return nullptr;
}

// Position of truth object id at utime, interpolated between the ground-truth scans around it.
std::optional<Eigen::Vector2d> TruthAt(const std::map<std::int64_t, vtrack::object_list_t>& truth,
                                       std::int64_t id, std::int64_t utime, double max_gap_s) {
  auto hi = truth.lower_bound(utime);
  if (hi == truth.end()) return std::nullopt;  // beyond the log
  const vtrack::object_t* b = FindObject(hi->second, id);
  if (hi->first == utime) {
    if (!b) return std::nullopt;
    return Eigen::Vector2d(b->x, b->y);
  }
  if (hi == truth.begin() || !b) return std::nullopt;
  auto lo = std::prev(hi);
  const vtrack::object_t* a = FindObject(lo->second, id);
  if (!a) return std::nullopt;
  const double gap = static_cast<double>(hi->first - lo->first) * 1e-6;
  if (gap > max_gap_s) return std::nullopt;
  const double s = static_cast<double>(utime - lo->first) / static_cast<double>(hi->first - lo->first);
  return Eigen::Vector2d((1 - s) * a->x + s * b->x, (1 - s) * a->y + s * b->y);
}

// The heading [rad] of truth object id at utime (interpolated the short way round between the
// lists around it, as TruthAt); nullopt where TruthAt has no position.
std::optional<double> TruthYawAt(const std::map<std::int64_t, vtrack::object_list_t>& truth,
                                 std::int64_t id, std::int64_t utime, double max_gap_s) {
  if (!TruthAt(truth, id, utime, max_gap_s)) return std::nullopt;
  auto hi = truth.lower_bound(utime);
  const vtrack::object_t* b = FindObject(hi->second, id);
  if (hi->first == utime) return b->yaw;
  const vtrack::object_t* a = FindObject(std::prev(hi)->second, id);
  const double s = static_cast<double>(utime - std::prev(hi)->first) /
                   static_cast<double>(hi->first - std::prev(hi)->first);
  return WrapToPi(a->yaw + s * AngleDiff(b->yaw, a->yaw));
}

// True if an object or track of a frame can be scored: its position and heading are finite (a
// NaN would poison every error sum it entered) and its id is new in the frame (ids holds those
// seen). Otherwise counts "<kind>_not_finite" or "<kind>_duplicate_id" in *problems (printed in
// the report's "input problem" lines and its JSON "problems") and returns false.
bool Admit(double x, double y, double heading, std::int64_t id, const std::string& kind,
           std::set<std::int64_t>* ids, std::map<std::string, std::int64_t>* problems) {
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(heading)) {
    ++(*problems)[kind + "_not_finite"];
    return false;
  }
  if (!ids->insert(id).second) {
    ++(*problems)[kind + "_duplicate_id"];
    return false;
  }
  return true;
}

}  // namespace

bool CameraRegion::Contains(const Eigen::Vector3d& p_sensor) const {
  const Eigen::Vector3d rect = rect_from_sensor * p_sensor;
  const Eigen::Vector3d img = P * rect.homogeneous();
  if (!(rect.z() > 0.1) || !(img.z() > 0.0)) return false;  // behind or at the camera
  const double u = img.x() / img.z();
  return u >= 0.0 && u < static_cast<double>(width);
}

std::string EvalParams::Validate() const {
  std::ostringstream os;
  auto positive = [&](const char* key, double v) {
    if (os.tellp() == 0 && !(v > 0.0 && std::isfinite(v))) os << key << " must be > 0, got " << v;
  };
  if (truth_channel.empty() || tracks_channel.empty()) {
    os << "truth_channel and tracks_channel must not be empty";
  }
  positive("gate_m", gate_m);
  positive("hota_gate_m", hota_gate_m);
  positive("max_truth_gap_s", max_truth_gap_s);
  positive("max_pose_gap_s", max_pose_gap_s);
  if (os.tellp() == 0 && !(region_range_m >= 0.0 && std::isfinite(region_range_m))) {
    os << "region_range_m must be >= 0 (0 = no limit), got " << region_range_m;
  }
  if (os.tellp() == 0 && !(region_fov_deg > 0.0 && region_fov_deg <= 360.0)) {
    os << "region_fov_deg must be in (0, 360], got " << region_fov_deg;
  }
  if (os.tellp() == 0 && !(moving_speed_mps >= 0.0 && std::isfinite(moving_speed_mps))) {
    os << "moving_speed_mps must be >= 0, got " << moving_speed_mps;
  }
  for (const double h : horizons_s) positive("horizons_s", h);
  if (os.tellp() == 0 && !(turning_yaw_rate >= 0.0 && std::isfinite(turning_yaw_rate))) {
    os << "turning_yaw_rate must be >= 0, got " << turning_yaw_rate;
  }
  if (os.tellp() == 0 && std::isinf(truth_time_offset_s)) {
    os << "truth_time_offset_s must be finite (or NaN for half the sweep), got " << truth_time_offset_s;
  }
  if (os.tellp() == 0 && region_camera && region_camera->width <= 0) {
    os << "region_camera.width must be > 0, got " << region_camera->width;
  }
  if (os.tellp() == 0 && dont_care) {
    if (!region_camera) {
      os << "dont_care needs region_camera (the ego pose and the sensor mounting)";
    } else if (!(dont_care->min_overlap > 0.0 && dont_care->min_overlap <= 1.0)) {
      os << "dont_care.min_overlap must be in (0, 1], got " << dont_care->min_overlap;
    } else if (const std::string err = dont_care->camera.Validate(); !err.empty()) {
      os << "dont_care.camera: " << err;
    }
  }
  if (os.tellp() == 0) {
    ClearMotParams c;
    c.gate_m = gate_m;
    c.mostly_tracked_ratio = mostly_tracked_ratio;
    c.mostly_lost_ratio = mostly_lost_ratio;
    os << c.Validate();
  }
  return os.str();
}

namespace {

// The sensor mounting and sweep duration of a scan or a slice of one (the first valid one).
template <class Msg>
void TakeMounting(const Msg& msg, LogData* data) {
  Eigen::Quaterniond q(msg.sensor_orientation[0], msg.sensor_orientation[1],
                       msg.sensor_orientation[2], msg.sensor_orientation[3]);
  const Eigen::Vector3d t(msg.sensor_pos[0], msg.sensor_pos[1], msg.sensor_pos[2]);
  if (t.allFinite() && q.coeffs().allFinite() && q.norm() > 1e-6) {
    Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
    m.linear() = q.normalized().toRotationMatrix();
    m.translation() = t;
    data->body_from_sensor = m;
    data->sweep_duration_us = msg.sweep_duration_us;
  }
}

}  // namespace

void AddLog(LogData* data, const std::string& path, const EvalParams& params,
            const std::function<void(const std::string&, double)>& progress) {
  data->paths.push_back(path);
  std::string why;
  lcm_util::LogReader reader(path);
  std::int64_t events = 0;
  struct DamageNote {  // noted however the loop ends
    const lcm_util::LogReader& reader;
    LogData* data;
    ~DamageNote() {
      if (reader.damaged()) data->damaged_logs.push_back(reader.DamageSummary());
    }
  } note{reader, data};
  while (const lcm::LogEvent* ev = reader.Next()) {
    if (progress && (++events % 256) == 0 && reader.FileSize() > 0) {
      progress(path, static_cast<double>(reader.BytesRead()) / reader.FileSize());
    }
    const auto size = static_cast<std::size_t>(std::max<std::int32_t>(ev->datalen, 0));
    if (ev->channel == params.truth_channel) {
      vtrack::object_list_t msg;
      if (lcm_util::Decode(ev->data, size, &msg, &why) != lcm_util::DecodeError::kNone) {
        ++data->problems["decode_error_" + params.truth_channel];
        continue;
      }
      Insert(&data->truth, msg, "truth", "ground-truth", path, &data->problems);
    } else if (ev->channel == params.tracks_channel) {
      vtrack::track_list_t msg;
      if (lcm_util::Decode(ev->data, size, &msg, &why) != lcm_util::DecodeError::kNone) {
        ++data->problems["decode_error_" + params.tracks_channel];
        continue;
      }
      Insert(&data->tracks[msg.mode], msg, "tracks", "track-list (mode '" + msg.mode + "')",
             path, &data->problems);
    } else if (ev->channel == params.pose_channel) {
      vtrack::pose_t msg;
      if (lcm_util::Decode(ev->data, size, &msg, &why) != lcm_util::DecodeError::kNone) {
        ++data->problems["decode_error_" + params.pose_channel];
        continue;
      }
      if (auto pose = PoseFromMessage(msg)) {
        data->pose_samples.emplace_back(msg.utime, *pose);
      } else {
        ++data->problems["invalid_pose"];
      }
    } else if (ev->channel == params.scan_channel && !data->body_from_sensor) {
      vtrack::ladar_scan_t msg;
      if (lcm_util::Decode(ev->data, size, &msg, &why) != lcm_util::DecodeError::kNone) {
        ++data->problems["decode_error_" + params.scan_channel];
        continue;
      }
      TakeMounting(msg, data);
    } else if (ev->channel == params.slice_channel && !data->body_from_sensor) {
      vtrack::ladar_slice_t msg;
      if (lcm_util::Decode(ev->data, size, &msg, &why) != lcm_util::DecodeError::kNone) {
        ++data->problems["decode_error_" + params.slice_channel];
        continue;
      }
      TakeMounting(msg, data);
    }
  }
  if (progress) progress(path, 1.0);

  // Poses of every log so far, in time order (the logs may interleave).
  std::stable_sort(data->pose_samples.begin(), data->pose_samples.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  data->poses.Clear();
  std::int64_t duplicates = 0;
  for (const auto& [utime, pose] : data->pose_samples) {
    if (data->poses.Add(utime, pose) != PoseHistory::AddResult::kOk) ++duplicates;
  }
  if (duplicates > 0) {
    data->problems["duplicate_pose"] = duplicates;
  } else {
    data->problems.erase("duplicate_pose");
  }
}

LogData LoadLogs(const std::vector<std::string>& paths, const EvalParams& params,
                 const std::function<void(const std::string&, double)>& progress) {
  LogData data;
  for (const std::string& path : paths) AddLog(&data, path, params, progress);
  return data;
}

std::string SelectMode(const LogData& data, const EvalParams& params) {
  // "; N of them undecodable" where the channel's messages were there but none could be read.
  const auto undecodable = [&](const std::string& channel) {
    const auto it = data.problems.find("decode_error_" + channel);
    return it == data.problems.end() ? std::string()
                                     : ": " + std::to_string(it->second) + " messages on it could not be decoded";
  };
  if (data.truth.empty()) {
    throw std::runtime_error("no ground truth (object_list_t on channel '" + params.truth_channel +
                             "') in the logs" + undecodable(params.truth_channel));
  }
  if (data.tracks.empty()) {
    throw std::runtime_error("no tracks (track_list_t on channel '" + params.tracks_channel +
                             "') in the logs" + undecodable(params.tracks_channel));
  }
  if (!params.mode.empty()) {
    if (!data.tracks.count(params.mode)) {
      std::string modes;
      for (const auto& [m, l] : data.tracks) modes += (modes.empty() ? "'" : ", '") + m + "'";
      throw std::runtime_error("no tracks of mode '" + params.mode + "' in the logs (found " +
                               modes + ")");
    }
    return params.mode;
  }
  if (data.tracks.size() > 1) {
    std::string modes;
    for (const auto& [m, l] : data.tracks) modes += (modes.empty() ? "'" : ", '") + m + "'";
    throw std::runtime_error("the logs hold tracks of several tracker modes (" + modes +
                             "): choose one with --mode, or compare them with vtrack-compare");
  }
  return data.tracks.begin()->first;
}

EvalSummary Evaluate(const LogData& data, const EvalParams& params,
                     std::vector<TrackLabel>* labels) {
  if (const std::string err = params.Validate(); !err.empty()) {
    throw std::runtime_error("invalid evaluation parameter: " + err);
  }
  if (labels) labels->clear();
  EvalSummary s;
  s.params = params;
  s.logs = data.paths;
  s.problems = data.problems;
  s.mode = SelectMode(data, params);
  const auto& track_lists = data.tracks.at(s.mode);
  if (params.RegionEnabled() && data.poses.empty()) {
    throw std::runtime_error("a scoring region (range/field of view) needs the ego pose, but the "
                             "logs hold no pose_t on channel '" + params.pose_channel + "'");
  }
  s.truth_time_offset_s = params.truth_time_offset_s;
  if (std::isnan(s.truth_time_offset_s)) {
    if (!data.sweep_duration_us) {
      throw std::runtime_error("the truth time offset 'half the sweep' needs a LADAR_SCAN on channel '" +
                               params.scan_channel + "' or a LADAR_SLICE on '" +
                               params.slice_channel + "' in the logs");
    }
    s.truth_time_offset_s = 0.5e-6 * static_cast<double>(*data.sweep_duration_us);
  }
  const double dt = s.truth_time_offset_s;
  const auto offset_us = static_cast<std::int64_t>(std::llround(dt * 1e6));
  const double half_fov = DegToRad(params.region_fov_deg) / 2.0;
  Eigen::Isometry3d body_from_sensor = Eigen::Isometry3d::Identity();
  if (params.region_camera) {
    if (data.body_from_sensor) {
      body_from_sensor = *data.body_from_sensor;
    } else {
      // Said in the summary's problems: the camera region then assumes sensor = body.
      s.problems["camera_region_without_scan_mounting_assumed_sensor_at_body_origin"] = 1;
    }
  }
  const auto max_pose_gap_us = static_cast<std::int64_t>(params.max_pose_gap_s * 1e6);

  // Per scored frame: the message objects behind each ScoringFrame entry.
  std::vector<ScoringFrame> frames;
  std::vector<std::vector<const vtrack::object_t*>> frame_truth;
  std::vector<std::vector<const vtrack::track_t*>> frame_tracks;
  std::vector<std::vector<TrackPose>> frame_track_poses;  // advanced by the truth time offset

  std::int64_t list_index = 0;
  bool dont_care_frame_found = false;  // a DontCare test met a frame with regions
  for (const auto& [utime, list] : track_lists) {
    const std::int64_t kitti_frame = KittiFrame(list, list_index++);
    const std::int64_t scan_utime = utime;  // lambdas take a copy: clang 14 cannot capture a structured binding
    const auto gt_it = data.truth.find(utime);
    if (gt_it == data.truth.end()) {
      ++s.tracks_without_truth;
      continue;
    }
    const vtrack::object_list_t& gt = gt_it->second;

    std::optional<Eigen::Isometry3d> ego;
    if (params.RegionEnabled()) {
      ego = data.poses.At(utime, max_pose_gap_us);
      if (!ego) {
        ++s.problems["scan_without_pose"];
        continue;
      }
    }
    // z: the object's centre height in the world, or nullopt for a track (which has none).
    auto in_region = [&](double x, double y, std::optional<double> z) {
      if (!ego) return true;
      const Eigen::Vector2d d = Eigen::Vector2d(x, y) - ego->translation().head<2>();
      if (params.region_range_m > 0.0 && d.norm() > params.region_range_m) return false;
      if (params.region_fov_deg < 360.0 &&
          std::abs(AngleDiff(std::atan2(d.y(), d.x()), YawOf(*ego))) > half_fov) {
        return false;
      }
      if (params.region_camera) {
        const Eigen::Isometry3d world_from_sensor = *ego * body_from_sensor;
        Eigen::Vector3d p_sensor = world_from_sensor.inverse() * Eigen::Vector3d(x, y, z.value_or(0.0));
        if (!z) p_sensor.z() = params.region_camera->track_z_sensor_m;
        if (!params.region_camera->Contains(p_sensor)) return false;
      }
      return true;
    };

    // KITTI's DontCare rule (EvalParams::dont_care): the track's image box lies in one of this
    // frame's DontCare regions by more than min_overlap of its area.
    // The camera where it was at the truth's time, as the track (tp, advanced to that time).
    const auto in_dont_care = [&](const vtrack::track_t& tr, const TrackPose& tp) {
      if (!params.dont_care) return false;
      const auto regions = params.dont_care->boxes.find(kitti_frame);
      if (regions == params.dont_care->boxes.end()) return false;
      const auto camera_pose = data.poses.At(scan_utime + offset_us, max_pose_gap_us);
      if (!camera_pose) return false;
      const Eigen::Isometry3d sensor_from_world = (*camera_pose * body_from_sensor).inverse();
      const std::optional<ImageBox> image = ProjectToImage(
          TrackBoxInSensor(tr, tp.x, tp.y, tp.theta, sensor_from_world, params.dont_care->camera),
          tr.length, tr.width, params.dont_care->camera);
      return image && std::any_of(regions->second.begin(), regions->second.end(),
                                  [&](const ImageBox& r) {
                                    return OverlapOfFirst(*image, r) > params.dont_care->min_overlap;
                                  });
    };

    if (params.dont_care && params.dont_care->boxes.count(kitti_frame)) dont_care_frame_found = true;
    ScoringFrame f;
    f.utime = utime;
    std::vector<const vtrack::object_t*> scored, all_truth;
    std::vector<bool> truth_scored;
    std::set<std::int64_t> truth_ids;
    for (const auto& o : gt.objects) {
      if (!Admit(o.x, o.y, o.yaw, o.id, "truth", &truth_ids, &s.problems)) continue;
      const bool is_scored =
          o.in_labelled_region && IsVehicleClass(o.object_class) &&
          in_region(o.x, o.y,
                    std::isfinite(o.z + 0.5 * o.height) ? std::optional<double>(o.z + 0.5 * o.height)
                                                         : std::nullopt);
      all_truth.push_back(&o);
      truth_scored.push_back(is_scored);
      if (is_scored) {
        scored.push_back(&o);
        f.gt_ids.push_back(o.id);
        f.gt_xy.emplace_back(o.x, o.y);
      }
    }

    if (labels) {
      // Every track of the frame, whatever its status and class, against the nearest truth
      // object of any class. Refused tracks are counted apart: the summary's problems stay those
      // of the scoring.
      std::optional<Eigen::Isometry3d> range_pose = ego;
      if (!range_pose && !data.poses.empty()) range_pose = data.poses.At(utime, max_pose_gap_us);
      std::set<std::int64_t> label_ids;
      std::map<std::string, std::int64_t> label_problems;
      for (const auto& tr : list.tracks) {
        if (!Admit(tr.x, tr.y, tr.theta, tr.id, "track", &label_ids, &label_problems)) continue;
        const TrackPose tp = Advance(tr, dt);
        TrackLabel row;
        row.utime = utime;
        row.track_id = tr.id;
        row.range_m = range_pose ? (Eigen::Vector2d(tp.x, tp.y) -
                                    range_pose->translation().head<2>()).norm()
                                 : kNaN;
        int nearest = -1;
        row.distance_m = kNaN;
        for (std::size_t i = 0; i < all_truth.size(); ++i) {
          const double d = std::hypot(tp.x - all_truth[i]->x, tp.y - all_truth[i]->y);
          if (nearest < 0 || d < row.distance_m) {
            nearest = static_cast<int>(i);
            row.distance_m = d;
          }
        }
        const bool gated = nearest >= 0 && row.distance_m < params.gate_m;
        if (gated) {
          row.truth_id = all_truth[nearest]->id;
          row.truth_class = all_truth[nearest]->object_class;
        }
        if (!in_region(tp.x, tp.y, std::nullopt)) {
          row.label = -1;
        } else if (!gated) {
          row.label = in_dont_care(tr, tp) ? -1 : 0;  // KITTI labels nothing there
        } else if (truth_scored[nearest]) {
          row.label = 1;
        } else if (IsVehicleClass(all_truth[nearest]->object_class) ||
                   all_truth[nearest]->object_class == vtrack::object_t::CLASS_UNKNOWN) {
          row.label = -1;
        } else {
          row.label = 0;
        }
        labels->push_back(row);
      }
    }

    // Candidate tracks, then drop those paired with ignored truth, or unpaired outside the region.
    std::vector<const vtrack::track_t*> candidates;
    std::vector<TrackPose> candidate_pose;
    std::set<std::int64_t> track_ids;
    for (const auto& tr : list.tracks) {
      const bool status_ok = tr.status == vtrack::track_t::STATUS_CONFIRMED ||
                             (params.score_coasting && tr.status == vtrack::track_t::STATUS_COASTING);
      if (!status_ok || tr.object_class != vtrack::track_t::CLASS_VEHICLE) continue;
      if (!Admit(tr.x, tr.y, tr.theta, tr.id, "track", &track_ids, &s.problems)) continue;
      candidates.push_back(&tr);
      candidate_pose.push_back(Advance(tr, dt));
    }
    Eigen::MatrixXd cost(candidates.size(), all_truth.size());
    for (std::size_t j = 0; j < candidates.size(); ++j) {
      for (std::size_t i = 0; i < all_truth.size(); ++i) {
        const double d = std::hypot(candidate_pose[j].x - all_truth[i]->x,
                                    candidate_pose[j].y - all_truth[i]->y);
        cost(j, i) = d < params.gate_m ? d : kInf;
      }
    }
    std::vector<int> partner(candidates.size(), -1);
    for (const auto& [j, i] : GatedAssignment(cost)) partner[j] = i;
    std::vector<const vtrack::track_t*> kept;
    std::vector<TrackPose> kept_pose;
    for (std::size_t j = 0; j < candidates.size(); ++j) {
      const vtrack::track_t* tr = candidates[j];
      if (partner[j] >= 0 && !truth_scored[partner[j]]) {
        ++s.ignored_track_detections;
        continue;
      }
      const TrackPose& tp = candidate_pose[j];
      if (partner[j] < 0 && !in_region(tp.x, tp.y, std::nullopt)) {
        ++s.outside_region_track_detections;
        continue;
      }
      if (partner[j] < 0 && in_dont_care(*tr, tp)) {
        ++s.dont_care_track_detections;
        continue;
      }
      kept.push_back(tr);
      kept_pose.push_back(tp);
      f.track_ids.push_back(tr->id);
      f.track_xy.emplace_back(tp.x, tp.y);
    }
    frames.push_back(std::move(f));
    frame_truth.push_back(std::move(scored));
    frame_tracks.push_back(std::move(kept));
    frame_track_poses.push_back(std::move(kept_pose));
  }
  for (const auto& [utime, gt] : data.truth) {
    if (!track_lists.count(utime)) ++s.scans_without_tracks;
  }
  if (params.dont_care && !params.dont_care->boxes.empty() && !dont_care_frame_found) {
    // DontCare regions given, none of them in a scored frame: labels of another sequence?
    s.problems["kitti_dontcare_regions_in_no_scored_frame"] = 1;
  }
  if (frames.empty()) {
    throw std::runtime_error("no scan has both ground truth and tracks of mode '" + s.mode +
                             "' with the same utime: are these logs of the same run?");
  }

  ClearMotParams cp;
  cp.gate_m = params.gate_m;
  cp.mostly_tracked_ratio = params.mostly_tracked_ratio;
  cp.mostly_lost_ratio = params.mostly_lost_ratio;
  s.clear = ComputeClearMot(frames, cp);
  HotaParams hp;
  hp.similarity_gate_m = params.hota_gate_m;
  s.hota = ComputeHota(frames, hp);
  s.scans = static_cast<std::int64_t>(frames.size());

  // State errors on the CLEAR MOT matches.
  const std::int64_t t0 = frames.front().utime;
  const std::size_t nh = params.horizons_s.size();
  Stats pos, head, speed, yaw_rate, axle, nees;
  std::vector<Stats> pred(nh), pred_turning(nh), pred_straight(nh);
  std::int64_t flips = 0, nees_inside = 0;
  struct PerTrack {
    TrackRow row;
    Stats pos, head, speed, yaw_rate, axle, nees;
    std::vector<Stats> pred;
    std::map<std::int64_t, std::int64_t> truth_counts;
  };
  std::map<std::int64_t, PerTrack> per_track;

  for (std::size_t t = 0; t < frames.size(); ++t) {
    const ScoringFrame& f = frames[t];
    const double ts = static_cast<double>(f.utime - t0) * 1e-6;
    ScanCounts c;
    c.t_s = ts;
    c.utime = f.utime;
    c.gt = static_cast<int>(f.gt_ids.size());
    c.tp = static_cast<int>(s.clear.matches[t].size());
    c.fn = c.gt - c.tp;
    c.fp = static_cast<int>(f.track_ids.size()) - c.tp;
    for (std::size_t j = 0; j < f.track_ids.size(); ++j) {
      PerTrack& p = per_track[f.track_ids[j]];
      if (p.row.scans == 0) {
        p.row.track_id = f.track_ids[j];
        p.row.first_s = ts;
        p.pred.resize(nh);
      }
      p.row.last_s = ts;
      ++p.row.scans;
    }
    for (const Match& m : s.clear.matches[t]) {
      const vtrack::object_t& o = *frame_truth[t][m.gt];
      const vtrack::track_t& tr = *frame_tracks[t][m.track];
      const TrackPose& tp = frame_track_poses[t][m.track];
      PairSample ps;
      ps.t_s = ts;
      ps.utime = f.utime;
      ps.truth_id = o.id;
      ps.track_id = tr.id;
      ps.id_switch = m.id_switch;
      c.id_switches += m.id_switch ? 1 : 0;
      ps.position_error_m = m.distance_m;
      const double dth = AngleDiff(tp.theta, o.yaw);
      ps.heading_flipped = std::abs(dth) > kPi / 2.0;
      const double folded = ps.heading_flipped ? WrapToPi(dth + kPi) : dth;
      ps.heading_error_deg = RadToDeg(folded);
      const double truth_speed = std::hypot(o.vx, o.vy);
      ps.speed_error_mps = tr.speed - truth_speed;
      ps.yaw_rate_error_dps = RadToDeg(tr.yaw_rate - o.yaw_rate);
      ps.rear_axle_error_m = kNaN;
      if (std::isfinite(tr.rear_axle_offset) && std::isfinite(o.rear_axle_offset) &&
          truth_speed > params.moving_speed_mps) {
        const double l = ps.heading_flipped ? -tr.rear_axle_offset : tr.rear_axle_offset;
        ps.rear_axle_error_m = l - o.rear_axle_offset;
      }
      // NEES of (x, y, theta).
      Eigen::Matrix3d cov;
      for (int r = 0; r < 3; ++r) {
        for (int k = 0; k < 3; ++k) cov(r, k) = tr.cov[3 * r + k];
      }
      ps.nees = kNaN;
      if (cov.allFinite() && (cov - cov.transpose()).cwiseAbs().maxCoeff() <=
                                 1e-9 * std::max(1.0, cov.cwiseAbs().maxCoeff())) {
        Eigen::LLT<Eigen::Matrix3d> llt(0.5 * (cov + cov.transpose()));
        if (llt.info() == Eigen::Success) {
          const Eigen::Vector3d e(tp.x - o.x, tp.y - o.y, folded);
          ps.nees = e.dot(llt.solve(e));
        }
      }
      if (!std::isfinite(ps.nees)) ++s.nees_invalid;
      // Prediction at each horizon.
      ps.prediction_error_m.assign(nh, kNaN);
      for (std::size_t h = 0; h < nh; ++h) {
        const auto p = PredictedAt(tr, params.horizons_s[h]);
        if (!p) continue;
        // The truth list stamped u describes u + offset: the truth at time utime + k is the list
        // time utime + k - offset.
        const auto when =
            f.utime + static_cast<std::int64_t>(std::llround(params.horizons_s[h] * 1e6)) - offset_us;
        const auto truth_then = TruthAt(data.truth, o.id, when, params.max_truth_gap_s);
        if (!truth_then) continue;
        ps.prediction_error_m[h] = (*p - *truth_then).norm();
        // Turning or straight over this horizon, from the truth's headings alone.
        const auto yaw_then = TruthYawAt(data.truth, o.id, when, params.max_truth_gap_s);
        const auto yaw_now = TruthYawAt(data.truth, o.id, f.utime - offset_us, params.max_truth_gap_s);
        const double yaw_from = yaw_now ? *yaw_now : o.yaw;
        if (yaw_then && std::abs(AngleDiff(*yaw_then, yaw_from)) >
                            params.turning_yaw_rate * params.horizons_s[h]) {
          pred_turning[h].Add(ps.prediction_error_m[h]);
        } else if (yaw_then) {
          pred_straight[h].Add(ps.prediction_error_m[h]);
        }
      }

      pos.Add(ps.position_error_m);
      head.Add(ps.heading_error_deg);
      speed.Add(ps.speed_error_mps);
      yaw_rate.Add(ps.yaw_rate_error_dps);
      axle.Add(ps.rear_axle_error_m);
      nees.Add(ps.nees);
      if (std::isfinite(ps.nees) && ps.nees <= kChi2Dof3Quantile95) ++nees_inside;
      flips += ps.heading_flipped ? 1 : 0;
      for (std::size_t h = 0; h < nh; ++h) pred[h].Add(ps.prediction_error_m[h]);

      PerTrack& p = per_track[tr.id];
      ++p.row.matched;
      ++p.truth_counts[o.id];
      p.row.id_switches += m.id_switch ? 1 : 0;
      p.pos.Add(ps.position_error_m);
      p.head.Add(ps.heading_error_deg);
      p.speed.Add(ps.speed_error_mps);
      p.yaw_rate.Add(ps.yaw_rate_error_dps);
      p.axle.Add(ps.rear_axle_error_m);
      p.nees.Add(ps.nees);
      for (std::size_t h = 0; h < nh; ++h) p.pred[h].Add(ps.prediction_error_m[h]);
      s.pairs.push_back(std::move(ps));
    }
    s.per_scan.push_back(c);
  }

  s.position_rmse_m = pos.Rms();
  s.heading_rmse_deg = head.Rms();
  s.heading_flip_fraction = pos.n > 0 ? static_cast<double>(flips) / pos.n : kNaN;
  s.speed_rmse_mps = speed.Rms();
  s.yaw_rate_rmse_dps = yaw_rate.Rms();
  s.rear_axle_rmse_m = axle.Rms();
  s.rear_axle_samples = axle.n;
  for (std::size_t h = 0; h < nh; ++h) {
    s.prediction_error_m.push_back(pred[h].Mean());
    s.prediction_samples.push_back(pred[h].n);
    s.prediction_error_turning_m.push_back(pred_turning[h].Mean());
    s.prediction_samples_turning.push_back(pred_turning[h].n);
    s.prediction_error_straight_m.push_back(pred_straight[h].Mean());
    s.prediction_samples_straight.push_back(pred_straight[h].n);
  }
  s.nees_mean = nees.Mean();
  s.nees_samples = nees.n;
  s.nees_within_95 = nees.n > 0 ? static_cast<double>(nees_inside) / nees.n : kNaN;
  s.scored_tracks = static_cast<std::int64_t>(per_track.size());
  for (auto& [id, p] : per_track) {
    TrackRow& row = p.row;
    for (const auto& [truth_id, n] : p.truth_counts) {
      if (n > row.truth_scans) {
        row.truth_scans = n;
        row.truth_id = truth_id;
      }
    }
    row.position_rmse_m = p.pos.Rms();
    row.heading_rmse_deg = p.head.Rms();
    row.speed_rmse_mps = p.speed.Rms();
    row.yaw_rate_rmse_dps = p.yaw_rate.Rms();
    row.rear_axle_rmse_m = p.axle.Rms();
    row.nees_mean = p.nees.Mean();
    for (std::size_t h = 0; h < nh; ++h) row.prediction_error_m.push_back(p.pred[h].Mean());
    s.per_track.push_back(row);
  }
  return s;
}

}  // namespace vtrack::eval
