// The point-cloud codec (lcmtypes/util/point_cloud_codec.cc) against LCM's generated code:
// decoded, the same fields bit for bit and the same messages accepted and refused; encoded, the
// same bytes; on seeded random messages (any float bit pattern: NaNs with payloads, infinities,
// subnormals, -0), their truncations and corruptions, into messages and buffers already holding
// others, and over an in-process LCM bus.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/encode.h"
#include "tests/support/encode.h"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/ladar_slice_t.hpp"

namespace vtrack::testing {
namespace {

using lcm_util::Decode;
using lcm_util::DecodeError;

template <class T>
bool SameBits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

template <class T>
::testing::AssertionResult SameArray(const char* name, const std::vector<T>& a,
                                     const std::vector<T>& b) {
  if (a.size() != b.size()) {
    return ::testing::AssertionFailure() << name << ": " << a.size() << " against " << b.size()
                                         << " elements";
  }
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!SameBits(a[i], b[i])) return ::testing::AssertionFailure() << name << "[" << i << "] differs";
  }
  return ::testing::AssertionSuccess();
}

// Every field of two messages of the same type, floats compared as bits.
template <class Msg>
::testing::AssertionResult SameFields(const Msg& a, const Msg& b) {
  if (a.utime != b.utime || a.seq != b.seq || a.sensor_id != b.sensor_id ||
      a.sweep_duration_us != b.sweep_duration_us || a.num_rings != b.num_rings ||
      a.npoints != b.npoints || !SameBits(a.max_range, b.max_range) ||
      std::memcmp(a.sensor_pos, b.sensor_pos, sizeof a.sensor_pos) != 0 ||
      std::memcmp(a.sensor_orientation, b.sensor_orientation, sizeof a.sensor_orientation) != 0) {
    return ::testing::AssertionFailure() << "a header field differs";
  }
  if constexpr (std::is_same_v<Msg, ladar_slice_t>) {
    if (a.slice_index != b.slice_index || a.slice_count != b.slice_count ||
        !SameBits(a.azimuth_begin, b.azimuth_begin) || !SameBits(a.azimuth_end, b.azimuth_end)) {
      return ::testing::AssertionFailure() << "a slice field differs";
    }
  }
  for (auto r : {SameArray("x", a.x, b.x), SameArray("y", a.y, b.y), SameArray("z", a.z, b.z),
                 SameArray("intensity", a.intensity, b.intensity),
                 SameArray("dt_us", a.dt_us, b.dt_us), SameArray("ring", a.ring, b.ring)}) {
    if (!r) return r;
  }
  return ::testing::AssertionSuccess();
}

// Messages whose every number is a random bit pattern.
class RandomClouds {
 public:
  explicit RandomClouds(unsigned seed) : rng_(seed) {}

  template <class T>
  T Bits() {
    std::uint64_t u = rng_();
    T v;
    std::memcpy(&v, &u, sizeof v);
    return v;
  }

  template <class Msg>
  Msg Make(int npoints) {
    Msg m{};
    m.utime = Bits<std::int64_t>();
    m.seq = Bits<std::int64_t>();
    const int len = static_cast<int>(rng_() % 40);
    for (int i = 0; i < len; ++i) m.sensor_id += static_cast<char>(1 + rng_() % 255);  // no NUL
    for (double& v : m.sensor_pos) v = Bits<double>();
    for (double& v : m.sensor_orientation) v = Bits<double>();
    m.sweep_duration_us = Bits<std::int32_t>();
    m.max_range = Bits<float>();
    m.num_rings = Bits<std::int16_t>();
    if constexpr (std::is_same_v<Msg, ladar_slice_t>) {
      m.slice_index = Bits<std::int32_t>();
      m.slice_count = Bits<std::int32_t>();
      m.azimuth_begin = Bits<double>();
      m.azimuth_end = Bits<double>();
    }
    m.npoints = npoints;
    auto fill = [&](auto* v) {
      v->resize(static_cast<std::size_t>(npoints));
      for (auto& e : *v) e = Bits<std::decay_t<decltype(e)>>();
    };
    fill(&m.x);
    fill(&m.y);
    fill(&m.z);
    fill(&m.intensity);
    fill(&m.dt_us);
    fill(&m.ring);
    return m;
  }

  int Count(int hi) { return static_cast<int>(rng_() % static_cast<unsigned>(hi + 1)); }
  std::mt19937_64& rng() { return rng_; }

 private:
  std::mt19937_64 rng_;
};

template <class Msg>
class PointCloudCodecTest : public ::testing::Test {};
using CloudTypes = ::testing::Types<ladar_scan_t, ladar_slice_t>;
TYPED_TEST_SUITE(PointCloudCodecTest, CloudTypes);

TYPED_TEST(PointCloudCodecTest, DecodesEveryFieldAsTheGeneratedDecoder) {
  RandomClouds r(11);
  for (int k = 0; k < 300; ++k) {
    const int n = k < 5 ? k : r.Count(k % 7 == 0 ? 5000 : 300);
    const std::vector<std::uint8_t> bytes = Encode(r.Make<TypeParam>(n));
    TypeParam reference;
    ASSERT_EQ(reference.decode(bytes.data(), 0, static_cast<int>(bytes.size())),
              static_cast<int>(bytes.size()));
    TypeParam fresh;
    ASSERT_EQ(Decode(bytes.data(), bytes.size(), &fresh), DecodeError::kNone) << k;
    EXPECT_TRUE(SameFields(fresh, reference)) << "message " << k << ", " << n << " returns";
    // Into a message holding other returns, more or fewer: none of them may survive.
    TypeParam reused = r.Make<TypeParam>(r.Count(2 * n + 3));
    ASSERT_EQ(Decode(bytes.data(), bytes.size(), &reused), DecodeError::kNone) << k;
    EXPECT_TRUE(SameFields(reused, reference)) << "message " << k << " decoded into another";
  }
}

TYPED_TEST(PointCloudCodecTest, ReturnsTheBytesReadAndRefusesEveryTruncation) {
  RandomClouds r(12);
  const std::vector<std::uint8_t> bytes = Encode(r.Make<TypeParam>(9));
  TypeParam m;
  EXPECT_EQ(lcm_util::DecodePointCloud(bytes.data(), bytes.size(), &m),
            static_cast<int>(bytes.size()));
  for (std::size_t cut = 0; cut < bytes.size(); ++cut) {
    TypeParam reference, fast;
    ASSERT_EQ(reference.decode(bytes.data(), 0, static_cast<int>(cut)), -1) << cut;
    EXPECT_EQ(lcm_util::DecodePointCloud(bytes.data(), cut, &fast), -1) << "cut at " << cut;
    EXPECT_NE(Decode(bytes.data(), cut, &fast), DecodeError::kNone) << "cut at " << cut;
  }
}

// Corrupted bytes: Decode accepts exactly what the length walk and the generated decoder accept,
// with the same fields.
TYPED_TEST(PointCloudCodecTest, AcceptsAndRefusesCorruptionsAsTheGeneratedDecoder) {
  RandomClouds r(13);
  int accepted = 0, refused = 0;
  for (int k = 0; k < 3000; ++k) {
    std::vector<std::uint8_t> bytes = Encode(r.Make<TypeParam>(r.Count(6)));
    const int flips = 1 + r.Count(3);
    for (int f = 0; f < flips; ++f) {
      // Mostly the header (lengths, the string), where a flip changes the layout.
      const std::size_t at = 8 + r.rng()() % std::min<std::size_t>(bytes.size() - 8, 120);
      bytes[at] ^= static_cast<std::uint8_t>(1u << (r.rng()() % 8));
    }
    std::string why;
    const bool layout_ok =
        lcm_util::CheckLengths(TypeParam::getHash(), bytes.data(), bytes.size(), &why);
    TypeParam reference;
    const bool reference_ok =
        layout_ok && reference.decode(bytes.data(), 0, static_cast<int>(bytes.size())) ==
                         static_cast<int>(bytes.size());
    TypeParam fast = r.Make<TypeParam>(3);
    const bool fast_ok = Decode(bytes.data(), bytes.size(), &fast) == DecodeError::kNone;
    ASSERT_EQ(fast_ok, reference_ok) << "corruption " << k << ": " << why;
    if (fast_ok) {
      ++accepted;
      EXPECT_TRUE(SameFields(fast, reference)) << "corruption " << k;
    } else {
      ++refused;
    }
  }
  // Both outcomes exercised (a flip in a number is accepted, one in a length refused).
  EXPECT_GT(accepted, 300);
  EXPECT_GT(refused, 300);
}

// Writes v big-endian at byte `at` of an encoding.
void PutI32(std::vector<std::uint8_t>* b, std::size_t at, std::int32_t v) {
  const auto u = static_cast<std::uint32_t>(v);
  for (int i = 0; i < 4; ++i) (*b)[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(u >> (24 - 8 * i));
}

// Called directly, without the length walk: a wrong fingerprint, impossible array and string
// lengths are refused and no array grows past what the buffer holds; an empty cloud empties
// arrays holding others.
TYPED_TEST(PointCloudCodecTest, RefusesHostileLengthsWithoutTheLengthWalk) {
  RandomClouds r(17);
  const TypeParam m = r.Make<TypeParam>(5);
  const std::vector<std::uint8_t> good = Encode(m);
  const std::size_t npoints_at = good.size() - 5 * (4 * 4 + 4 + 2) - 4;
  const std::size_t string_at = 8 + 8 + 8;
  for (const std::int32_t n : {-1, INT32_MIN, INT32_MAX, 1 << 30, 6}) {
    std::vector<std::uint8_t> b = good;
    PutI32(&b, npoints_at, n);
    TypeParam out;
    EXPECT_EQ(lcm_util::DecodePointCloud(b.data(), b.size(), &out), -1) << "npoints " << n;
    // Arrays are grown only to what the buffer holds.
    const std::size_t bytes = 4 * (out.x.size() + out.y.size() + out.z.size() + out.intensity.size() +
                                   out.dt_us.size()) +
                              2 * out.ring.size();
    EXPECT_LE(bytes, b.size()) << "npoints " << n;
  }
  for (const std::int32_t len : {0, -1, INT32_MIN, INT32_MAX}) {
    std::vector<std::uint8_t> b = good;
    PutI32(&b, string_at, len);
    TypeParam out;
    EXPECT_EQ(lcm_util::DecodePointCloud(b.data(), b.size(), &out), -1) << "string length " << len;
  }
  std::vector<std::uint8_t> other_type = good;
  other_type[3] ^= 0x10;
  TypeParam out;
  EXPECT_EQ(lcm_util::DecodePointCloud(other_type.data(), other_type.size(), &out), -1);
  // Exactly the encoding: accepted, its size returned.
  EXPECT_EQ(lcm_util::DecodePointCloud(good.data(), good.size(), &out), static_cast<int>(good.size()));
  // An empty cloud into arrays holding 40 returns (LCM's decoder would leave them).
  const std::vector<std::uint8_t> empty = Encode(r.Make<TypeParam>(0));
  TypeParam full = r.Make<TypeParam>(40);
  ASSERT_EQ(Decode(empty.data(), empty.size(), &full), DecodeError::kNone);
  EXPECT_EQ(full.npoints, 0);
  EXPECT_TRUE(full.x.empty() && full.y.empty() && full.z.empty() && full.intensity.empty() &&
              full.dt_us.empty() && full.ring.empty());
}

TYPED_TEST(PointCloudCodecTest, EncodesTheBytesOfTheGeneratedEncoder) {
  RandomClouds r(14);
  std::vector<std::uint8_t> buffer;
  for (int k = 0; k < 300; ++k) {
    const int n = k < 5 ? k : r.Count(k % 7 == 0 ? 5000 : 300);
    const TypeParam m = r.Make<TypeParam>(n);
    const std::vector<std::uint8_t> reference = Encode(m);
    // The buffer holds the message before, longer or shorter: its bytes must not survive.
    ASSERT_EQ(lcm_util::Encode(m, &buffer), static_cast<int>(reference.size())) << k;
    ASSERT_EQ(buffer, reference) << "message " << k << ", " << n << " returns";
  }
}

TYPED_TEST(PointCloudCodecTest, RefusesToEncodeAnInconsistentMessage) {
  RandomClouds r(15);
  std::vector<std::uint8_t> buffer;
  const TypeParam good = r.Make<TypeParam>(7);
  ASSERT_EQ(lcm_util::Encode(good, &buffer), static_cast<int>(Encode(good).size()));
  TypeParam short_ring = good;
  short_ring.ring.pop_back();
  EXPECT_EQ(lcm_util::Encode(short_ring, &buffer), -1);
  TypeParam long_x = good;
  long_x.x.push_back(1.0f);
  EXPECT_EQ(lcm_util::Encode(long_x, &buffer), -1);
  // The same number of bytes in all, but not npoints in each array.
  TypeParam shifted = good;
  shifted.x.push_back(1.0f);
  shifted.y.pop_back();
  EXPECT_EQ(lcm_util::Encode(shifted, &buffer), -1);
  TypeParam negative = good;
  negative.npoints = -1;
  EXPECT_EQ(lcm_util::Encode(negative, &buffer), -1);
  // LCM's encoder would write the name up to the NUL but announce its whole size.
  TypeParam nul = good;
  nul.sensor_id = std::string("velo\0dyne", 9);
  EXPECT_EQ(lcm_util::Encode(nul, &buffer), -1);
}

TYPED_TEST(PointCloudCodecTest, PublishesTheBytesOfTheGeneratedEncoderOnTheBus) {
  lcm::LCM bus("memq://");
  ASSERT_TRUE(bus.good());
  std::vector<std::vector<std::uint8_t>> received;
  struct Sink {
    std::vector<std::vector<std::uint8_t>>* out;
    void On(const lcm::ReceiveBuffer* rb, const std::string&) {
      const auto* b = static_cast<const std::uint8_t*>(rb->data);
      out->emplace_back(b, b + rb->data_size);
    }
  } sink{&received};
  bus.subscribe("CLOUD", &Sink::On, &sink);
  RandomClouds r(16);
  std::vector<TypeParam> sent;
  std::vector<std::uint8_t> buffer;
  for (int k = 0; k < 5; ++k) {
    sent.push_back(r.Make<TypeParam>(r.Count(2000)));
    ASSERT_EQ(lcm_util::Publish(&bus, "CLOUD", sent.back(), &buffer), 0);
    ASSERT_EQ(bus.handleTimeout(1000), 1);
  }
  ASSERT_EQ(received.size(), sent.size());
  for (std::size_t k = 0; k < sent.size(); ++k) EXPECT_EQ(received[k], Encode(sent[k])) << k;
  TypeParam bad = sent[0];
  bad.z.clear();
  EXPECT_EQ(lcm_util::Publish(&bus, "CLOUD", bad, &buffer), -1);
}

}  // namespace
}  // namespace vtrack::testing
