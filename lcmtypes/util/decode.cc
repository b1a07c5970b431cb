#include "lcmtypes/util/decode.h"

#include <cstring>
#include <string>

#include "vtrack/detection_list_t.hpp"
#include "vtrack/detection_t.hpp"
#include "vtrack/hypothesis_t.hpp"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/object_list_t.hpp"
#include "vtrack/object_t.hpp"
#include "vtrack/pose_t.hpp"
#include "vtrack/track_debug_entry_t.hpp"
#include "vtrack/track_debug_t.hpp"
#include "vtrack/track_list_t.hpp"
#include "vtrack/track_t.hpp"
#include "vtrack/tracker_status_t.hpp"

namespace vtrack::lcm_util {

const char* DecodeErrorName(DecodeError e) {
  switch (e) {
    case DecodeError::kNone: return "ok";
    case DecodeError::kTooShort: return "decode_too_short";
    case DecodeError::kWrongType: return "decode_wrong_type";
    case DecodeError::kBadLength: return "decode_bad_length";
    case DecodeError::kMalformed: return "decode_malformed";
  }
  return "decode_unknown";
}

std::int64_t ReadFingerprint(const void* data, std::size_t size) {
  if (size < 8) return 0;
  const auto* b = static_cast<const unsigned char*>(data);
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | b[i];
  return static_cast<std::int64_t>(v);
}

namespace {

// Encoded size of a message type that has no variable-length field.
template <class T>
std::size_t FixedSize() {
  static const std::size_t n = static_cast<std::size_t>(T()._getEncodedSizeNoHash());
  return n;
}

// Reads an LCM encoding field by field (big-endian; strings are int32 length incl. NUL + bytes)
// without allocating. The layouts below follow the .lcm files field by field; the round-trip
// tests in tests/lcmtypes check them against the generated encoder.
class Walker {
 public:
  Walker(const void* data, std::size_t size, std::string* why)
      : p_(static_cast<const unsigned char*>(data)), size_(size), why_(why) {}

  std::size_t remaining() const { return size_ - pos_; }

  bool Skip(std::size_t n, const char* field) {
    if (n > remaining()) return Fail(field, "truncated");
    pos_ += n;
    return true;
  }
  bool ReadI32(std::int32_t* v, const char* field) {
    if (remaining() < 4) return Fail(field, "truncated");
    std::uint32_t u = 0;
    for (int i = 0; i < 4; ++i) u = (u << 8) | p_[pos_ + i];
    pos_ += 4;
    *v = static_cast<std::int32_t>(u);
    return true;
  }
  bool SkipString(const char* field) {
    std::int32_t len = 0;
    if (!ReadI32(&len, field)) return false;
    // LCM strings carry their NUL terminator inside the length; LCM's decoder does not check
    // it and would accept (and re-encode differently) a string without one.
    if (len < 1) return Fail(field, "string length " + std::to_string(len) + " < 1");
    if (static_cast<std::size_t>(len) > remaining()) return Fail(field, "truncated string");
    if (p_[pos_ + static_cast<std::size_t>(len) - 1] != 0) return Fail(field, "string not NUL-terminated");
    // LCM's encoder measures strings with strlen: an embedded NUL would not survive a round trip.
    if (std::memchr(p_ + pos_, 0, static_cast<std::size_t>(len) - 1) != nullptr) {
      return Fail(field, "string contains a NUL byte");
    }
    return Skip(static_cast<std::size_t>(len), field);
  }
  // Reads an array length field and checks that count elements of at least min_elem_bytes each
  // fit in what is left of the buffer.
  bool ReadCount(std::int32_t* count, std::size_t min_elem_bytes, const char* field) {
    if (!ReadI32(count, field)) return false;
    if (*count < 0) return Fail(field, "negative array length " + std::to_string(*count));
    if (static_cast<std::size_t>(*count) * min_elem_bytes > remaining()) {
      return Fail(field, "claims " + std::to_string(*count) + " elements but only " +
                             std::to_string(remaining()) + " bytes remain");
    }
    return true;
  }
  bool Fail(const char* field, const std::string& what) {
    if (why_) *why_ = std::string(field) + ": " + what;
    return false;
  }

 private:
  const unsigned char* p_;
  std::size_t size_;
  std::size_t pos_ = 0;
  std::string* why_;
};

constexpr std::size_t kMinStringBytes = 5;  // int32 length + NUL

bool WalkLadarScan(Walker& w) {
  std::int32_t n = 0;
  return w.Skip(8 + 8, "ladar_scan_t.utime/seq") && w.SkipString("ladar_scan_t.sensor_id") &&
         w.Skip(24 + 32 + 4 + 4 + 2, "ladar_scan_t.mounting") &&
         w.ReadCount(&n, 4 * 4 + 4 + 2, "ladar_scan_t.npoints") &&
         w.Skip(static_cast<std::size_t>(n) * 22, "ladar_scan_t.points");
}

bool WalkObjectList(Walker& w) {
  std::int32_t n = 0;
  const std::size_t obj = FixedSize<object_t>();
  return w.Skip(8 + 8, "object_list_t.utime/scan_seq") && w.SkipString("object_list_t.source") &&
         w.ReadCount(&n, obj, "object_list_t.num_objects") &&
         w.Skip(static_cast<std::size_t>(n) * obj, "object_list_t.objects");
}

bool WalkDetectionList(Walker& w) {
  std::int32_t n = 0;
  const std::size_t det = FixedSize<detection_t>();
  return w.Skip(8 + 8, "detection_list_t.utime/seq") && w.SkipString("detection_list_t.source") &&
         w.ReadCount(&n, det, "detection_list_t.num_detections") &&
         w.Skip(static_cast<std::size_t>(n) * det, "detection_list_t.detections");
}

bool WalkTrack(Walker& w) {
  // Everything before npred is fixed: the default message (npred = 0) minus the npred field.
  const std::size_t head = FixedSize<track_t>() - 4;
  std::int32_t n = 0;
  return w.Skip(head, "track_t.fields") && w.ReadCount(&n, 4 + 8 + 8 + 4 + 4, "track_t.npred") &&
         w.Skip(static_cast<std::size_t>(n) * 28, "track_t.pred");
}

bool WalkTrackList(Walker& w) {
  std::int32_t n = 0;
  if (!(w.Skip(8 + 8 + 8, "track_list_t.utime/scan_seq/latency") &&
        w.SkipString("track_list_t.mode") &&
        w.ReadCount(&n, FixedSize<track_t>(), "track_list_t.num_tracks"))) {
    return false;
  }
  for (std::int32_t i = 0; i < n; ++i) {
    if (!WalkTrack(w)) return false;
  }
  return true;
}

bool WalkDebugEntry(Walker& w) {
  std::int32_t edges = 0, points = 0, hyps = 0;
  const std::size_t hyp = FixedSize<hypothesis_t>();
  return w.Skip(8 + 1 + 24 + 72 + 40 + 40 + 72 + 1 + 32, "track_debug_entry_t.fields") &&
         w.ReadCount(&edges, 32, "track_debug_entry_t.num_edges") &&
         w.Skip(static_cast<std::size_t>(edges) * 32, "track_debug_entry_t.edges") &&
         w.ReadCount(&points, 9, "track_debug_entry_t.num_points") &&
         w.Skip(static_cast<std::size_t>(points) * 9, "track_debug_entry_t.points") &&
         w.ReadCount(&hyps, hyp, "track_debug_entry_t.num_hypotheses") &&
         w.Skip(static_cast<std::size_t>(hyps) * hyp, "track_debug_entry_t.hypotheses");
}

bool WalkTrackDebug(Walker& w) {
  std::int32_t n = 0;
  if (!(w.Skip(8 + 8 + 4, "track_debug_t.utime/scan_seq/num_segments") &&
        w.ReadCount(&n, FixedSize<track_debug_entry_t>(), "track_debug_t.num_entries"))) {
    return false;
  }
  for (std::int32_t i = 0; i < n; ++i) {
    if (!WalkDebugEntry(w)) return false;
  }
  return true;
}

bool WalkTrackerStatus(Walker& w) {
  std::int32_t n = 0;
  if (!(w.Skip(8 + 8, "tracker_status_t.utime/wall_utime") &&
        w.SkipString("tracker_status_t.mode") && w.Skip(6 * 8, "tracker_status_t.counters") &&
        w.ReadCount(&n, kMinStringBytes + 8, "tracker_status_t.num_reasons"))) {
    return false;
  }
  for (std::int32_t i = 0; i < n; ++i) {
    if (!w.SkipString("tracker_status_t.reject_reason")) return false;
  }
  return w.Skip(static_cast<std::size_t>(n) * 8, "tracker_status_t.reject_count") &&
         w.Skip(8 + 8 + 3 * 4, "tracker_status_t.latency/tracks");
}

}  // namespace

bool CheckLengths(std::int64_t fingerprint, const void* data, std::size_t size, std::string* why) {
  if (size < 8) {
    if (why) *why = "shorter than a fingerprint";
    return false;
  }
  Walker w(static_cast<const unsigned char*>(data) + 8, size - 8, why);
  bool ok = true;
  if (fingerprint == ladar_scan_t::getHash()) {
    ok = WalkLadarScan(w);
  } else if (fingerprint == object_list_t::getHash()) {
    ok = WalkObjectList(w);
  } else if (fingerprint == detection_list_t::getHash()) {
    ok = WalkDetectionList(w);
  } else if (fingerprint == detection_t::getHash()) {
    ok = w.Skip(FixedSize<detection_t>(), "detection_t");
  } else if (fingerprint == track_t::getHash()) {
    ok = WalkTrack(w);
  } else if (fingerprint == track_list_t::getHash()) {
    ok = WalkTrackList(w);
  } else if (fingerprint == track_debug_entry_t::getHash()) {
    ok = WalkDebugEntry(w);
  } else if (fingerprint == track_debug_t::getHash()) {
    ok = WalkTrackDebug(w);
  } else if (fingerprint == tracker_status_t::getHash()) {
    ok = WalkTrackerStatus(w);
  } else if (fingerprint == pose_t::getHash()) {
    ok = w.Skip(FixedSize<pose_t>(), "pose_t");
  } else if (fingerprint == object_t::getHash()) {
    ok = w.Skip(FixedSize<object_t>(), "object_t");
  } else if (fingerprint == hypothesis_t::getHash()) {
    ok = w.Skip(FixedSize<hypothesis_t>(), "hypothesis_t");
  } else {
    return true;  // not a vtrack type: the fingerprint check refuses it
  }
  // A message is exactly its encoding: bytes left over mean the layout is not what we think.
  if (ok && w.remaining() != 0) {
    return w.Fail("message", std::to_string(w.remaining()) + " trailing bytes");
  }
  return ok;
}

}  // namespace vtrack::lcm_util
