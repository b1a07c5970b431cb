// Encoding of LCM messages into a buffer the caller keeps, and publishing through it.
//
// lcm::LCM::publish(channel, &msg) allocates a buffer per message and encodes with the generated
// code; for a 64-beam sweep (2.7 MB) both cost more than a millisecond. Encode<T> writes into a
// buffer reused from message to message, the two point-cloud types array by array
// (point_cloud_codec.cc says why): the bytes are those of the generated encode().
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "lcmtypes/util/point_cloud.h"

namespace vtrack::lcm_util {

// The encoding of m (fingerprint included) into *out, resized to it: its size, or -1 if m is
// inconsistent (an array not of npoints elements, a sensor_id holding a NUL byte).
int EncodePointCloud(const ladar_scan_t& m, std::vector<std::uint8_t>* out);
int EncodePointCloud(const ladar_slice_t& m, std::vector<std::uint8_t>* out);

// The encoding of any vtrack message into *out: its size, or -1 if the generated encoder fails.
template <class T>
int Encode(const T& m, std::vector<std::uint8_t>* out) {
  if constexpr (kIsPointCloud<T>) {
    return EncodePointCloud(m, out);
  } else {
    const int size = m.getEncodedSize();
    out->resize(static_cast<std::size_t>(size));
    return m.encode(out->data(), 0, size) == size ? size : -1;
  }
}

// Publishes m on channel, encoded by Encode into *buffer (kept by the caller from message to
// message). lcm::LCM::publish's result: 0 on success, -1 on failure (also when m cannot be
// encoded).
template <class T>
int Publish(lcm::LCM* lcm, const std::string& channel, const T& m, std::vector<std::uint8_t>* buffer) {
  const int size = Encode(m, buffer);
  if (size < 0) return -1;
  return lcm->publish(channel, buffer->data(), static_cast<unsigned int>(size));
}

}  // namespace vtrack::lcm_util
