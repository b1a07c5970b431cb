#include "log_tools/eval/gated_assignment.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tracker/core/association.h"

namespace vtrack::eval {

std::vector<std::pair<int, int>> GatedAssignment(const Eigen::MatrixXd& cost) {
  const int rows = static_cast<int>(cost.rows());
  const int cols = static_cast<int>(cost.cols());
  std::vector<std::pair<int, int>> pairs;
  if (rows == 0 || cols == 0) return pairs;

  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double v = cost(r, c);
      if (!std::isfinite(v)) continue;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  if (!std::isfinite(lo)) return pairs;  // nothing allowed

  // Allowed costs shifted to [0, hi - lo]; a complete assignment has n = min(rows, cols) pairs,
  // so any set of allowed pairs costs at most n (hi - lo) < forbidden. Minimising the total thus
  // first minimises the number of forbidden pairs used (maximum cardinality), then the cost.
  const int n = std::min(rows, cols);
  const double forbidden = (hi - lo + 1.0) * static_cast<double>(n) + 1.0;
  const bool transpose = rows > cols;  // the solver wants rows <= cols
  const int r_count = transpose ? cols : rows;
  const int c_count = transpose ? rows : cols;
  std::vector<double> flat(static_cast<std::size_t>(r_count) * c_count);
  for (int r = 0; r < r_count; ++r) {
    for (int c = 0; c < c_count; ++c) {
      const double v = transpose ? cost(c, r) : cost(r, c);
      flat[static_cast<std::size_t>(r) * c_count + c] = std::isfinite(v) ? v - lo : forbidden;
    }
  }
  const std::vector<int> assign = SolveAssignment(flat, r_count, c_count);
  for (int r = 0; r < r_count; ++r) {
    const int c = assign[static_cast<std::size_t>(r)];
    if (c < 0 || c >= c_count) continue;
    const int row = transpose ? c : r;
    const int col = transpose ? r : c;
    if (std::isfinite(cost(row, col))) pairs.emplace_back(row, col);
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace vtrack::eval
