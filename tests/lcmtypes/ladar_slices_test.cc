// Slicing of sweeps and their reassembly (lcmtypes/util/ladar_slices.h) on seeded synthetic
// sweeps of a rotating multi-layer sensor whose truth is known: every return's column azimuth,
// and which slice a lost wedge was.
#include "lcmtypes/util/ladar_slices.h"
#include "lcmtypes/util/decode.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace vtrack::lcm_util {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A sweep of `columns` columns of `rings` layers turning clockwise (direction -1) or
// counter-clockwise from start_deg over the full circle in 100 ms; each ray returns with
// probability 0.8 at a seeded range in [2, 80] m.
ladar_scan_t MakeSweep(std::int64_t seq, int columns, int rings, double start_deg, int direction,
                       std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> range(2.0, 80.0), u(0.0, 1.0);
  ladar_scan_t s{};
  s.utime = 1'700'000'000'000'000 + seq * 100'000;
  s.seq = seq;
  s.sensor_id = "velodyne";
  s.sensor_pos[2] = 1.73;
  s.sensor_orientation[0] = 1.0;
  s.sweep_duration_us = 99'900;
  s.max_range = 120.0f;
  s.num_rings = static_cast<std::int16_t>(rings);
  for (int j = 0; j < columns; ++j) {
    const double az = (start_deg + direction * 360.0 * j / columns) * kPi / 180.0;
    for (int r = 0; r < rings; ++r) {
      if (u(rng) > 0.8) continue;
      const double el = (-24.0 + 26.0 * r / std::max(1, rings - 1)) * kPi / 180.0;
      const double d = range(rng);
      s.x.push_back(static_cast<float>(d * std::cos(el) * std::cos(az)));
      s.y.push_back(static_cast<float>(d * std::cos(el) * std::sin(az)));
      s.z.push_back(static_cast<float>(d * std::sin(el)));
      s.intensity.push_back(static_cast<float>(u(rng)));
      s.dt_us.push_back(static_cast<std::int32_t>(99'900LL * j / columns));
      s.ring.push_back(static_cast<std::int16_t>(r));
    }
  }
  s.npoints = static_cast<std::int32_t>(s.x.size());
  return s;
}

bool InArc(double azimuth, double begin, double end) {
  double d = std::fmod(azimuth - begin, 2.0 * kPi);
  if (d < 0.0) d += 2.0 * kPi;
  return d <= end - begin + 1e-9;
}

void ExpectSameScan(const ladar_scan_t& a, const ladar_scan_t& b) {
  std::vector<std::uint8_t> ea(static_cast<std::size_t>(a.getEncodedSize()));
  std::vector<std::uint8_t> eb(static_cast<std::size_t>(b.getEncodedSize()));
  a.encode(ea.data(), 0, static_cast<int>(ea.size()));
  b.encode(eb.data(), 0, static_cast<int>(eb.size()));
  EXPECT_EQ(ea, eb) << "seq " << a.seq << " / " << b.seq;
}

TEST(SliceSweepTest, SlicesHoldTheirArcsReturnsInOrderAndFitOneDatagram) {
  for (const int direction : {-1, 1}) {
    const ladar_scan_t scan = MakeSweep(7, 2048, 64, 180.0, direction, 11);
    const std::vector<ladar_slice_t> slices = SliceSweep(scan, 0);
    const int n = static_cast<int>(slices.size());
    // At least the bytes over the limit, and the fewest: one slice fewer overflows.
    const std::int64_t bytes = static_cast<std::int64_t>(scan.npoints) * 22;
    EXPECT_GE(n, static_cast<int>(bytes / kMaxDatagramMessageBytes) + 1);
    std::int64_t largest_fewer = 0;
    for (const ladar_slice_t& s : SliceSweep(scan, n - 1)) {
      largest_fewer = std::max<std::int64_t>(largest_fewer, s.getEncodedSize());
    }
    EXPECT_GT(largest_fewer, kMaxDatagramMessageBytes);
    ladar_scan_t joined = scan;
    for (auto* v : {&joined.x, &joined.y, &joined.z, &joined.intensity}) v->clear();
    joined.dt_us.clear();
    joined.ring.clear();
    std::vector<AzimuthArc> arcs;
    double width_sum = 0.0;
    for (int k = 0; k < n; ++k) {
      const ladar_slice_t& s = slices[static_cast<std::size_t>(k)];
      EXPECT_EQ(s.slice_index, k);
      EXPECT_EQ(s.slice_count, n);
      EXPECT_LE(s.getEncodedSize(), kMaxDatagramMessageBytes);
      EXPECT_GE(s.azimuth_begin, -kPi);
      EXPECT_LT(s.azimuth_begin, kPi);
      width_sum += s.azimuth_end - s.azimuth_begin;
      arcs.push_back({s.azimuth_begin, s.azimuth_end});
      for (int i = 0; i < s.npoints; ++i) {
        // Within float rounding: a column goes by its first return's azimuth.
        const double az = std::atan2(static_cast<double>(s.y[i]), static_cast<double>(s.x[i]));
        EXPECT_TRUE(InArc(az, s.azimuth_begin - 1e-6, s.azimuth_end + 1e-6))
            << "slice " << k << " return " << i;
      }
      joined.x.insert(joined.x.end(), s.x.begin(), s.x.end());
      joined.y.insert(joined.y.end(), s.y.begin(), s.y.end());
      joined.z.insert(joined.z.end(), s.z.begin(), s.z.end());
      joined.intensity.insert(joined.intensity.end(), s.intensity.begin(), s.intensity.end());
      joined.dt_us.insert(joined.dt_us.end(), s.dt_us.begin(), s.dt_us.end());
      joined.ring.insert(joined.ring.end(), s.ring.begin(), s.ring.end());
    }
    EXPECT_NEAR(width_sum, 2.0 * kPi, 1e-9);
    EXPECT_TRUE(UncoveredArcs(arcs).empty());
    // A rotating sensor's returns come in firing order: the slices in index order are the sweep.
    ExpectSameScan(joined, scan);
  }
}

TEST(SliceSweepTest, CountsAndOptionsOutOfRangeAreRefused) {
  const ladar_scan_t scan = MakeSweep(1, 100, 4, 0.0, 1, 3);
  EXPECT_THROW(SliceSweep(scan, -2), std::invalid_argument);
  EXPECT_THROW(SliceSweep(scan, kMaxSlicesPerSweep + 1), std::invalid_argument);
  ladar_scan_t bad = scan;
  bad.ring.pop_back();
  EXPECT_THROW(SliceSweep(bad, 4), std::invalid_argument);
  EXPECT_EQ(ParseSlicesOption("auto"), kSlicesAuto);
  EXPECT_EQ(ParseSlicesOption("0"), 0);
  EXPECT_EQ(ParseSlicesOption("16"), 16);
  EXPECT_FALSE(ParseSlicesOption("-1"));
  EXPECT_FALSE(ParseSlicesOption("4097"));
  EXPECT_FALSE(ParseSlicesOption("1x"));
  EXPECT_FALSE(ParseSlicesOption(""));
  // Auto: a single-plane sweep goes whole, a 3-D one sliced.
  ladar_scan_t plane = MakeSweep(1, 361, 1, -90.0, 1, 3);
  EXPECT_EQ(SlicesFor(kSlicesAuto, plane), 0);
  EXPECT_GT(SlicesFor(kSlicesAuto, MakeSweep(1, 2048, 64, 180.0, -1, 3)), 1);
  EXPECT_EQ(SlicesFor(5, plane), 5);
}

// Feeds slices, collecting what the assembler hands on.
struct Fed {
  SweepAssembler assembler;
  std::vector<AssembledSweep> out;
  explicit Fed(SweepAssembler::Options o = {}) : assembler(o) {}
  void Add(ladar_slice_t s) { assembler.Add(std::move(s), &out); }
};

TEST(SweepAssemblerTest, InOrderAndReorderedSlicesGiveTheSweepBack) {
  const ladar_scan_t scan = MakeSweep(3, 2048, 64, 180.0, -1, 5);
  std::vector<ladar_slice_t> slices = SliceSweep(scan, 0);
  Fed in_order;
  for (const auto& s : slices) in_order.Add(s);
  ASSERT_EQ(in_order.out.size(), 1u);
  EXPECT_FALSE(in_order.out[0].partial());
  EXPECT_TRUE(in_order.out[0].missing.empty());
  ExpectSameScan(in_order.out[0].scan, scan);

  std::mt19937 rng(9);
  std::shuffle(slices.begin(), slices.end(), rng);
  Fed shuffled;
  for (const auto& s : slices) shuffled.Add(s);
  ASSERT_EQ(shuffled.out.size(), 1u);
  ExpectSameScan(shuffled.out[0].scan, scan);
  EXPECT_EQ(shuffled.assembler.sweeps_whole(), 1);
  EXPECT_EQ(shuffled.assembler.slices_lost(), 0);
}

// The sweep without slice `lost`: its returns and its arc are what the assembler must report.
void ExpectWithout(const AssembledSweep& a, const std::vector<ladar_slice_t>& slices,
                   std::size_t lost) {
  ASSERT_TRUE(a.partial());
  EXPECT_EQ(a.slices_received, static_cast<int>(slices.size()) - 1);
  ASSERT_EQ(a.missing.size(), 1u);
  EXPECT_NEAR(a.missing[0].begin, slices[lost].azimuth_begin, 1e-9);
  EXPECT_NEAR(a.missing[0].end, slices[lost].azimuth_end, 1e-9);
  EXPECT_NEAR(a.MissingDeg(), 360.0 / static_cast<double>(slices.size()), 1e-6);
  std::vector<float> x;
  for (std::size_t k = 0; k < slices.size(); ++k) {
    if (k != lost) x.insert(x.end(), slices[k].x.begin(), slices[k].x.end());
  }
  EXPECT_EQ(a.scan.x, x);
  EXPECT_EQ(a.scan.npoints, static_cast<std::int32_t>(x.size()));
}

TEST(SweepAssemblerTest, MissingSliceIsHandedOnWithItsWedgeWhenTheNextSweepStarts) {
  const std::vector<ladar_slice_t> s1 = SliceSweep(MakeSweep(1, 2048, 64, 180.0, -1, 1), 0);
  const std::vector<ladar_slice_t> s2 = SliceSweep(MakeSweep(2, 2048, 64, 180.0, -1, 2), 0);
  for (const std::size_t lost : {std::size_t{17}, s1.size() - 1, std::size_t{0}}) {
    Fed f;
    for (std::size_t k = 0; k < s1.size(); ++k) {
      if (k != lost) f.Add(s1[k]);
    }
    EXPECT_TRUE(f.out.empty()) << "nothing says yet that slice " << lost << " is lost";
    f.Add(s2[0]);
    ASSERT_EQ(f.out.size(), 1u);
    ExpectWithout(f.out[0], s1, lost);
    for (std::size_t k = 1; k < s2.size(); ++k) f.Add(s2[k]);
    ASSERT_EQ(f.out.size(), 2u);
    EXPECT_FALSE(f.out[1].partial());
    EXPECT_EQ(f.out[1].scan.seq, 2);
    EXPECT_EQ(f.assembler.slices_lost(), 1);
    EXPECT_EQ(f.assembler.sweeps_partial(), 1);
    EXPECT_NEAR(f.assembler.missing_deg(), 360.0 / s1.size(), 1e-6);
    // The lost slice arriving now is late: refused and counted.
    f.Add(s1[lost]);
    EXPECT_EQ(f.assembler.refused().at("slice_late"), 1);
    EXPECT_EQ(f.out.size(), 2u);
  }
}

TEST(SweepAssemblerTest, TimeoutAndFlushHandOnIncompleteSweeps) {
  const std::vector<ladar_slice_t> s1 = SliceSweep(MakeSweep(1, 512, 16, 0.0, 1, 4), 8);
  SweepAssembler::Options o;
  o.timeout_us = 50'000;
  Fed f(o);
  for (std::size_t k = 0; k + 1 < s1.size(); ++k) f.Add(s1[k]);
  const std::int64_t end = s1[0].utime + s1[0].sweep_duration_us;
  f.assembler.Expire(end + 50'000, &f.out);
  EXPECT_TRUE(f.out.empty());
  f.assembler.Expire(end + 50'001, &f.out);
  ASSERT_EQ(f.out.size(), 1u);
  ExpectWithout(f.out[0], s1, s1.size() - 1);
  Fed g;
  for (std::size_t k = 1; k < s1.size(); ++k) g.Add(s1[k]);
  g.assembler.Flush(&g.out);
  ASSERT_EQ(g.out.size(), 1u);
  ExpectWithout(g.out[0], s1, 0);
}

TEST(SweepAssemblerTest, DuplicatesAreCountedAndIgnored) {
  const ladar_scan_t scan = MakeSweep(4, 1024, 32, 90.0, 1, 6);
  const std::vector<ladar_slice_t> slices = SliceSweep(scan, 12);
  Fed f;
  for (std::size_t k = 0; k < slices.size(); ++k) {
    f.Add(slices[k]);
    if (k % 3 == 0 && k + 1 < slices.size()) f.Add(slices[k]);  // sent twice
  }
  ASSERT_EQ(f.out.size(), 1u);
  ExpectSameScan(f.out[0].scan, scan);
  EXPECT_EQ(f.assembler.refused().at("slice_duplicate"), 4);
  f.Add(slices[11]);  // after the sweep was handed on
  EXPECT_EQ(f.assembler.refused().at("slice_late"), 1);
}

TEST(SweepAssemblerTest, InterleavedSweepsOfTwoSensorsAndOfOneWithAWindow) {
  const ladar_scan_t a = MakeSweep(5, 1024, 32, 180.0, -1, 7);
  ladar_scan_t b = MakeSweep(9, 1024, 32, 0.0, 1, 8);
  b.sensor_id = "front";
  const auto sa = SliceSweep(a, 10), sb = SliceSweep(b, 6);
  Fed f;
  for (std::size_t k = 0; k < 10; ++k) {
    f.Add(sa[k]);
    if (k < 6) f.Add(sb[k]);
  }
  ASSERT_EQ(f.out.size(), 2u);
  ExpectSameScan(f.out[0].scan, b);  // completed first
  ExpectSameScan(f.out[1].scan, a);

  // One sensor, sweeps 5 and 6 interleaved: with a window of one sweep both come whole, in order.
  const ladar_scan_t a2 = MakeSweep(6, 1024, 32, 180.0, -1, 9);
  const auto sa2 = SliceSweep(a2, 10);
  SweepAssembler::Options o;
  o.reorder_window_us = 100'000;
  Fed g(o);
  for (std::size_t k = 0; k < 10; ++k) {
    g.Add(sa[k]);
    g.Add(sa2[k]);  // the later sweep's slices among the earlier one's
  }
  ASSERT_EQ(g.out.size(), 2u);
  ExpectSameScan(g.out[0].scan, a);
  ExpectSameScan(g.out[1].scan, a2);
  // Without the window the first slice of sweep 6 closes sweep 5 at once.
  Fed h;
  for (std::size_t k = 0; k < 10; ++k) {
    h.Add(sa2[k]);
    h.Add(sa[k]);
  }
  EXPECT_EQ(h.assembler.refused().at("slice_late"), 9);
  ASSERT_EQ(h.out.size(), 2u);
  EXPECT_EQ(h.out[0].scan.seq, 5);
  EXPECT_EQ(h.out[0].slices_received, 1);
  ExpectSameScan(h.out[1].scan, a2);
}

TEST(SweepAssemblerTest, BadSlicesAreRefusedByReason) {
  const ladar_scan_t scan = MakeSweep(2, 512, 8, 45.0, 1, 10);
  const std::vector<ladar_slice_t> slices = SliceSweep(scan, 4);
  Fed f;
  ladar_slice_t s = slices[0];
  s.slice_index = 4;  // == count
  f.Add(s);
  s = slices[0];
  s.slice_index = -1;
  f.Add(s);
  s = slices[0];
  s.slice_count = 0;
  s.slice_index = 0;
  f.Add(s);
  s = slices[1];
  s.azimuth_end = std::nan("");
  f.Add(s);
  s = slices[1];
  s.azimuth_end = s.azimuth_begin + 7.0;  // more than a turn
  f.Add(s);
  f.Add(slices[0]);
  s = slices[1];
  s.slice_count = 5;  // unlike slice 0's
  f.Add(s);
  s = slices[2];
  s.sweep_duration_us += 1;
  f.Add(s);
  EXPECT_EQ(f.assembler.refused().at("slice_bad_index"), 3);
  EXPECT_EQ(f.assembler.refused().at("slice_bad_arc"), 2);
  EXPECT_EQ(f.assembler.refused().at("slice_inconsistent"), 2);
  for (std::size_t k = 1; k < 4; ++k) f.Add(slices[k]);
  ASSERT_EQ(f.out.size(), 1u);
  ExpectSameScan(f.out[0].scan, scan);
  EXPECT_EQ(f.assembler.slices_accepted(), 4);
}

// Checked decoding knows the slice's layout: whole slices decode, an inflated npoints or a cut
// buffer is refused before LCM's decoder allocates.
TEST(LadarSliceDecodeTest, InflatedOrTruncatedSlicesAreRefused) {
  const ladar_slice_t s = SliceSweep(MakeSweep(1, 256, 8, 0.0, 1, 12), 4)[1];
  std::vector<std::uint8_t> buf(static_cast<std::size_t>(s.getEncodedSize()));
  s.encode(buf.data(), 0, static_cast<int>(buf.size()));
  ladar_slice_t out;
  ASSERT_EQ(Decode(buf.data(), buf.size(), &out), DecodeError::kNone);
  EXPECT_EQ(out.npoints, s.npoints);
  EXPECT_EQ(out.azimuth_end, s.azimuth_end);
  // npoints sits just before the arrays: 4 x 4 + 4 + 2 bytes per return after it.
  const std::size_t npoints_at = buf.size() - static_cast<std::size_t>(s.npoints) * 22 - 4;
  std::vector<std::uint8_t> inflated = buf;
  inflated[npoints_at] = 0x7f;  // big-endian: ~2e9 returns
  std::string why;
  EXPECT_EQ(Decode(inflated.data(), inflated.size(), &out, &why), DecodeError::kBadLength);
  EXPECT_NE(why.find("ladar_slice_t.npoints"), std::string::npos) << why;
  EXPECT_NE(Decode(buf.data(), buf.size() - 3, &out), DecodeError::kNone);
}

TEST(UncoveredArcsTest, GapsAcrossTheSeamAreMerged) {
  // Arcs of 8 equal slices starting at 170 deg; slices 1, 2 (across +-180) and 6 missing.
  const double w = 2.0 * kPi / 8, a0 = 170.0 * kPi / 180.0;
  std::vector<AzimuthArc> covered;
  auto arc = [&](int k) {
    double b = std::remainder(a0 + k * w, 2.0 * kPi);
    if (b >= kPi) b -= 2.0 * kPi;
    return AzimuthArc{b, b + w};
  };
  for (int k : {0, 3, 4, 5, 7}) covered.push_back(arc(k));
  const std::vector<AzimuthArc> gaps = UncoveredArcs(covered);
  ASSERT_EQ(gaps.size(), 2u);
  double total = 0.0;
  for (const AzimuthArc& g : gaps) total += g.width();
  EXPECT_NEAR(total, 3 * w, 1e-9);
  // Every missing slice's middle is in a gap; no received one's is.
  for (int k = 0; k < 8; ++k) {
    const AzimuthArc a = arc(k);
    const double mid = 0.5 * (a.begin + a.end);
    const bool in_gap = std::any_of(gaps.begin(), gaps.end(),
                                    [&](const AzimuthArc& g) { return InArc(mid, g.begin, g.end); });
    EXPECT_EQ(in_gap, k == 1 || k == 2 || k == 6) << k;
  }
  EXPECT_NEAR(UncoveredArcs({}).front().width(), 2.0 * kPi, 1e-12);
}

}  // namespace
}  // namespace vtrack::lcm_util
