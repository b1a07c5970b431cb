// The linear assignment problem: one-to-one pairing of rows with columns at the least total cost.
// The tracker (association of segments and boxes) and the evaluators use it.
#pragma once

#include <vector>

namespace vtrack {

// Solves min sum cost[r][assign[r]] over one-to-one assignments of rows to columns
// (rows <= cols), cost row-major rows x cols. Returns assign (column per row). Hungarian method
// with potentials, O(rows^2 cols). Hand-written: the core depends on Eigen only, and the
// assignment is 60 lines that a brute-force test checks.
std::vector<int> SolveAssignment(const std::vector<double>& cost, int rows, int cols);

}  // namespace vtrack
