// Checked decoding of LCM messages.
//
// LCM's generated decode() returns -1 on any failure, without saying why, and sizes arrays from
// the length fields in the buffer before checking that the buffer holds that much data. Every
// process decodes through Decode<T>() so that a bad message is refused with a reason that can be
// counted (tracker_status_t) and never crashes or exhausts memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string>

#include "lcmtypes/util/point_cloud.h"

namespace vtrack::lcm_util {

enum class DecodeError {
  kNone = 0,
  kTooShort,     // shorter than the 8-byte type fingerprint
  kWrongType,    // fingerprint of another type
  kBadLength,    // an array length field claims more data than the buffer holds
  kMalformed,    // LCM's decoder refused it (truncated, corrupted)
};

// Short snake_case name, used as the reason key in tracker_status_t.
const char* DecodeErrorName(DecodeError e);

// Reads the big-endian 64-bit fingerprint at the start of an encoded message.
std::int64_t ReadFingerprint(const void* data, std::size_t size);

// Walks the encoding of a vtrack message of the given fingerprint without allocating, and checks
// that every length field is non-negative and fits in the rest of the buffer. Returns false (and
// the offending field in *why) for a message that would make the generated decoder allocate more
// than the buffer could possibly carry. Unknown fingerprints pass (the type check catches them).
bool CheckLengths(std::int64_t fingerprint, const void* data, std::size_t size, std::string* why);

// Decodes the two point-cloud types from data[0, size) into *out, array by array
// (point_cloud_codec.cc says why): the same fields as LCM's generated decode(), bit for bit, and
// the same return for what it accepts (the bytes read; -1 for another fingerprint or a buffer
// that ends early). Unlike it, every array is resized to npoints, also to 0, and a string length
// below 1, a negative npoints or a buffer over INT32_MAX bytes give -1 (where the generated code
// throws or allocates); arrays already in *out lend their memory (a sweep decoded into the
// arrays of one at least as large allocates and zeroes nothing). Decode<T> checks the layout
// (CheckLengths) first.
int DecodePointCloud(const void* data, std::size_t size, ladar_scan_t* out);
int DecodePointCloud(const void* data, std::size_t size, ladar_slice_t* out);

// Decodes a T from data[0, size). Never throws.
template <class T>
DecodeError Decode(const void* data, std::size_t size, T* out, std::string* why = nullptr) {
  if (size < 8) return DecodeError::kTooShort;
  const std::int64_t fp = ReadFingerprint(data, size);
  if (fp != T::getHash()) return DecodeError::kWrongType;
  std::string local_why;
  if (!CheckLengths(fp, data, size, why ? why : &local_why)) return DecodeError::kBadLength;
  if (size > static_cast<std::size_t>(INT32_MAX)) return DecodeError::kMalformed;
  try {
    int n = -1;
    if constexpr (kIsPointCloud<T>) {
      n = DecodePointCloud(data, size, out);
    } else {
      n = out->decode(data, 0, static_cast<int>(size));
    }
    if (n < 0) return DecodeError::kMalformed;
  } catch (const std::bad_alloc&) {
    return DecodeError::kBadLength;
  } catch (const std::length_error&) {
    return DecodeError::kBadLength;
  }
  return DecodeError::kNone;
}

}  // namespace vtrack::lcm_util
