#include "lcmtypes/util/decode.h"

#include <cstring>
#include <string>
#include <vector>

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
  // An array field: its length, then count elements of elem_bytes each.
  bool SkipArray(std::size_t elem_bytes, const char* count_field, const char* elems_field) {
    std::int32_t n = 0;
    return ReadCount(&n, elem_bytes, count_field) &&
           Skip(static_cast<std::size_t>(n) * elem_bytes, elems_field);
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

// An array field of variable-size elements, each at least min_elem_bytes long, walked by walk.
bool WalkArray(Walker& w, std::size_t min_elem_bytes, const char* count_field,
               bool (*walk)(Walker&)) {
  std::int32_t n = 0;
  if (!w.ReadCount(&n, min_elem_bytes, count_field)) return false;
  for (std::int32_t i = 0; i < n; ++i) {
    if (!walk(w)) return false;
  }
  return true;
}

// A message type without variable-length fields.
template <class T>
bool WalkFixed(Walker& w) {
  return w.Skip(FixedSize<T>(), T::getTypeName());
}

bool WalkLadarScan(Walker& w) {
  return w.Skip(8 + 8, "ladar_scan_t.utime/seq") && w.SkipString("ladar_scan_t.sensor_id") &&
         w.Skip(24 + 32 + 4 + 4 + 2, "ladar_scan_t.mounting") &&
         w.SkipArray(4 * 4 + 4 + 2, "ladar_scan_t.npoints", "ladar_scan_t.points");
}

bool WalkLadarSlice(Walker& w) {
  return w.Skip(8 + 8, "ladar_slice_t.utime/seq") && w.SkipString("ladar_slice_t.sensor_id") &&
         w.Skip(24 + 32 + 4 + 4 + 2, "ladar_slice_t.mounting") &&
         w.Skip(4 + 4 + 8 + 8, "ladar_slice_t.slice") &&
         w.SkipArray(4 * 4 + 4 + 2, "ladar_slice_t.npoints", "ladar_slice_t.points");
}

bool WalkObjectList(Walker& w) {
  return w.Skip(8 + 8, "object_list_t.utime/scan_seq") && w.SkipString("object_list_t.source") &&
         w.SkipArray(FixedSize<object_t>(), "object_list_t.num_objects", "object_list_t.objects");
}

bool WalkDetectionList(Walker& w) {
  return w.Skip(8 + 8, "detection_list_t.utime/seq") && w.SkipString("detection_list_t.source") &&
         w.SkipArray(FixedSize<detection_t>(), "detection_list_t.num_detections",
                     "detection_list_t.detections");
}

bool WalkTrack(Walker& w) {
  // Everything before npred is fixed: the default message (npred = 0) minus the npred field.
  const std::size_t head = FixedSize<track_t>() - 4;
  return w.Skip(head, "track_t.fields") &&
         w.SkipArray(4 + 8 + 8 + 4 + 4, "track_t.npred", "track_t.pred");
}

bool WalkTrackList(Walker& w) {
  return w.Skip(8 + 8 + 8, "track_list_t.utime/scan_seq/latency") &&
         w.SkipString("track_list_t.mode") &&
         WalkArray(w, FixedSize<track_t>(), "track_list_t.num_tracks", WalkTrack);
}

bool WalkDebugEntry(Walker& w) {
  return w.Skip(8 + 1 + 24 + 72 + 40 + 40 + 72 + 1 + 32, "track_debug_entry_t.fields") &&
         w.SkipArray(32, "track_debug_entry_t.num_edges", "track_debug_entry_t.edges") &&
         w.SkipArray(9, "track_debug_entry_t.num_points", "track_debug_entry_t.points") &&
         w.SkipArray(FixedSize<hypothesis_t>(), "track_debug_entry_t.num_hypotheses",
                     "track_debug_entry_t.hypotheses");
}

bool WalkTrackDebug(Walker& w) {
  return w.Skip(8 + 8 + 4, "track_debug_t.utime/scan_seq/num_segments") &&
         WalkArray(w, FixedSize<track_debug_entry_t>(), "track_debug_t.num_entries",
                   WalkDebugEntry);
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

// Every vtrack message type with the walk of its encoding.
struct MessageLayout {
  std::int64_t fingerprint;
  bool (*walk)(Walker&);
};

const std::vector<MessageLayout>& Layouts() {
  static const std::vector<MessageLayout> layouts = {
      {ladar_scan_t::getHash(), WalkLadarScan},
      {ladar_slice_t::getHash(), WalkLadarSlice},
      {object_list_t::getHash(), WalkObjectList},
      {detection_list_t::getHash(), WalkDetectionList},
      {detection_t::getHash(), WalkFixed<detection_t>},
      {track_t::getHash(), WalkTrack},
      {track_list_t::getHash(), WalkTrackList},
      {track_debug_entry_t::getHash(), WalkDebugEntry},
      {track_debug_t::getHash(), WalkTrackDebug},
      {tracker_status_t::getHash(), WalkTrackerStatus},
      {pose_t::getHash(), WalkFixed<pose_t>},
      {object_t::getHash(), WalkFixed<object_t>},
      {hypothesis_t::getHash(), WalkFixed<hypothesis_t>},
  };
  return layouts;
}

}  // namespace

bool CheckLengths(std::int64_t fingerprint, const void* data, std::size_t size, std::string* why) {
  if (size < 8) {
    if (why) *why = "shorter than a fingerprint";
    return false;
  }
  for (const MessageLayout& layout : Layouts()) {
    if (layout.fingerprint != fingerprint) continue;
    Walker w(static_cast<const unsigned char*>(data) + 8, size - 8, why);
    if (!layout.walk(w)) return false;
    // A message is exactly its encoding: bytes left over mean the layout is not what we think.
    if (w.remaining() != 0) {
      return w.Fail("message", std::to_string(w.remaining()) + " trailing bytes");
    }
    return true;
  }
  return true;  // not a vtrack type: the fingerprint check refuses it
}

}  // namespace vtrack::lcm_util
