// Decoding of the two point-cloud message types array by array (decode.h, DecodePointCloud).
//
// Written here rather than left to LCM: the C++ that lcm-gen 1.3.1 generates decodes each array
// through an out-of-line function that assembles every element from four byte shifts (about 7
// instructions per element, not vectorised), after resizing the array, which zeroes it. For a
// KITTI sweep (117k returns, 2.6 MB) that is 6.9 M instructions, 1.3-1.5 ms of CPU, on the path
// from a whole sweep's arrival to its tracks (tests/bench/tracker_bench.cc,
// BM_DecodeSweep_Kitti). The byte order is the same as LCM's (big-endian, IEEE floats moved bit
// for bit), and tests/lcmtypes/point_cloud_decode_test.cc holds every field of the result
// against the generated decoder.
#include <boost/endian/conversion.hpp>

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "lcmtypes/util/decode.h"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/ladar_slice_t.hpp"

namespace vtrack::lcm_util {

namespace {

// The unsigned integer of T's size, which carries T's bytes through the swap.
template <class T>
using BitsOf = std::conditional_t<
    sizeof(T) == 8, std::uint64_t,
    std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint16_t>>;

// Reads an LCM body (after the fingerprint) front to back. A read past the end marks the
// reader failed and leaves the destination as it was.
class BigEndianReader {
 public:
  BigEndianReader(const void* data, std::size_t size)
      : p_(static_cast<const unsigned char*>(data)), size_(size) {}

  bool ok() const { return ok_; }
  std::size_t pos() const { return pos_; }

  template <class T>
  void Scalar(T* out) {
    static_assert(std::is_arithmetic_v<T> && sizeof(T) >= 2 && sizeof(T) <= 8);
    if (!Take(sizeof(T))) return;
    *out = Load<T>(p_ + pos_ - sizeof(T));
  }

  template <class T, std::size_t N>
  void Scalars(T (&out)[N]) {
    for (std::size_t i = 0; i < N; ++i) Scalar(&out[i]);
  }

  // An LCM string: int32 length including the NUL, then the bytes (as the generated decoder
  // reads it: the NUL is not kept).
  void String(std::string* out) {
    std::int32_t len = 0;
    Scalar(&len);
    if (!ok_ || len < 1 || !Take(static_cast<std::size_t>(len))) {
      ok_ = false;
      return;
    }
    out->assign(reinterpret_cast<const char*>(p_ + pos_ - static_cast<std::size_t>(len)),
                static_cast<std::size_t>(len) - 1);
  }

  // n elements into *out, resized to n (elements already there are overwritten, not zeroed).
  template <class T>
  void Array(std::int32_t n, std::vector<T>* out) {
    if (n < 0 || !Take(static_cast<std::size_t>(n) * sizeof(T))) {
      ok_ = false;
      return;
    }
    out->resize(static_cast<std::size_t>(n));
    const unsigned char* src = p_ + pos_ - static_cast<std::size_t>(n) * sizeof(T);
    T* dst = out->data();
    for (std::int32_t i = 0; i < n; ++i) dst[i] = Load<T>(src + static_cast<std::size_t>(i) * sizeof(T));
  }

 private:
  template <class T>
  static T Load(const unsigned char* src) {
    BitsOf<T> bits;
    std::memcpy(&bits, src, sizeof bits);
    bits = boost::endian::big_to_native(bits);
    T v;
    std::memcpy(&v, &bits, sizeof v);
    return v;
  }

  bool Take(std::size_t n) {
    if (!ok_ || n > size_ - pos_) {
      ok_ = false;
      return false;
    }
    pos_ += n;
    return true;
  }

  const unsigned char* p_;
  std::size_t size_;
  std::size_t pos_ = 0;
  bool ok_ = true;
};

// The fields both types open with, in their .lcm order.
template <class Msg>
void ReadSensor(BigEndianReader* r, Msg* m) {
  r->Scalar(&m->utime);
  r->Scalar(&m->seq);
  r->String(&m->sensor_id);
  r->Scalars(m->sensor_pos);
  r->Scalars(m->sensor_orientation);
  r->Scalar(&m->sweep_duration_us);
  r->Scalar(&m->max_range);
  r->Scalar(&m->num_rings);
}

// The count and the arrays both types close with.
template <class Msg>
void ReadReturns(BigEndianReader* r, Msg* m) {
  r->Scalar(&m->npoints);
  if (!r->ok()) return;
  r->Array(m->npoints, &m->x);
  r->Array(m->npoints, &m->y);
  r->Array(m->npoints, &m->z);
  r->Array(m->npoints, &m->intensity);
  r->Array(m->npoints, &m->dt_us);
  r->Array(m->npoints, &m->ring);
}

constexpr std::size_t kFingerprintBytes = 8;

// Bytes read including the fingerprint, or -1.
int Finish(const BigEndianReader& r) {
  return r.ok() ? static_cast<int>(kFingerprintBytes + r.pos()) : -1;
}

}  // namespace

int DecodePointCloud(const void* data, std::size_t size, ladar_scan_t* out) {
  if (size < kFingerprintBytes) return -1;
  BigEndianReader r(static_cast<const unsigned char*>(data) + kFingerprintBytes,
                    size - kFingerprintBytes);
  ReadSensor(&r, out);
  ReadReturns(&r, out);
  return Finish(r);
}

int DecodePointCloud(const void* data, std::size_t size, ladar_slice_t* out) {
  if (size < kFingerprintBytes) return -1;
  BigEndianReader r(static_cast<const unsigned char*>(data) + kFingerprintBytes,
                    size - kFingerprintBytes);
  ReadSensor(&r, out);
  r.Scalar(&out->slice_index);
  r.Scalar(&out->slice_count);
  r.Scalar(&out->azimuth_begin);
  r.Scalar(&out->azimuth_end);
  ReadReturns(&r, out);
  return Finish(r);
}

}  // namespace vtrack::lcm_util
