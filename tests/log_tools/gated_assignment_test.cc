// GatedAssignment against exhaustive search: maximum number of allowed pairs, then minimum cost.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "log_tools/eval/gated_assignment.h"

namespace vtrack::eval {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Exhaustive: every partial one-to-one matching of allowed pairs; the best by (count desc, cost asc).
void Search(const Eigen::MatrixXd& c, int row, std::vector<bool>& used, int count, double cost,
            int* best_count, double* best_cost) {
  if (row == c.rows()) {
    if (count > *best_count || (count == *best_count && cost < *best_cost)) {
      *best_count = count;
      *best_cost = cost;
    }
    return;
  }
  Search(c, row + 1, used, count, cost, best_count, best_cost);  // row left unmatched
  for (int j = 0; j < c.cols(); ++j) {
    if (used[j] || !std::isfinite(c(row, j))) continue;
    used[j] = true;
    Search(c, row + 1, used, count + 1, cost + c(row, j), best_count, best_cost);
    used[j] = false;
  }
}

TEST(GatedAssignmentTest, MatchesExhaustiveSearchOnRandomMatrices) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> size(0, 6);
  std::uniform_real_distribution<double> value(-3.0, 10.0), unit(0.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial) {
    const int rows = size(rng), cols = size(rng);
    const double forbid = unit(rng);  // fraction of forbidden pairs varies per trial
    Eigen::MatrixXd c(rows, cols);
    for (int i = 0; i < rows; ++i) {
      for (int j = 0; j < cols; ++j) c(i, j) = unit(rng) < forbid ? kInf : value(rng);
    }
    int best_count = -1;
    double best_cost = kInf;
    std::vector<bool> used(cols, false);
    Search(c, 0, used, 0, 0.0, &best_count, &best_cost);

    const auto pairs = GatedAssignment(c);
    std::vector<bool> row_used(rows, false), col_used(cols, false);
    double cost = 0.0;
    for (const auto& [i, j] : pairs) {
      ASSERT_TRUE(i >= 0 && i < rows && j >= 0 && j < cols);
      ASSERT_FALSE(row_used[i]) << "row used twice";
      ASSERT_FALSE(col_used[j]) << "column used twice";
      ASSERT_TRUE(std::isfinite(c(i, j))) << "forbidden pair returned";
      row_used[i] = col_used[j] = true;
      cost += c(i, j);
    }
    ASSERT_EQ(static_cast<int>(pairs.size()), best_count) << "trial " << trial;
    if (best_count > 0) {
      ASSERT_NEAR(cost, best_cost, 1e-9) << "trial " << trial;
    }
  }
}

TEST(GatedAssignmentTest, PrefersMorePairsOverLowerCost) {
  // Row 0 could take column 0 at cost 0 alone, but then row 1 (only column 0 allowed) stays
  // unmatched: two pairs at cost 10 + 10 win.
  Eigen::MatrixXd c(2, 2);
  c << 0.0, 10.0, 10.0, kInf;
  const auto pairs = GatedAssignment(c);
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0], std::make_pair(0, 1));
  EXPECT_EQ(pairs[1], std::make_pair(1, 0));
}

TEST(GatedAssignmentTest, EmptyAndAllForbidden) {
  EXPECT_TRUE(GatedAssignment(Eigen::MatrixXd(0, 3)).empty());
  EXPECT_TRUE(GatedAssignment(Eigen::MatrixXd(3, 0)).empty());
  Eigen::MatrixXd c = Eigen::MatrixXd::Constant(3, 2, kInf);
  EXPECT_TRUE(GatedAssignment(c).empty());
  c(2, 1) = std::numeric_limits<double>::quiet_NaN();  // NaN is forbidden too
  EXPECT_TRUE(GatedAssignment(c).empty());
}

}  // namespace
}  // namespace vtrack::eval
