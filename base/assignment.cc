#include "base/assignment.h"

#include <algorithm>
#include <limits>

namespace vtrack {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

std::vector<int> SolveAssignment(const std::vector<double>& cost, int rows, int cols) {
  // Shortest augmenting paths with row/column potentials (Kuhn-Munkres, Jonker-Volgenant
  // style); 1-based arrays with column 0 as the virtual start.
  std::vector<double> u(static_cast<std::size_t>(rows) + 1, 0.0);
  std::vector<double> v(static_cast<std::size_t>(cols) + 1, 0.0);
  std::vector<int> p(static_cast<std::size_t>(cols) + 1, 0);    // row matched to column
  std::vector<int> way(static_cast<std::size_t>(cols) + 1, 0);
  std::vector<double> minv(static_cast<std::size_t>(cols) + 1);
  std::vector<char> used(static_cast<std::size_t>(cols) + 1);
  auto a = [&](int r, int c) {
    return cost[static_cast<std::size_t>(r - 1) * static_cast<std::size_t>(cols) +
                static_cast<std::size_t>(c - 1)];
  };
  for (int i = 1; i <= rows; ++i) {
    p[0] = i;
    int j0 = 0;
    std::fill(minv.begin(), minv.end(), kInf);
    std::fill(used.begin(), used.end(), 0);
    do {
      used[static_cast<std::size_t>(j0)] = 1;
      const int i0 = p[static_cast<std::size_t>(j0)];
      double delta = kInf;
      int j1 = 0;
      for (int j = 1; j <= cols; ++j) {
        if (used[static_cast<std::size_t>(j)]) continue;
        const double cur = a(i0, j) - u[static_cast<std::size_t>(i0)] - v[static_cast<std::size_t>(j)];
        if (cur < minv[static_cast<std::size_t>(j)]) {
          minv[static_cast<std::size_t>(j)] = cur;
          way[static_cast<std::size_t>(j)] = j0;
        }
        if (minv[static_cast<std::size_t>(j)] < delta) {
          delta = minv[static_cast<std::size_t>(j)];
          j1 = j;
        }
      }
      for (int j = 0; j <= cols; ++j) {
        if (used[static_cast<std::size_t>(j)]) {
          u[static_cast<std::size_t>(p[static_cast<std::size_t>(j)])] += delta;
          v[static_cast<std::size_t>(j)] -= delta;
        } else {
          minv[static_cast<std::size_t>(j)] -= delta;
        }
      }
      j0 = j1;
    } while (p[static_cast<std::size_t>(j0)] != 0);
    do {
      const int j1 = way[static_cast<std::size_t>(j0)];
      p[static_cast<std::size_t>(j0)] = p[static_cast<std::size_t>(j1)];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> assign(static_cast<std::size_t>(rows), -1);
  for (int j = 1; j <= cols; ++j) {
    if (p[static_cast<std::size_t>(j)] > 0) assign[static_cast<std::size_t>(p[static_cast<std::size_t>(j)] - 1)] = j - 1;
  }
  return assign;
}

}  // namespace vtrack
