// Validate() of the viewer's parameter structs (RenderParams, SceneParams, ...), in terms of
// their FirstProblem().
#pragma once

#include <string>

namespace vtrack::viewer {

// True if p.FirstProblem() is ""; *error (if given) is set to it either way.
template <class P>
bool ValidateByFirstProblem(const P& p, std::string* error) {
  const std::string problem = p.FirstProblem();
  if (error) *error = problem;
  return problem.empty();
}

}  // namespace vtrack::viewer
