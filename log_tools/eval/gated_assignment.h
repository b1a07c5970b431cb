// Gated one-to-one assignment, the matching step of every metric in vtrack_eval.
//
// Candidates are the pairs (row, column) with a finite cost; +inf or NaN marks a pair that is
// not allowed (outside the gate). The result is a matching of maximum cardinality among the
// allowed pairs and, among those, of minimum total cost: the semantics that CLEAR MOT
// (Bernardin & Stiefelhagen 2008, Sec. 2.1.1) and HOTA (Luiten et al. 2021, Sec. 5) ask of their
// Hungarian step. It is solved exactly with the project's Hungarian solver
// (vtrack::SolveAssignment, base/assignment.h): forbidden pairs get a cost larger
// than any sum of allowed costs, so that the solver's complete assignment uses as few of them as
// possible, and those are then dropped. The problem is split into the connected components of
// the allowed pairs first (the optimum decomposes over them), so that the cubic cost of the
// Hungarian method applies only to groups of nearby objects.
#pragma once

#include <Eigen/Core>

#include <utility>
#include <vector>

namespace vtrack::eval {

// Returns the matched (row, column) pairs, sorted by row.
std::vector<std::pair<int, int>> GatedAssignment(const Eigen::MatrixXd& cost);

}  // namespace vtrack::eval
