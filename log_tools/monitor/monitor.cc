#include "log_tools/monitor/monitor.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <Eigen/Geometry>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/text.h"
#include "base/angle.h"
#include "base/pose.h"
#include "vtrack/detection_list_t.hpp"
#include "vtrack/detection_t.hpp"
#include "vtrack/hypothesis_t.hpp"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/ladar_slice_t.hpp"
#include "vtrack/object_list_t.hpp"
#include "vtrack/object_t.hpp"
#include "vtrack/pose_t.hpp"
#include "vtrack/track_debug_entry_t.hpp"
#include "vtrack/track_debug_t.hpp"
#include "vtrack/track_list_t.hpp"
#include "vtrack/track_t.hpp"
#include "vtrack/tracker_status_t.hpp"

namespace vtrack::monitor {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using lcm_util::Format;

long long LL(std::int64_t v) { return static_cast<long long>(v); }

bool IsVehicle(std::int8_t c) {
  return c == object_t::CLASS_CAR || c == object_t::CLASS_VAN || c == object_t::CLASS_TRUCK ||
         c == object_t::CLASS_SKID_STEER;
}

std::string Summarise(const ladar_scan_t& m) {
  return Format("seq %lld %s: %d pts, %d rings, sweep %.1f ms", LL(m.seq), m.sensor_id.c_str(),
                m.npoints, m.num_rings, m.sweep_duration_us * 1e-3);
}

std::string Summarise(const ladar_slice_t& m) {
  return Format("seq %lld %s: slice %d/%d, azimuth %.1f..%.1f deg, %d pts, %d rings", LL(m.seq),
                m.sensor_id.c_str(), m.slice_index + 1, m.slice_count, RadToDeg(m.azimuth_begin),
                RadToDeg(m.azimuth_end), m.npoints, m.num_rings);
}

std::string Summarise(const pose_t& m) {
  const Eigen::Quaterniond q(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]);
  const double yaw = q.norm() > 1e-9 ? RadToDeg(YawOf(q.normalized())) : kNaN;
  return Format("pos (%.2f, %.2f, %.2f) m, yaw %.1f deg, speed %.2f m/s", m.pos[0], m.pos[1],
                m.pos[2], yaw, std::sqrt(m.vel[0] * m.vel[0] + m.vel[1] * m.vel[1] + m.vel[2] * m.vel[2]));
}

std::string Summarise(const object_list_t& m) {
  int scored = 0;
  for (const auto& o : m.objects) scored += (o.in_labelled_region && IsVehicle(o.object_class)) ? 1 : 0;
  return Format("%s: %d objects (%d vehicles in labelled region), scan %lld", m.source.c_str(),
                m.num_objects, scored, LL(m.scan_seq));
}

std::string Summarise(const track_list_t& m) {
  int tentative = 0, confirmed = 0, coasting = 0, vehicles = 0;
  for (const auto& t : m.tracks) {
    tentative += t.status == track_t::STATUS_TENTATIVE;
    confirmed += t.status == track_t::STATUS_CONFIRMED;
    coasting += t.status == track_t::STATUS_COASTING;
    vehicles += t.object_class == track_t::CLASS_VEHICLE;
  }
  return Format("%s: %d tracks (%d confirmed, %d tentative, %d coasting; %d vehicles), scan %lld, "
                "latency %.1f ms",
                m.mode.c_str(), m.num_tracks, confirmed, tentative, coasting, vehicles,
                LL(m.scan_seq), m.latency_us * 1e-3);
}

std::string Summarise(const detection_list_t& m) {
  double best = -std::numeric_limits<double>::infinity();
  for (const auto& b : m.detections) best = std::max(best, static_cast<double>(b.score));
  return m.num_detections == 0
             ? Format("%s: no boxes, frame %lld", m.source.c_str(), LL(m.seq))
             : Format("%s: %d boxes (best score %.2f), frame %lld", m.source.c_str(),
                      m.num_detections, best, LL(m.seq));
}

std::string Summarise(const detection_t& m) {
  return Format("box class %d at (%.2f, %.2f) m, %.2f x %.2f m, score %.2f", m.object_class, m.x,
                m.y, m.length, m.width, m.score);
}

std::string Summarise(const track_debug_t& m) {
  return Format("scan %lld: %d segments, %d track entries", LL(m.scan_seq), m.num_segments,
                m.num_entries);
}

std::string Summarise(const tracker_status_t& m) {
  std::string s = Format("%s: scans %lld recv / %lld proc / %lld drop, decode errors %lld, "
                         "latency %.1f ms (median %.1f), tracks %d conf / %d tent / %d coast",
                         m.mode.c_str(), LL(m.scans_received), LL(m.scans_processed),
                         LL(m.scans_dropped), LL(m.decode_errors), m.last_latency_ms,
                         m.median_latency_ms, m.tracks_confirmed, m.tracks_tentative,
                         m.tracks_coasting);
  for (int i = 0; i < m.num_reasons && i < static_cast<int>(m.reject_reason.size()); ++i) {
    s += Format(", %s %lld", m.reject_reason[i].c_str(), LL(m.reject_count[i]));
  }
  return s;
}

std::string Summarise(const object_t& m) {
  return Format("object %lld class %d at (%.2f, %.2f) m", LL(m.id), m.object_class, m.x, m.y);
}
std::string Summarise(const track_t& m) {
  return Format("track %lld status %d at (%.2f, %.2f) m, %.2f m/s", LL(m.id), m.status, m.x, m.y,
                m.speed);
}
std::string Summarise(const hypothesis_t& m) {
  return Format("hypothesis %d model %d at (%.2f, %.2f) m", m.index, m.model, m.x, m.y);
}
std::string Summarise(const track_debug_entry_t& m) {
  return Format("track %lld fit %d, %d points, %d hypotheses", LL(m.track_id), m.fit_kind,
                m.num_points, m.num_hypotheses);
}

template <class T>
bool TryDescribe(const void* data, std::size_t size, std::int64_t fp, const char* name,
                 Description* d) {
  if (fp != T::getHash()) return false;
  d->type = name;
  T msg;
  std::string why;
  const lcm_util::DecodeError e = lcm_util::Decode(data, size, &msg, &why);
  if (e != lcm_util::DecodeError::kNone) {
    d->ok = false;
    d->summary = std::string("cannot decode: ") + lcm_util::DecodeErrorName(e) +
                 (why.empty() ? "" : " (" + why + ")");
    return true;
  }
  d->ok = true;
  d->summary = Summarise(msg);
  return true;
}

struct KnownType {
  std::int64_t fp;
  const char* name;
};
const std::vector<KnownType>& KnownTypes() {
  static const std::vector<KnownType> types = {
      {ladar_scan_t::getHash(), "ladar_scan_t"},     {ladar_slice_t::getHash(), "ladar_slice_t"},
      {pose_t::getHash(), "pose_t"},
      {object_list_t::getHash(), "object_list_t"},   {track_list_t::getHash(), "track_list_t"},
      {track_debug_t::getHash(), "track_debug_t"},   {tracker_status_t::getHash(), "tracker_status_t"},
      {object_t::getHash(), "object_t"},             {track_t::getHash(), "track_t"},
      {hypothesis_t::getHash(), "hypothesis_t"},     {track_debug_entry_t::getHash(), "track_debug_entry_t"},
      {detection_list_t::getHash(), "detection_list_t"}, {detection_t::getHash(), "detection_t"}};
  return types;
}

std::string HumanBytes(double bps) {
  if (!std::isfinite(bps)) return "-";
  if (bps >= 1e6) return Format("%.2f MB/s", bps / 1e6);
  if (bps >= 1e3) return Format("%.1f kB/s", bps / 1e3);
  return Format("%.0f B/s", bps);
}

}  // namespace

std::string TypeName(std::int64_t fingerprint) {
  for (const auto& t : KnownTypes()) {
    if (t.fp == fingerprint) return t.name;
  }
  return "";
}

Description Describe(const void* data, std::size_t size) {
  Description d;
  if (size < 8) {
    d.type = "?";
    d.summary = Format("cannot decode: %zu bytes, shorter than a fingerprint", size);
    return d;
  }
  const std::int64_t fp = lcm_util::ReadFingerprint(data, size);
  if (TryDescribe<ladar_scan_t>(data, size, fp, "ladar_scan_t", &d) ||
      TryDescribe<ladar_slice_t>(data, size, fp, "ladar_slice_t", &d) ||
      TryDescribe<pose_t>(data, size, fp, "pose_t", &d) ||
      TryDescribe<object_list_t>(data, size, fp, "object_list_t", &d) ||
      TryDescribe<track_list_t>(data, size, fp, "track_list_t", &d) ||
      TryDescribe<track_debug_t>(data, size, fp, "track_debug_t", &d) ||
      TryDescribe<tracker_status_t>(data, size, fp, "tracker_status_t", &d) ||
      TryDescribe<object_t>(data, size, fp, "object_t", &d) ||
      TryDescribe<track_t>(data, size, fp, "track_t", &d) ||
      TryDescribe<hypothesis_t>(data, size, fp, "hypothesis_t", &d) ||
      TryDescribe<track_debug_entry_t>(data, size, fp, "track_debug_entry_t", &d) ||
      TryDescribe<detection_list_t>(data, size, fp, "detection_list_t", &d) ||
      TryDescribe<detection_t>(data, size, fp, "detection_t", &d)) {
    return d;
  }
  d.type = Format("? 0x%016llx", static_cast<unsigned long long>(fp));
  d.summary = Format("not a vtrack type, %zu bytes", size);
  d.ok = true;
  return d;
}

ChannelTable::ChannelTable(double window_s)
    : window_us_(static_cast<std::int64_t>(std::max(window_s, 1e-3) * 1e6)) {}

void ChannelTable::Add(const std::string& channel, std::int64_t time_us, const void* data,
                       std::size_t size) {
  Channel& c = channels_[channel];
  if (c.count == 0) c.first_us = time_us;
  ++c.count;
  c.bytes += static_cast<std::int64_t>(size);
  c.last_us = std::max(c.last_us, time_us);
  ++total_messages_;
  total_bytes_ += static_cast<std::int64_t>(size);
  c.fingerprint = lcm_util::ReadFingerprint(data, size);
  // A cheap check of every message: the type is known and its length fields fit.
  std::string why;
  if (size < 8 || (!TypeName(c.fingerprint).empty() &&
                   !lcm_util::CheckLengths(c.fingerprint, data, size, &why))) {
    ++c.decode_errors;
  }
  c.recent.emplace_back(time_us, size);
  while (!c.recent.empty() && c.recent.front().first < time_us - window_us_) c.recent.pop_front();
  c.last_message.assign(static_cast<const char*>(data), size);
}

std::vector<ChannelTable::Row> ChannelTable::Rows(std::int64_t now_us, bool whole_span) const {
  std::vector<Row> rows;
  for (const auto& [name, c] : channels_) {
    Row r;
    r.channel = name;
    r.count = c.count;
    r.decode_errors = c.decode_errors;
    const Description d = Describe(c.last_message.data(), c.last_message.size());
    r.type = d.type;
    r.summary = d.summary;
    if (whole_span) {
      const double span = static_cast<double>(c.last_us - c.first_us) * 1e-6;
      r.rate_hz = (c.count >= 2 && span > 0.0) ? static_cast<double>(c.count - 1) / span : kNaN;
      r.bandwidth_bps = r.rate_hz * static_cast<double>(c.bytes) / static_cast<double>(c.count);
    } else {
      // Messages received within the window ending now (the window is shorter right after the
      // first message of the channel).
      const std::int64_t from = now_us - window_us_;
      std::int64_t n = 0, bytes = 0;
      for (const auto& [t, sz] : c.recent) {
        if (t >= from && t <= now_us) {
          ++n;
          bytes += static_cast<std::int64_t>(sz);
        }
      }
      const double span = static_cast<double>(now_us - std::max(from, c.first_us)) * 1e-6;
      r.rate_hz = span > 0.0 ? static_cast<double>(n) / span : kNaN;
      r.bandwidth_bps = span > 0.0 ? static_cast<double>(bytes) / span : kNaN;
    }
    rows.push_back(std::move(r));
  }
  return rows;
}

std::string ChannelTable::Render(std::int64_t now_us, bool whole_span, int width) const {
  const auto rows = Rows(now_us, whole_span);
  std::size_t wc = 7, wt = 4;
  for (const auto& r : rows) {
    wc = std::max(wc, r.channel.size());
    wt = std::max(wt, r.type.size());
  }
  std::string out;
  auto line = [&](std::string s) {
    if (width > 0 && static_cast<int>(s.size()) > width) s.resize(static_cast<std::size_t>(width));
    out += s + "\n";
  };
  line(Format("%-*s  %-*s  %8s  %8s  %11s  %6s  %s", static_cast<int>(wc), "channel",
              static_cast<int>(wt), "type", "msgs", "rate Hz", "bandwidth", "errors", "last message"));
  for (const auto& r : rows) {
    const std::string rate = std::isfinite(r.rate_hz) ? Format("%.1f", r.rate_hz) : "-";
    line(Format("%-*s  %-*s  %8lld  %8s  %11s  %6lld  %s", static_cast<int>(wc), r.channel.c_str(),
                static_cast<int>(wt), r.type.c_str(), LL(r.count), rate.c_str(),
                HumanBytes(r.bandwidth_bps).c_str(), LL(r.decode_errors), r.summary.c_str()));
  }
  return out;
}

}  // namespace vtrack::monitor
