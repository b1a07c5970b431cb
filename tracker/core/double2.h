// Two doubles side by side, for per-return loops that run two returns per step: a GCC and Clang
// vector extension (one SSE2 register on x86-64; a pair of scalars on a target without one).
// Lane-wise +, -, *, / and comparisons round exactly as the scalar operations, and the helpers
// below give exactly the scalar functions' results, so such a loop computes the very doubles a
// loop over one return at a time would: no decision changes. Eigen::Array2d does the same
// arithmetic, but its abs, max and masked select go through expression templates whose
// instruction sequence is not spelled out; here each operation is one that rounds as the scalar
// code does, which is what the exactness rests on.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>

namespace vtrack {

typedef double Double2 __attribute__((vector_size(16)));
typedef std::int64_t Mask2 __attribute__((vector_size(16)));  // a lane's comparison: 0 or -1

inline Double2 Splat(double v) { return Double2{v, v}; }
inline Double2 Load2(const double* p) {
  Double2 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
// std::max(a, b) (a < b ? b : a) and std::abs(a) (the sign bit cleared), lane by lane.
inline Double2 Max2(Double2 a, Double2 b) { return a < b ? b : a; }
inline Double2 Abs2(Double2 a) {
  constexpr std::int64_t kAllButSign = std::numeric_limits<std::int64_t>::max();
  return std::bit_cast<Double2>(std::bit_cast<Mask2>(a) & Mask2{kAllButSign, kAllButSign});
}

}  // namespace vtrack
