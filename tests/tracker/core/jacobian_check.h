// One Jacobian checker for every model (in the manner of Ceres' GradientChecker): compares an
// analytic Jacobian with central finite differences of the function, column by column.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "base/angle.h"

namespace vtrack::testing {

struct JacobianCheckOptions {
  // Output components that are angles: their differences are wrapped to (-pi, pi], so a
  // perturbation that carries theta across +-pi does not look like a jump of 2 pi.
  std::vector<int> angle_outputs;
  // Step for input i: relative_step * max(1, |x_i|). Central differences err by O(step^2) from
  // truncation and O(eps / step) from rounding; 1e-5 balances both for these models.
  double relative_step = 1e-5;
  // Entry (r, c) passes if |analytic - numeric| <= tolerance * max(1, |numeric|).
  double tolerance = 1e-6;
};

// f: Eigen::Matrix<double, M, 1>(const Eigen::Matrix<double, N, 1>&).
template <typename F, int M, int N>
::testing::AssertionResult JacobianMatchesCentralDifferences(
    F&& f, const Eigen::Matrix<double, N, 1>& x, const Eigen::Matrix<double, M, N>& analytic,
    const JacobianCheckOptions& options = JacobianCheckOptions()) {
  Eigen::Matrix<double, M, N> numeric;
  for (int c = 0; c < N; ++c) {
    const double h = options.relative_step * std::max(1.0, std::abs(x(c)));
    Eigen::Matrix<double, N, 1> xp = x, xm = x;
    xp(c) += h;
    xm(c) -= h;
    const Eigen::Matrix<double, M, 1> fp = f(xp), fm = f(xm);
    Eigen::Matrix<double, M, 1> diff = fp - fm;
    for (int r : options.angle_outputs) diff(r) = AngleDiff(fp(r), fm(r));
    // (x + h) - (x - h) is not exactly 2h in floating point; divide by the step actually taken.
    numeric.col(c) = diff / (xp(c) - xm(c));
  }
  std::ostringstream failures;
  int failed = 0;
  for (int c = 0; c < N; ++c) {
    for (int r = 0; r < M; ++r) {
      const double err = std::abs(analytic(r, c) - numeric(r, c));
      if (!(err <= options.tolerance * std::max(1.0, std::abs(numeric(r, c))))) {
        ++failed;
        failures << "\n  d out(" << r << ") / d in(" << c << "): analytic " << analytic(r, c)
                 << ", central difference " << numeric(r, c) << ", error " << err;
      }
    }
  }
  if (failed == 0) return ::testing::AssertionSuccess();
  Eigen::IOFormat fmt(Eigen::StreamPrecision, 0, ", ", "; ");
  return ::testing::AssertionFailure() << failed << " Jacobian entries differ at x = ["
                                       << x.transpose().format(fmt) << "]:" << failures.str();
}

}  // namespace vtrack::testing
