// Every message type round-trips through encode/decode with non-trivial content; truncated,
// corrupted, mistyped and length-inflated buffers are refused by Decode<T>, never crashed on.
#include <gtest/gtest.h>

#include <random>

#include "lcmtypes/util/decode.h"
#include "tests/lcmtypes/random_messages.h"

namespace vtrack {
namespace {

using lcm_util::Decode;
using lcm_util::DecodeError;
using testing::Encode;
using testing::RandomMessages;

// Round trip: decode(encode(m)) re-encodes to the same bytes, so every field survived (a field
// the decoder dropped would re-encode as its default and differ).
template <class T>
T RoundTrip(const T& m) {
  const auto bytes = Encode(m);
  T out;
  std::string why;
  EXPECT_EQ(Decode(bytes.data(), bytes.size(), &out, &why), DecodeError::kNone) << why;
  EXPECT_EQ(Encode(out), bytes);
  return out;
}

TEST(LcmTypes, PoseRoundTrip) {
  RandomMessages r(1);
  const pose_t m = r.Pose();
  const pose_t out = RoundTrip(m);
  EXPECT_EQ(out.utime, m.utime);
  EXPECT_EQ(out.orientation[3], m.orientation[3]);
  EXPECT_EQ(out.yaw_std, m.yaw_std);
}

TEST(LcmTypes, HugeScanRoundTrip) {
  RandomMessages r(2);
  const ladar_scan_t m = r.Scan(130000);
  const auto bytes = Encode(m);
  // 22 bytes a point: the parallel-array layout of docs/design.md, section 2.
  EXPECT_GT(bytes.size(), 130000u * 22u);
  EXPECT_LT(bytes.size(), 130000u * 22u + 200u);
  const ladar_scan_t out = RoundTrip(m);
  ASSERT_EQ(out.npoints, 130000);
  EXPECT_EQ(out.x.back(), m.x.back());
  EXPECT_EQ(out.ring[12345], m.ring[12345]);
  EXPECT_EQ(out.dt_us[129999], m.dt_us[129999]);
  EXPECT_EQ(out.sensor_id, "velodyne_hdl64");
}

TEST(LcmTypes, EmptyScanRoundTrip) {
  RandomMessages r(3);
  EXPECT_EQ(RoundTrip(r.Scan(0)).npoints, 0);
}

TEST(LcmTypes, ObjectListRoundTrip) {
  RandomMessages r(4);
  const auto m = r.ObjectList(37);
  const auto out = RoundTrip(m);
  ASSERT_EQ(out.objects.size(), 37u);
  EXPECT_EQ(out.objects[36].rear_axle_offset, m.objects[36].rear_axle_offset);
  EXPECT_EQ(out.objects[5].in_labelled_region, m.objects[5].in_labelled_region);
}

TEST(LcmTypes, TrackListRoundTrip) {
  RandomMessages r(5);
  const auto m = r.TrackList(25);
  const auto out = RoundTrip(m);
  ASSERT_EQ(out.tracks.size(), 25u);
  EXPECT_EQ(out.tracks[24].pred_x, m.tracks[24].pred_x);
  EXPECT_EQ(out.tracks[3].cov[8], m.tracks[3].cov[8]);
}

TEST(LcmTypes, TrackDebugRoundTrip) {
  RandomMessages r(6);
  const auto m = r.Debug(12);
  const auto out = RoundTrip(m);
  ASSERT_EQ(out.entries.size(), 12u);
  EXPECT_EQ(out.entries[11].hypotheses.size(), m.entries[11].hypotheses.size());
  EXPECT_EQ(out.entries[0].point_edge, m.entries[0].point_edge);
}

TEST(LcmTypes, TrackerStatusRoundTrip) {
  RandomMessages r(7);
  const auto m = r.Status();
  const auto out = RoundTrip(m);
  EXPECT_EQ(out.reject_reason, m.reject_reason);
  EXPECT_EQ(out.reject_count, m.reject_count);
}

// The length walk must consume exactly the generated encoder's output for every type and size,
// otherwise its layout has drifted from the .lcm files.
TEST(LcmTypes, LengthWalkAgreesWithEncoderOnRandomMessages) {
  RandomMessages r(8);
  std::string why;
  for (int trial = 0; trial < 50; ++trial) {
    auto check = [&](const auto& m) {
      const auto b = Encode(m);
      EXPECT_TRUE(lcm_util::CheckLengths(lcm_util::ReadFingerprint(b.data(), b.size()), b.data(),
                                         b.size(), &why))
          << why;
    };
    check(r.Pose());
    check(r.Scan(r.I(0, 300)));
    check(r.ObjectList(r.I(0, 20)));
    check(r.Object(trial));
    check(r.Track(trial, r.I(0, 30)));
    check(r.TrackList(r.I(0, 10)));
    check(r.Hypothesis(trial));
    check(r.Debug(r.I(0, 4)));
    check(r.Status());
  }
}

template <class T>
void ExpectTruncationsRefused(const T& m) {
  const auto bytes = Encode(m);
  for (size_t len : {size_t{0}, size_t{7}, size_t{8}, size_t{9}, bytes.size() / 2, bytes.size() - 1}) {
    T out;
    EXPECT_NE(Decode(bytes.data(), len, &out), DecodeError::kNone) << "length " << len;
  }
}

TEST(LcmTypes, TruncatedBuffersAreRefused) {
  RandomMessages r(9);
  ExpectTruncationsRefused(r.Pose());
  ExpectTruncationsRefused(r.Scan(1000));
  ExpectTruncationsRefused(r.ObjectList(5));
  ExpectTruncationsRefused(r.TrackList(5));
  ExpectTruncationsRefused(r.Debug(3));
  ExpectTruncationsRefused(r.Status());
}

TEST(LcmTypes, WrongTypeIsRefused) {
  RandomMessages r(10);
  const auto pose = Encode(r.Pose());
  ladar_scan_t scan;
  EXPECT_EQ(Decode(pose.data(), pose.size(), &scan), DecodeError::kWrongType);
}

// A scan whose npoints field claims 2^31 - 1 points: LCM's generated decoder would resize eight
// arrays to that size (tens of GB) before noticing the buffer is short. Decode<T> refuses first.
TEST(LcmTypes, InflatedArrayLengthIsRefusedBeforeAllocation) {
  RandomMessages r(11);
  ladar_scan_t m = r.Scan(10);
  auto bytes = Encode(m);
  // npoints sits right before the 10 * 22 bytes of point arrays.
  const size_t at = bytes.size() - 10 * 22 - 4;
  bytes[at] = 0x7f; bytes[at + 1] = 0xff; bytes[at + 2] = 0xff; bytes[at + 3] = 0xff;
  ladar_scan_t out;
  std::string why;
  EXPECT_EQ(Decode(bytes.data(), bytes.size(), &out, &why), DecodeError::kBadLength);
  EXPECT_NE(why.find("npoints"), std::string::npos) << why;

  // The same for a negative count and for a nested count inside a track list.
  bytes[at] = 0xff;
  EXPECT_EQ(Decode(bytes.data(), bytes.size(), &out), DecodeError::kBadLength);

  track_list_t tl = r.TrackList(1);
  tl.tracks[0].npred = 0; tl.tracks[0].pred_t.clear(); tl.tracks[0].pred_x.clear();
  tl.tracks[0].pred_y.clear(); tl.tracks[0].pred_theta.clear(); tl.tracks[0].pred_pos_std.clear();
  auto tb = Encode(tl);
  const size_t npred_at = tb.size() - 4;  // last field of the only track
  tb[npred_at] = 0x10;
  track_list_t tout;
  EXPECT_EQ(Decode(tb.data(), tb.size(), &tout, &why), DecodeError::kBadLength);
  EXPECT_NE(why.find("npred"), std::string::npos) << why;
}

// Random byte corruption: every outcome is a clean refusal or a message that re-encodes to the
// buffer's size; never a crash (this test runs under the sanitizers too).
TEST(LcmTypes, CorruptedBuffersNeverCrash) {
  RandomMessages r(12);
  std::mt19937 rng(99);
  const auto scan = Encode(r.Scan(200));
  const auto tracks = Encode(r.TrackList(4));
  const auto debug = Encode(r.Debug(2));
  int refused = 0, accepted = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    auto corrupt = [&](std::vector<unsigned char> b) {
      const int flips = 1 + static_cast<int>(rng() % 4);
      for (int k = 0; k < flips; ++k) b[8 + rng() % (b.size() - 8)] = static_cast<unsigned char>(rng());
      return b;
    };
    auto check = [&](auto msg, const std::vector<unsigned char>& b) {
      if (Decode(b.data(), b.size(), &msg) == DecodeError::kNone) {
        ++accepted;
        EXPECT_EQ(static_cast<size_t>(msg.getEncodedSize()), b.size());
      } else {
        ++refused;
      }
    };
    check(ladar_scan_t{}, corrupt(scan));
    check(track_list_t{}, corrupt(tracks));
    check(track_debug_t{}, corrupt(debug));
  }
  EXPECT_GT(refused, 0);
  EXPECT_GT(accepted, 0);  // most flips land in float payload and stay decodable
}

}  // namespace
}  // namespace vtrack

namespace vtrack {
namespace {

// LCM's decoder accepts a string whose bytes lack the NUL terminator or hold an embedded NUL;
// its encoder then writes different bytes (it uses strlen). Decode<T> refuses both (found by the
// decoder fuzzers; inputs kept in tests/fuzz/regressions/).
TEST(LcmTypes, MalformedStringsAreRefused) {
  testing::RandomMessages r(13);
  ladar_scan_t m = r.Scan(3);
  m.sensor_id = "abcd";
  auto bytes = testing::Encode(m);
  // sensor_id: int32 length (5) at offset 8 (hash) + 16 (utime, seq), then "abcd\0".
  const size_t at = 8 + 16 + 4;
  ASSERT_EQ(bytes[at - 1], 5);
  ASSERT_EQ(bytes[at + 4], 0);
  ladar_scan_t out;
  std::string why;
  auto no_nul = bytes;
  no_nul[at + 4] = 'e';
  EXPECT_EQ(lcm_util::Decode(no_nul.data(), no_nul.size(), &out, &why), lcm_util::DecodeError::kBadLength);
  EXPECT_NE(why.find("NUL-terminated"), std::string::npos) << why;
  auto embedded = bytes;
  embedded[at + 1] = 0;
  EXPECT_EQ(lcm_util::Decode(embedded.data(), embedded.size(), &out, &why), lcm_util::DecodeError::kBadLength);
  EXPECT_NE(why.find("contains a NUL"), std::string::npos) << why;
  EXPECT_EQ(lcm_util::Decode(bytes.data(), bytes.size(), &out), lcm_util::DecodeError::kNone);
}

}  // namespace
}  // namespace vtrack
