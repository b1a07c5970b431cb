// Encoding and decoding of the two point-cloud message types array by array (encode.h,
// EncodePointCloud; decode.h, DecodePointCloud).
//
// Written here rather than left to LCM: the C++ that lcm-gen 1.3.1 generates moves each array
// element through an out-of-line function of byte shifts (about 7 instructions per element to
// decode, 9 to encode, not vectorised); its decoder first resizes each array, which zeroes it,
// and lcm::LCM::publish encodes into a buffer it allocates per message. For a KITTI sweep (117k
// returns, 2.6 MB) that is 6.9 M instructions to decode and 10.6 M to encode, each over 1 ms of
// CPU on the path from a whole sweep's last return to its tracks (tests/bench/tracker_bench.cc,
// BM_DecodeSweep_Kitti and BM_EncodeSweep_Kitti). The bytes are LCM's (big-endian, IEEE floats
// moved bit for bit): tests/lcmtypes/point_cloud_codec_test.cc holds every field decoded, and
// every byte encoded, against the generated code.
#include <boost/endian/conversion.hpp>

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/encode.h"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/ladar_slice_t.hpp"

namespace vtrack::lcm_util {

namespace {

// The unsigned integer of T's size, which carries T's bytes through the swap.
template <class T>
using BitsOf = std::conditional_t<
    sizeof(T) == 8, std::uint64_t,
    std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint16_t>>;

// A position in a buffer of known size; a step past its end fails it for good.
class Cursor {
 public:
  bool ok() const { return ok_; }
  std::size_t pos() const { return pos_; }
  void Fail() { ok_ = false; }

 protected:
  explicit Cursor(std::size_t size) : size_(size) {}

  // Advances by count elements of elem_bytes each, *at their start; false (and failed) if they
  // are not there (compared as a count, so that no product can wrap).
  bool Take(std::size_t count, std::size_t elem_bytes, std::size_t* at) {
    if (!ok_ || count > (size_ - pos_) / elem_bytes) {
      ok_ = false;
      return false;
    }
    *at = pos_;
    pos_ += count * elem_bytes;
    return true;
  }
  // Advances by n bytes, *at their start; false (and failed) if they are not there.
  bool Take(std::size_t n, std::size_t* at) {
    if (!ok_ || n > size_ - pos_) {
      ok_ = false;
      return false;
    }
    *at = pos_;
    pos_ += n;
    return true;
  }

 private:
  std::size_t size_;
  std::size_t pos_ = 0;
  bool ok_ = true;
};

// Reads an LCM body (after the fingerprint) front to back. A read past the end marks the
// reader failed and leaves the destination as it was.
class BigEndianReader : public Cursor {
 public:
  BigEndianReader(const void* data, std::size_t size)
      : Cursor(size), p_(static_cast<const unsigned char*>(data)) {}

  template <class T>
  void Scalar(T* out) {
    static_assert(std::is_arithmetic_v<T> && sizeof(T) >= 2 && sizeof(T) <= 8);
    std::size_t at = 0;
    if (Take(sizeof(T), &at)) *out = Load<T>(p_ + at);
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
    std::size_t at = 0;
    if (!ok() || len < 1 || !Take(static_cast<std::size_t>(len), &at)) {
      Fail();
      return;
    }
    out->assign(reinterpret_cast<const char*>(p_ + at), static_cast<std::size_t>(len) - 1);
  }

  // n elements into *out, resized to n (elements already there are overwritten, not zeroed).
  template <class T>
  void Array(std::int32_t n, std::vector<T>* out) {
    std::size_t at = 0;
    if (n < 0 || !Take(static_cast<std::size_t>(n), sizeof(T), &at)) {
      Fail();
      return;
    }
    out->resize(static_cast<std::size_t>(n));
    const unsigned char* src = p_ + at;
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

  const unsigned char* p_;
};

// Writes an LCM encoding into a buffer of the size the message says it needs. A write that
// would not fit marks the writer failed and writes nothing.
class BigEndianWriter : public Cursor {
 public:
  BigEndianWriter(unsigned char* data, std::size_t size) : Cursor(size), p_(data) {}

  template <class T>
  void Scalar(T v) {
    static_assert(std::is_arithmetic_v<T> && sizeof(T) >= 2 && sizeof(T) <= 8);
    std::size_t at = 0;
    if (Take(sizeof(T), &at)) Store(v, p_ + at);
  }

  template <class T, std::size_t N>
  void Scalars(const T (&v)[N]) {
    for (std::size_t i = 0; i < N; ++i) Scalar(v[i]);
  }

  // As LCM's encoder writes a string: its length up to the first NUL, plus one, then those
  // bytes and a NUL.
  void String(const std::string& s) {
    const std::size_t len = std::strlen(s.c_str());
    Scalar(static_cast<std::int32_t>(len + 1));
    std::size_t at = 0;
    if (!Take(len + 1, &at)) return;
    unsigned char* dst = p_ + at;
    std::memcpy(dst, s.data(), len);
    dst[len] = 0;
  }

  template <class T>
  void Array(const std::vector<T>& v) {
    // Read through locals: the byte stores may alias any object, v's own pointers included.
    const T* src = v.data();
    const std::size_t n = v.size();
    std::size_t at = 0;
    if (!Take(n * sizeof(T), &at)) return;
    unsigned char* dst = p_ + at;
    for (std::size_t i = 0; i < n; ++i) Store(src[i], dst + i * sizeof(T));
  }

 private:
  template <class T>
  static void Store(T v, unsigned char* dst) {
    BitsOf<T> bits;
    std::memcpy(&bits, &v, sizeof bits);
    bits = boost::endian::native_to_big(bits);
    std::memcpy(dst, &bits, sizeof bits);
  }


  unsigned char* p_;
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

template <class Msg>
void WriteSensor(const Msg& m, BigEndianWriter* w) {
  w->Scalar(m.utime);
  w->Scalar(m.seq);
  w->String(m.sensor_id);
  w->Scalars(m.sensor_pos);
  w->Scalars(m.sensor_orientation);
  w->Scalar(m.sweep_duration_us);
  w->Scalar(m.max_range);
  w->Scalar(m.num_rings);
}

template <class Msg>
bool ArraysHoldNpoints(const Msg& m) {
  const auto n = static_cast<std::size_t>(m.npoints);
  return m.npoints >= 0 && m.x.size() == n && m.y.size() == n && m.z.size() == n &&
         m.intensity.size() == n && m.dt_us.size() == n && m.ring.size() == n;
}

template <class Msg>
void WriteReturns(const Msg& m, BigEndianWriter* w) {
  w->Scalar(m.npoints);
  w->Array(m.x);
  w->Array(m.y);
  w->Array(m.z);
  w->Array(m.intensity);
  w->Array(m.dt_us);
  w->Array(m.ring);
}

// Into *out, sized to the encoding (a buffer already that large is not zeroed again): the bytes,
// or -1 if the arrays do not all hold npoints elements, or sensor_id holds a NUL (LCM's encoder
// would then write fewer bytes than the message's size).
template <class Msg>
int Encoded(const Msg& m, std::vector<std::uint8_t>* out,
            void (*write_middle)(const Msg&, BigEndianWriter*)) {
  if (!ArraysHoldNpoints(m)) return -1;
  const auto size = static_cast<std::size_t>(m.getEncodedSize());
  out->resize(size);
  BigEndianWriter w(out->data(), size);
  w.Scalar(Msg::getHash());
  WriteSensor(m, &w);
  write_middle(m, &w);
  WriteReturns(m, &w);
  return w.ok() && w.pos() == size ? static_cast<int>(size) : -1;
}

constexpr std::size_t kFingerprintBytes = 8;

// Bytes read including the fingerprint, or -1.
int Finish(const BigEndianReader& r) {
  return r.ok() ? static_cast<int>(kFingerprintBytes + r.pos()) : -1;
}

// A reader of the body after Msg's fingerprint, failed if the buffer does not open with it or
// is longer than an LCM message can be (INT32_MAX bytes, the generated code's int sizes).
template <class Msg>
BigEndianReader BodyOf(const void* data, std::size_t size) {
  const bool fits = size >= kFingerprintBytes && size <= static_cast<std::size_t>(INT32_MAX) &&
                    ReadFingerprint(data, size) == Msg::getHash();
  BigEndianReader r(static_cast<const unsigned char*>(data) + (fits ? kFingerprintBytes : 0),
                    fits ? size - kFingerprintBytes : 0);
  if (!fits) r.Fail();
  return r;
}

}  // namespace

int DecodePointCloud(const void* data, std::size_t size, ladar_scan_t* out) {
  BigEndianReader r = BodyOf<ladar_scan_t>(data, size);
  ReadSensor(&r, out);
  ReadReturns(&r, out);
  return Finish(r);
}

int DecodePointCloud(const void* data, std::size_t size, ladar_slice_t* out) {
  BigEndianReader r = BodyOf<ladar_slice_t>(data, size);
  ReadSensor(&r, out);
  r.Scalar(&out->slice_index);
  r.Scalar(&out->slice_count);
  r.Scalar(&out->azimuth_begin);
  r.Scalar(&out->azimuth_end);
  ReadReturns(&r, out);
  return Finish(r);
}

int EncodePointCloud(const ladar_scan_t& m, std::vector<std::uint8_t>* out) {
  return Encoded<ladar_scan_t>(m, out, [](const ladar_scan_t&, BigEndianWriter*) {});
}

int EncodePointCloud(const ladar_slice_t& m, std::vector<std::uint8_t>* out) {
  return Encoded<ladar_slice_t>(m, out, [](const ladar_slice_t& s, BigEndianWriter* w) {
    w->Scalar(s.slice_index);
    w->Scalar(s.slice_count);
    w->Scalar(s.azimuth_begin);
    w->Scalar(s.azimuth_end);
  });
}

}  // namespace vtrack::lcm_util
