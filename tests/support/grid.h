// Grids of values for tests that check a property at every combination of a few values.
#pragma once

#include <vector>

namespace vtrack::testing {

// Calls check(a, b, c, d) for every a in as, b in bs, c in cs and d in ds, in that order (d
// varying fastest). Returns the number of calls.
template <typename Check>
int ForEachCombination(const std::vector<double>& as, const std::vector<double>& bs,
                       const std::vector<double>& cs, const std::vector<double>& ds,
                       Check check) {
  int calls = 0;
  for (double a : as) {
    for (double b : bs) {
      for (double c : cs) {
        for (double d : ds) {
          check(a, b, c, d);
          ++calls;
        }
      }
    }
  }
  return calls;
}

}  // namespace vtrack::testing
