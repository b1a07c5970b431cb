#include "log_tools/eval/gated_assignment.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "base/assignment.h"

namespace vtrack::eval {
namespace {

// Solves one connected block: rows and cols index into cost, every listed row and column has at
// least one allowed pair within the block.
void SolveBlock(const Eigen::MatrixXd& cost, const std::vector<int>& rows,
                const std::vector<int>& cols, std::vector<std::pair<int, int>>* pairs) {
  if (rows.size() == 1 && cols.size() == 1) {  // the common case: an isolated pair
    pairs->emplace_back(rows[0], cols[0]);
    return;
  }
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  for (const int r : rows) {
    for (const int c : cols) {
      const double v = cost(r, c);
      if (!std::isfinite(v)) continue;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  // Allowed costs shifted to [0, hi - lo]; a complete assignment has n = min(rows, cols) pairs,
  // so any set of allowed pairs costs at most n (hi - lo) < forbidden. Minimising the total thus
  // first minimises the number of forbidden pairs used (maximum cardinality), then the cost.
  const int n = static_cast<int>(std::min(rows.size(), cols.size()));
  const double forbidden = (hi - lo + 1.0) * static_cast<double>(n) + 1.0;
  const bool transpose = rows.size() > cols.size();  // the solver wants rows <= cols
  const std::vector<int>& rr = transpose ? cols : rows;
  const std::vector<int>& cc = transpose ? rows : cols;
  const int nr = static_cast<int>(rr.size()), nc = static_cast<int>(cc.size());
  std::vector<double> flat(static_cast<std::size_t>(nr) * nc);
  for (int a = 0; a < nr; ++a) {
    for (int b = 0; b < nc; ++b) {
      const double v = transpose ? cost(cc[b], rr[a]) : cost(rr[a], cc[b]);
      flat[static_cast<std::size_t>(a) * nc + b] = std::isfinite(v) ? v - lo : forbidden;
    }
  }
  const std::vector<int> assign = SolveAssignment(flat, nr, nc);
  for (int a = 0; a < nr; ++a) {
    const int b = assign[static_cast<std::size_t>(a)];
    if (b < 0 || b >= nc) continue;
    const int row = transpose ? cc[b] : rr[a];
    const int col = transpose ? rr[a] : cc[b];
    if (std::isfinite(cost(row, col))) pairs->emplace_back(row, col);
  }
}

int Find(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace

std::vector<std::pair<int, int>> GatedAssignment(const Eigen::MatrixXd& cost) {
  const int rows = static_cast<int>(cost.rows());
  const int cols = static_cast<int>(cost.cols());
  std::vector<std::pair<int, int>> pairs;
  if (rows == 0 || cols == 0) return pairs;

  // The optimum decomposes over the connected components of the graph of allowed pairs: solve
  // each separately (most are a single pair), so the cubic cost applies only to small groups.
  std::vector<int> parent(static_cast<std::size_t>(rows + cols));
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<bool> row_linked(rows, false), col_linked(cols, false);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      if (!std::isfinite(cost(r, c))) continue;
      row_linked[r] = col_linked[c] = true;
      const int a = Find(parent, r), b = Find(parent, rows + c);
      if (a != b) parent[a] = b;
    }
  }
  std::vector<std::vector<int>> block_rows(static_cast<std::size_t>(rows + cols)),
      block_cols(static_cast<std::size_t>(rows + cols));
  for (int r = 0; r < rows; ++r) {
    if (row_linked[r]) block_rows[Find(parent, r)].push_back(r);
  }
  for (int c = 0; c < cols; ++c) {
    if (col_linked[c]) block_cols[Find(parent, rows + c)].push_back(c);
  }
  for (std::size_t k = 0; k < block_rows.size(); ++k) {
    if (!block_rows[k].empty()) SolveBlock(cost, block_rows[k], block_cols[k], &pairs);
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace vtrack::eval
