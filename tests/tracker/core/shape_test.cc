#include "tracker/core/shape.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <stdexcept>
#include <vector>

namespace vtrack {
namespace {

// A sample's weight halves every half-life: 2^(-t / half_life).
TEST(Shape, WeightsDecayWithTheHalfLife) {
  ShapeParams p;
  p.half_life = 2.0;
  DimensionHistogram hist(p);
  EXPECT_EQ(hist.TotalWeight(0.0), 0.0);
  ASSERT_TRUE(hist.Add(10.0, 4.0));
  EXPECT_DOUBLE_EQ(hist.TotalWeight(10.0), 1.0);
  EXPECT_DOUBLE_EQ(hist.TotalWeight(12.0), 0.5);
  EXPECT_DOUBLE_EQ(hist.TotalWeight(16.0), 0.125);
  ASSERT_TRUE(hist.Add(14.0, 4.0));  // the first now weighs 0.25
  EXPECT_DOUBLE_EQ(hist.TotalWeight(14.0), 1.25);
  ASSERT_TRUE(hist.Add(12.0, 4.0));  // an older sample arrives late: weight 0.5 at t = 14
  EXPECT_DOUBLE_EQ(hist.TotalWeight(14.0), 1.75);
}

TEST(Shape, SingleValueIsItsOwnEstimate) {
  DimensionHistogram hist;
  EXPECT_FALSE(hist.Estimate().has_value());
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(hist.Add(0.1 * i, 4.53));
  ASSERT_TRUE(hist.Estimate().has_value());
  EXPECT_NEAR(*hist.Estimate(), 4.53, 0.01);
}

TEST(Shape, BadSamplesAreRefused) {
  DimensionHistogram hist;
  EXPECT_FALSE(hist.Add(0.0, std::nan("")));
  EXPECT_FALSE(hist.Add(0.0, -1.0));
  EXPECT_FALSE(hist.Add(0.0, 0.0));
  EXPECT_FALSE(hist.Add(std::numeric_limits<double>::infinity(), 4.0));
  EXPECT_EQ(hist.TotalWeight(0.0), 0.0);
  EXPECT_FALSE(hist.Estimate().has_value());
  // Above the range: counted (as an outlier), never an estimate.
  EXPECT_TRUE(hist.Add(0.0, 1000.0));
  EXPECT_EQ(hist.TotalWeight(0.0), 1.0);
  EXPECT_FALSE(hist.Estimate().has_value());
}

// The histogram is linear in its samples' weights: a sample of weight w is w of a sample of
// weight 1 taken at the same time. At each of six times, 4.5 m with weight 1 and 5.5 m with weight
// 0.2 against five samples of 4.5 m and one of 5.5 m, each of weight 1: every weight five times
// as large, the same estimate (4.5 m: the 5.5 m peak is 0.2 of the other's height, below
// min_peak_fraction 0.25). Unweighted (one sample of each), the longer peak counts and is the
// estimate.
TEST(Shape, AWeightedSampleCountsAsThatShareOfOne) {
  DimensionHistogram weighted, repeated, plain;
  for (int i = 0; i < 6; ++i) {
    const double t = 0.1 * i;
    ASSERT_TRUE(weighted.Add(t, 4.5, 1.0));
    ASSERT_TRUE(weighted.Add(t, 5.5, 0.2));
    for (int k = 0; k < 5; ++k) ASSERT_TRUE(repeated.Add(t, 4.5));
    ASSERT_TRUE(repeated.Add(t, 5.5));
    ASSERT_TRUE(plain.Add(t, 4.5));
    ASSERT_TRUE(plain.Add(t, 5.5));
  }
  EXPECT_NEAR(weighted.TotalWeight(0.5) * 5.0, repeated.TotalWeight(0.5), 1e-12);
  ASSERT_TRUE(weighted.Estimate() && repeated.Estimate() && plain.Estimate());
  EXPECT_NEAR(*weighted.Estimate(), *repeated.Estimate(), 1e-9);
  EXPECT_NEAR(*weighted.Estimate(), 4.5, 0.05);
  EXPECT_NEAR(*plain.Estimate(), 5.5, 0.05);
  const double before = weighted.TotalWeight(0.5);
  EXPECT_FALSE(weighted.Add(0.5, 4.5, 0.0));
  EXPECT_FALSE(weighted.Add(0.5, 4.5, -1.0));
  EXPECT_FALSE(weighted.Add(0.5, 4.5, std::nan("")));
  EXPECT_FALSE(weighted.Add(0.5, 4.5, std::numeric_limits<double>::infinity()));
  EXPECT_EQ(weighted.TotalWeight(0.5), before);
}

// A car's side seen densely 18 times (4.5 m), and 6 times at a grazing angle from a few returns
// (6.0 m, each uncertain by 0.3 m where the dense views are by 0.03 m). Unweighted, the longer
// peak is about a third as high as the other, above min_peak_fraction (0.25), and as the longest
// counted peak it is the estimate; weighted, (0.03 / 0.3)^2 = 0.01 each, it holds a third of a
// percent of the weight: below min_peak_fraction, and inside the excluded top 5 % as well.
TEST(Shape, SparseViewsWeighedByTheirUncertaintyDoNotSetTheLength) {
  EXPECT_DOUBLE_EQ(DimensionSampleWeight(0.3, 0.03), 0.01);
  EXPECT_DOUBLE_EQ(DimensionSampleWeight(0.03, 0.03), 1.0);
  EXPECT_DOUBLE_EQ(DimensionSampleWeight(0.01, 0.03), 1.0);  // never above one sample
  EXPECT_DOUBLE_EQ(DimensionSampleWeight(std::nan(""), 0.03), 1.0);  // uncertainty not known
  EXPECT_DOUBLE_EQ(DimensionSampleWeight(0.0, 0.03), 1.0);
  // Nothing known: no weight, and the histogram refuses the sample.
  EXPECT_EQ(DimensionSampleWeight(std::numeric_limits<double>::infinity(), 0.03), 0.0);
  DimensionHistogram plain, weighted;
  for (int i = 0; i < 24; ++i) {
    const bool grazing = i % 4 == 3;
    const double value = grazing ? 6.0 : 4.5;
    ASSERT_TRUE(plain.Add(0.1 * i, value));
    ASSERT_TRUE(weighted.Add(0.1 * i, value, DimensionSampleWeight(grazing ? 0.3 : 0.03, 0.03)));
  }
  ASSERT_TRUE(plain.Estimate() && weighted.Estimate());
  EXPECT_NEAR(*plain.Estimate(), 6.0, 0.05);
  EXPECT_NEAR(*weighted.Estimate(), 4.5, 0.05);
}

// Paper Section 2.3: occluded views give shorter lengths. With 60% of the samples from occluded
// views (a persistent partial occlusion that makes a strong peak at 2.2 m, and lengths spread
// below the true one) and 3% gross outliers above, the estimate is the true length.
TEST(Shape, TrueLengthDespiteSixtyPercentOccludedViews) {
  const double true_length = 4.6;
  for (std::uint64_t seed : {1, 2, 3, 4, 5}) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    std::normal_distribution<double> noise(0.0, 0.06);
    std::uniform_real_distribution<double> shorter(1.0, true_length - 0.3);
    std::uniform_real_distribution<double> gross(6.0, 15.0);
    DimensionHistogram hist;
    int occluded = 0;
    const int n = 300;  // 30 s at 10 Hz; half-life 3 s
    for (int i = 0; i < n; ++i) {
      const double r = u01(rng);
      double value;
      if (r < 0.45) {
        value = 2.2 + noise(rng);
        ++occluded;
      } else if (r < 0.60) {
        value = shorter(rng);
        ++occluded;
      } else if (r < 0.97) {
        value = true_length + noise(rng);
      } else {
        value = gross(rng);
      }
      ASSERT_TRUE(hist.Add(0.1 * i, value));
    }
    EXPECT_GT(occluded, 0.5 * n);  // the occluded views are the majority
    ASSERT_TRUE(hist.Estimate().has_value());
    EXPECT_NEAR(*hist.Estimate(), true_length, 0.05) << "seed " << seed;
  }
}

// Estimate after a step change of the true size from `before` to `after` at t = 0, sampled at
// 10 Hz with noise, `elapsed` seconds after the change.
double AfterChange(double before, double after, double elapsed, const ShapeParams& p,
                   std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.05);
  DimensionHistogram hist(p);
  for (double t = -30.0; t < 1e-9; t += 0.1) hist.Add(t, before + noise(rng));
  for (double t = 0.1; t <= elapsed + 1e-9; t += 0.1) hist.Add(t, after + noise(rng));
  return *hist.Estimate();
}

// A size that grows (a vehicle first seen end-on) is followed within the half-life; one that
// shrinks is followed after log2((1 + f) / f) half-lives (shape.h), not before, because a
// shorter peak is indistinguishable from an occluded view.
TEST(Shape, FollowsChangeOfTrueSizeWithinHalfLife) {
  ShapeParams p;
  p.half_life = 2.0;
  EXPECT_NEAR(AfterChange(4.5, 5.6, p.half_life, p, 1), 5.6, 0.05);
  EXPECT_NEAR(AfterChange(1.8, 4.5, p.half_life, p, 2), 4.5, 0.05);
  // Before the change the old size holds.
  EXPECT_NEAR(AfterChange(4.5, 5.6, 0.0, p, 3), 4.5, 0.05);

  const double shrink_time =
      p.half_life * std::log2((1.0 + p.min_peak_fraction) / p.min_peak_fraction);
  EXPECT_NEAR(AfterChange(5.6, 4.5, 0.8 * shrink_time, p, 4), 5.6, 0.05);
  EXPECT_NEAR(AfterChange(5.6, 4.5, 1.2 * shrink_time, p, 5), 4.5, 0.05);
}

// Decay is a scaling by a power of two per whole half-life, which floating point does exactly:
// samples added over time, each decayed as later ones come, hold the same weights as the same
// samples added at the end, each with its weight decayed to that time, 2^-(age / half_life).
// Seeded streams of sizes in three clusters across the whole range, at whole half-lives, with
// gaps of 60 half-lives after which the samples before them decay below the cut (1e-15 of the
// total: those are left out of the second histogram). The estimates agree to 1e-9 m
// (the cut samples' share of the total, 1e-18, is all that differs). Fails if the decay or the
// search for the peaks misses a bin that holds weight.
TEST(Shape, SamplesDecayedAsTheyComeMatchTheSameSamplesWeighedAtTheEnd) {
  ShapeParams p;
  p.half_life = 1.5;
  std::mt19937 rng(17);
  for (int trial = 0; trial < 200; ++trial) {
    struct Sample {
      int step;  // [half-lives]
      double value;
    };
    std::vector<Sample> samples;
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double centre[3] = {0.1 + 2.0 * u(rng), 3.0 + 6.0 * u(rng), 14.0 + 5.5 * u(rng)};
    int step = 0;
    std::size_t forgotten_before = 0;
    const int n = 5 + static_cast<int>(40 * u(rng));
    for (int k = 0; k < n; ++k) {
      const double r = u(rng);
      if (r < 0.05) {
        step += 60;  // every earlier sample decays below the cut
        forgotten_before = static_cast<std::size_t>(k);
      } else if (r < 0.5) {
        step += 1 + static_cast<int>(3 * u(rng));
      }
      const double value = centre[static_cast<int>(3 * u(rng))] + 0.3 * (u(rng) - 0.5);
      samples.push_back({step, std::max(value, 0.01)});
    }
    // One more step: the decay it brings cuts what the last gap left (the cut compares with the
    // total decayed alike, so a gap alone cuts nothing).
    samples.push_back({++step, centre[1]});
    DimensionHistogram streamed(p), at_end(p);
    for (const Sample& s : samples) ASSERT_TRUE(streamed.Add(s.step * p.half_life, s.value));
    for (std::size_t k = forgotten_before; k < samples.size(); ++k) {
      const Sample& s = samples[k];
      ASSERT_TRUE(at_end.Add(step * p.half_life, s.value, std::ldexp(1.0, s.step - step)));
    }
    const std::optional<double> a = streamed.Estimate(), b = at_end.Estimate();
    ASSERT_EQ(a.has_value(), b.has_value()) << "trial " << trial;
    if (a) {
      EXPECT_NEAR(*a, *b, 1e-9) << "trial " << trial;
    }
  }
}

TEST(Shape, LengthAndWidthAreSeparateAndSwap) {
  ShapeEstimator shape;
  for (int i = 0; i < 20; ++i) {
    shape.AddLength(0.1 * i, 4.4);
    shape.AddWidth(0.1 * i, 1.8);
  }
  EXPECT_NEAR(*shape.Length(), 4.4, 0.01);
  EXPECT_NEAR(*shape.Width(), 1.8, 0.01);
  shape.SwapLengthAndWidth();
  EXPECT_NEAR(*shape.Length(), 1.8, 0.01);
  EXPECT_NEAR(*shape.Width(), 4.4, 0.01);
}

TEST(Shape, ParamsValidationNamesFieldAndValue) {
  std::string error;
  EXPECT_TRUE(ShapeParams().Validate(&error)) << error;
  ShapeParams p;
  p.excluded_fraction = 1.5;
  EXPECT_FALSE(p.Validate(&error));
  EXPECT_NE(error.find("excluded_fraction = 1.5"), std::string::npos) << error;
  p = ShapeParams();
  p.half_life = 0.0;
  EXPECT_FALSE(p.Validate(&error));
  EXPECT_NE(error.find("half_life"), std::string::npos) << error;
  p = ShapeParams();
  p.bin_width = -0.1;
  EXPECT_THROW(DimensionHistogram{p}, std::invalid_argument);
}

}  // namespace
}  // namespace vtrack
