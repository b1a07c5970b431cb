// libFuzzer harness for the tracker: vtrack-tracker's node (TrackerNode: checked decoding,
// message conversion, the core Tracker with sequencing, preprocessing, segmentation,
// association, fitting, the multi-hypothesis track manager, and the TRACKS / TRACK_DEBUG /
// TRACKER_STATUS encoders) fed arbitrary scans and poses. The input is a small program
// (tracker_program.h): a scene of moving boxes seen by a moving ego, whose scans and poses the
// fuzzer perturbs in time (repeats, jumps back, gaps), in content (NaN/Inf/far returns, returns
// outside the sweep, degenerate geometry: all returns on one point or one line, duplicates,
// huge scans, bad mountings and poses) and in encoding (raw bytes, inflated length fields).
//
// Oracle (std::abort with a message on any violation, besides the sanitizers):
//  - the node never throws and never reports an internal error;
//  - scans received = processed + dropped + queued, after every message, and every dropped scan
//    is counted under exactly one scan reason (dropped = their sum, tracker/README.md);
//  - every TRACKS / TRACK_DEBUG / TRACKER_STATUS message decodes (Decode<T>) and every reported
//    track has finite position, heading, covariance (with a non-negative diagonal) and size;
//  - track ids are unique within a message and an id that has disappeared never comes back;
//  - a pose with NaN or a non-rotation quaternion is counted "invalid_pose", and a scan whose
//    mounting is not a rotation is counted "bad_scan" (refused, not used with a scaled frame).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>
#include <string>
#include <vector>

#include "lcmtypes/util/decode.h"
#include "tests/fuzz/tracker_program.h"
#include "tracker/core/parameters.h"
#include "tracker/tracker_node.h"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/pose_t.hpp"
#include "vtrack/track_debug_t.hpp"
#include "vtrack/track_list_t.hpp"
#include "vtrack/tracker_status_t.hpp"

namespace vtrack::fuzz {
namespace {

[[noreturn]] void Fail(const std::string& what) {
  std::fprintf(stderr, "tracker_fuzzer: %s\n", what.c_str());
  std::abort();
}

// Reads the program; bytes past the end read as zero. (libFuzzer's FuzzedDataProvider would do,
// but it ships with clang only, and the regression replay builds with gcc.)
class Reader {
 public:
  Reader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool done() const { return pos_ >= size_; }
  std::uint8_t U8() { return pos_ < size_ ? data_[pos_++] : 0; }
  std::int8_t I8() { return static_cast<std::int8_t>(U8()); }
  std::int16_t I16() { return static_cast<std::int16_t>((U8() << 8) | U8()); }
  std::int32_t I32() {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v = (v << 8) | U8();
    return static_cast<std::int32_t>(v);
  }
  std::vector<std::uint8_t> Take(std::size_t n) {
    n = std::min(n, size_ - std::min(pos_, size_));
    std::vector<std::uint8_t> v(data_ + pos_, data_ + pos_ + n);
    pos_ += n;
    return v;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

struct Box {
  double x, y, yaw, length, width, speed, yaw_rate;  // [m, m, rad, m, m, m/s, rad/s] world
};

template <class T>
std::vector<std::uint8_t> Encode(const T& m) {
  std::vector<std::uint8_t> b(static_cast<std::size_t>(m.getEncodedSize()));
  if (m.encode(b.data(), 0, static_cast<int>(b.size())) != static_cast<int>(b.size())) Fail("encode");
  return b;
}

class Harness {
 public:
  explicit Harness(Reader* in) : in_(*in) {
    TrackerParams params;
    // The mode from the first byte (% 4): mht, ism, vasm, cv.
    const int mode = in_.U8() % 4;
    params.manager.mode = mode == 0   ? TrackerMode::kMht
                          : mode == 1 ? TrackerMode::kIsm
                          : mode == 2 ? TrackerMode::kVasm
                                      : TrackerMode::kCv;
    params.preprocess.max_points = 400;  // reachable by kScanHuge
    params.input.max_queued_scans = 4;
    rings_ = (in_.U8() & 1) ? 16 : 1;
    NodeOptions options;
    options.debug = true;
    node_ = std::make_unique<TrackerNode>(
        params, options, [this](std::int64_t, const std::string& channel, const void* data, std::size_t size) {
          CheckOutput(channel, static_cast<const std::uint8_t*>(data), size);
        });
    const int n = in_.U8() % (kMaxObjects + 1);
    for (int i = 0; i < n; ++i) {
      Box b;
      b.x = in_.I8() * 0.5;
      b.y = in_.I8() * 0.5;
      b.yaw = in_.U8() * (2 * M_PI / 256);
      b.length = 1 + in_.U8() / 32.0;
      b.width = 1 + in_.U8() / 32.0;
      b.speed = in_.I8() * 0.25;
      b.yaw_rate = in_.I8() * 0.01;
      boxes_.push_back(b);
    }
  }

  void Run() {
    for (int op = 0; op < kMaxOps && !in_.done(); ++op) {
      switch (in_.U8() % kNumOps) {
        case kOpPose: Pose(); break;
        case kOpScan: Scan(); break;
        case kOpRaw: Raw(); break;
        case kOpInflate: Inflate(); break;
        case kOpFlush:
          node_->Flush();
          node_->PublishStatus(0);
          break;
      }
      CheckCounters();
    }
    node_->Flush();
    node_->PublishStatus(0);
    CheckCounters();
  }

 private:
  std::int64_t Reject(const char* reason) const {
    const auto& r = node_->tracker().rejects();
    const auto it = r.find(reason);
    return it == r.end() ? 0 : it->second;
  }

  void Send(const std::string& channel, const std::vector<std::uint8_t>& bytes) {
    node_->Handle(channel, bytes.data(), bytes.size());
  }

  void Pose() {
    const std::int64_t dt = in_.I16() * 100;
    ego_speed_ = in_.I8() * 0.25;
    ego_yaw_rate_ = in_.I8() * 0.01;
    const std::uint8_t flags = in_.U8();
    if (flags & kPoseRepeat) {
      // same time as the previous pose
    } else if (flags & kPoseJumpBack) {
      pose_utime_ -= 10'000'000;
    } else {
      Advance(dt);
    }
    pose_t m{};
    m.utime = pose_utime_;
    const double far = (flags & kPoseFar) ? 1e9 : 0.0;
    m.pos[0] = ego_x_ + far;
    m.pos[1] = ego_y_;
    m.pos[2] = 0;
    if (flags & kPoseNaN) m.pos[1] = std::nan("");
    m.orientation[0] = std::cos(ego_yaw_ / 2);
    m.orientation[3] = std::sin(ego_yaw_ / 2);
    if (flags & kPoseBadQuat) m.orientation[0] = 3;  // norm >= 3
    for (int i = 0; i < 3; ++i) m.pos_std[i] = -1;
    m.yaw_std = -1;
    const bool invalid = (flags & (kPoseNaN | kPoseBadQuat)) != 0;
    const std::int64_t before = Reject("invalid_pose");
    Send("EGO_POSE", Encode(m));
    if (invalid && Reject("invalid_pose") != before + 1) Fail("an invalid pose was not counted as invalid_pose");
  }

  // Moves the ego (unicycle) and the boxes (constant speed and yaw rate) forward by dt.
  void Advance(std::int64_t dt_us) {
    pose_utime_ += dt_us;
    const double dt = std::clamp(dt_us * 1e-6, -1.0, 1.0);
    ego_x_ += ego_speed_ * std::cos(ego_yaw_) * dt;
    ego_y_ += ego_speed_ * std::sin(ego_yaw_) * dt;
    ego_yaw_ += ego_yaw_rate_ * dt;
    for (Box& b : boxes_) {
      b.x += b.speed * std::cos(b.yaw) * dt;
      b.y += b.speed * std::sin(b.yaw) * dt;
      b.yaw += b.yaw_rate * dt;
    }
  }

  ladar_scan_t MakeScan() {
    const std::int64_t dt = in_.I16() * 100;
    const int seq_step = in_.I8();
    const std::int32_t sweep_us = in_.U8() * 1000;
    const int per_box = in_.U8() % 64;
    const std::uint8_t flags = in_.U8();
    const int corrupt = in_.U8();
    const std::uint8_t mount = in_.U8();

    ladar_scan_t m{};
    m.utime = pose_utime_ + dt;
    seq_ += seq_step;
    m.seq = seq_;
    m.sensor_id = "fuzz";
    m.sensor_orientation[0] = 1;
    if (mount & 0x80) m.sensor_orientation[0] = 2;  // not a rotation
    m.sensor_pos[2] = (mount & 0x7f) * 0.02;
    m.sweep_duration_us = sweep_us;
    m.max_range = 80;
    m.num_rings = static_cast<std::int16_t>(rings_);
    // Returns on the boxes' outlines, in the sensor frame of the current ego pose.
    const double c = std::cos(ego_yaw_), s = std::sin(ego_yaw_);
    auto add = [&](double wx, double wy, double z, int ring) {
      const double dx = wx - ego_x_, dy = wy - ego_y_;
      m.x.push_back(static_cast<float>(c * dx + s * dy));
      m.y.push_back(static_cast<float>(-s * dx + c * dy));
      m.z.push_back(static_cast<float>(z - m.sensor_pos[2]));
      m.intensity.push_back(0.5f);
      m.dt_us.push_back(sweep_us > 0 ? static_cast<std::int32_t>(m.x.size() * 997 % sweep_us) : 0);
      m.ring.push_back(static_cast<std::int16_t>(ring));
    };
    for (const Box& b : boxes_) {
      const double bc = std::cos(b.yaw), bs = std::sin(b.yaw);
      const double per = 2 * (b.length + b.width);
      for (int i = 0; i < per_box; ++i) {
        double u = per * i / std::max(per_box, 1);
        double lx, ly;
        if (flags & kScanCollapse) u = 0;
        if (flags & kScanLine) u = std::fmod(u, b.length);
        if (u < b.length) { lx = u - b.length / 2; ly = -b.width / 2; }
        else if ((u -= b.length) < b.width) { lx = b.length / 2; ly = u - b.width / 2; }
        else if ((u -= b.width) < b.length) { lx = b.length / 2 - u; ly = b.width / 2; }
        else { u -= b.length; lx = -b.length / 2; ly = b.width / 2 - u; }
        const double wx = b.x + bc * lx - bs * ly, wy = b.y + bs * lx + bc * ly;
        for (int r = 0; r < (rings_ > 1 ? 3 : 1); ++r) add(wx, wy, rings_ > 1 ? 0.5 + 0.5 * r : 0.8, r);
        if (rings_ > 1) add(wx + 1.0, wy, 0.0, 0);  // ground beside it
      }
    }
    if (flags & kScanDuplicate) {
      const std::size_t n = m.x.size();
      for (std::size_t i = 0; i < n; ++i) {
        m.x.push_back(m.x[i]); m.y.push_back(m.y[i]); m.z.push_back(m.z[i]);
        m.intensity.push_back(m.intensity[i]); m.dt_us.push_back(m.dt_us[i]); m.ring.push_back(m.ring[i]);
      }
    }
    if (flags & kScanHuge) {
      for (int i = 0; i < 400; ++i) add(ego_x_ + 5 + i * 0.01, ego_y_ + 5, 1.0, 0);
    }
    if (!m.x.empty()) {
      const std::size_t k = static_cast<std::size_t>(corrupt) % m.x.size();
      if (flags & kScanNaN) m.x[k] = std::nanf("");
      if (flags & kScanInf) m.y[k] = INFINITY;
      if (flags & kScanBadTime) m.dt_us[k] = sweep_us + 1 + corrupt;
      if (flags & kScanFarPoints) m.z[k] = m.x[k] = 1e30f;
    }
    m.npoints = static_cast<std::int32_t>(m.x.size());
    return m;
  }

  void Scan() {
    const ladar_scan_t m = MakeScan();
    const bool bad_mount = m.sensor_orientation[0] != 1;
    const std::int64_t before = Reject("bad_scan");
    Send("LADAR_SCAN", Encode(m));
    if (bad_mount && Reject("bad_scan") != before + 1) Fail("a scan with a non-rotation mounting was not counted as bad_scan");
  }

  void Raw() {
    const std::uint8_t how = in_.U8();
    const std::size_t len = in_.U8();
    std::vector<std::uint8_t> body = in_.Take(len);
    const bool scan = how & 1;
    if (how & 2) {
      const std::int64_t h = scan ? ladar_scan_t::getHash() : pose_t::getHash();
      for (int i = 7; i >= 0; --i) body.insert(body.begin(), static_cast<std::uint8_t>(static_cast<std::uint64_t>(h) >> (56 - 8 * i)));
    }
    Send(scan ? "LADAR_SCAN" : "EGO_POSE", body);
  }

  void Inflate() {
    const std::int32_t claimed = in_.I32();
    ladar_scan_t m = MakeScan();
    std::vector<std::uint8_t> bytes = Encode(m);
    // npoints sits after fingerprint (8), utime, seq (16), sensor_id (4 + len + 1), sensor_pos (24),
    // sensor_orientation (32), sweep_duration_us (4), max_range (4), num_rings (2).
    const std::size_t at = 8 + 16 + 4 + m.sensor_id.size() + 1 + 24 + 32 + 4 + 4 + 2;
    for (int i = 0; i < 4; ++i) bytes[at + i] = static_cast<std::uint8_t>(static_cast<std::uint32_t>(claimed) >> (24 - 8 * i));
    const std::int64_t before = node_->decode_errors();
    Send("LADAR_SCAN", bytes);
    if (claimed != m.npoints && node_->decode_errors() != before + 1) Fail("a scan with a wrong npoints was decoded");
  }

  void CheckCounters() const {
    const Tracker& t = node_->tracker();
    if (t.scans_received() != t.scans_processed() + t.scans_dropped() + static_cast<std::int64_t>(t.queued_scans())) {
      Fail("scans received " + std::to_string(t.scans_received()) + " != processed " +
           std::to_string(t.scans_processed()) + " + dropped " + std::to_string(t.scans_dropped()) +
           " + queued " + std::to_string(t.queued_scans()));
    }
    std::int64_t by_reason = 0;
    for (const char* k : {"empty_scan", "huge_scan", "bad_scan", "scan_repeated", "scan_out_of_order",
                          "scan_overrun", "scan_time_jump", "scan_reset", "pose_missing", "stale_pose"}) {
      by_reason += Reject(k);
    }
    if (by_reason != t.scans_dropped()) {
      Fail("scans dropped " + std::to_string(t.scans_dropped()) + " != " + std::to_string(by_reason) +
           " counted by scan reason");
    }
    const tracker_status_t st = node_->Status();
    for (int i = 0; i < st.num_reasons; ++i) {
      if (st.reject_reason[i] == "internal_error") Fail("the node reported an internal error");
    }
  }

  void CheckOutput(const std::string& channel, const std::uint8_t* data, std::size_t size) {
    if (channel == "TRACKS") {
      track_list_t m;
      if (lcm_util::Decode(data, size, &m) != lcm_util::DecodeError::kNone) Fail("TRACKS does not decode");
      std::set<std::int64_t> ids;
      for (const track_t& t : m.tracks) {
        if (!ids.insert(t.id).second) Fail("track id " + std::to_string(t.id) + " twice in one message");
        if (gone_.count(t.id)) Fail("track id " + std::to_string(t.id) + " came back after it was gone");
        bool ok = std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.theta) &&
                  std::isfinite(t.length) && std::isfinite(t.width) && t.length >= 0 && t.width >= 0;
        for (double v : t.cov) ok = ok && std::isfinite(v);
        for (int i = 0; i < 3; ++i) ok = ok && t.cov[4 * i] >= 0;
        if (!ok) Fail("track " + std::to_string(t.id) + " has a non-finite or negative state/covariance/size");
      }
      for (std::int64_t id : live_) {
        if (!ids.count(id)) gone_.insert(id);
      }
      live_ = std::move(ids);
    } else if (channel == "TRACK_DEBUG") {
      track_debug_t m;
      if (lcm_util::Decode(data, size, &m) != lcm_util::DecodeError::kNone) Fail("TRACK_DEBUG does not decode");
    } else if (channel == "TRACKER_STATUS") {
      tracker_status_t m;
      if (lcm_util::Decode(data, size, &m) != lcm_util::DecodeError::kNone) Fail("TRACKER_STATUS does not decode");
    } else {
      Fail("output on unexpected channel " + channel);
    }
  }

  Reader& in_;
  std::unique_ptr<TrackerNode> node_;
  int rings_ = 1;
  std::vector<Box> boxes_;
  std::int64_t pose_utime_ = kStartUtime;
  std::int64_t seq_ = 0;
  double ego_x_ = 0, ego_y_ = 0, ego_yaw_ = 0, ego_speed_ = 0, ego_yaw_rate_ = 0;
  std::set<std::int64_t> live_, gone_;
};

}  // namespace
}  // namespace vtrack::fuzz

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  vtrack::fuzz::Reader in(data, size);
  vtrack::fuzz::Harness h(&in);
  h.Run();
  return 0;
}
